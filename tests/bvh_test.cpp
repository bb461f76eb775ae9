// The BVH builder: traversal of the built tree finds exactly the hits brute force
// finds, and the tree keeps the invariants the traversal relies on.
#include <cmath>
#include <numeric>
#include <random>
#include <utility>

#include "bvh_support.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"
#include "wavetrace/path.hpp"

namespace wt {
namespace {

using test::box_contains;
using test::walk;

struct SphereSet {
  std::string name;
  std::vector<SphereGeom> spheres;
};

// sphere_materials[i] = i, so after the builder's reordering each sphere still
// says where it was.
Scene built(const std::vector<SphereGeom>& spheres) {
  Scene s;
  s.source = "bvh-test";
  s.spheres = spheres;
  s.sphere_materials.resize(spheres.size());
  std::iota(s.sphere_materials.begin(), s.sphere_materials.end(), 0u);
  if (!spheres.empty()) s.placements.push_back({kSpheres, kIdentityTransform, kIdentityTransform, true, -1});
  build_bvh(s);
  return s;
}

// The root of the spheres' own tree (below the top level's single leaf).
int sphere_root(const Scene& s) { return s.instances.at(0).root; }

std::vector<SphereGeom> random_spheres(uint32_t seed, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-10.0f, 10.0f), log_radius(std::log(0.05f), std::log(2.0f));
  std::vector<SphereGeom> out;
  for (int i = 0; i < count; ++i) out.push_back(SphereGeom{pos(rng), pos(rng), pos(rng), std::exp(log_radius(rng))});
  return out;
}

// The reference scene's shape: a radius-1000 ground under many small spheres.
std::vector<SphereGeom> ground_and_marbles(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-11.0f, 11.0f);
  std::vector<SphereGeom> out = {{0, -1000, 0, 1000}, {0, 1, 0, 1}, {-4, 1, 0, 1}, {4, 1, 0, 1}};
  for (int i = 0; i < 300; ++i) out.push_back(SphereGeom{pos(rng), 0.2f, pos(rng), 0.2f});
  return out;
}

// Every centre the same point: no split plane separates them.
std::vector<SphereGeom> concentric(int count) {
  std::vector<SphereGeom> out;
  for (int i = 0; i < count; ++i) out.push_back(SphereGeom{1, 2, 3, 0.1f * static_cast<float>(i + 1)});
  return out;
}

// Three chains of centres, one along each axis, each 32 times farther out than the
// last: equal-width bins can then only peel one sphere off a chain per level, so
// SAH alone would make a tree about as deep as the sphere count.
std::vector<SphereGeom> power_chains() {
  std::vector<SphereGeom> out;
  for (int axis = 0; axis < 3; ++axis) {
    for (int i = 0; i < 25; ++i) {
      float c[3] = {0, 0, 0};
      c[axis] = std::ldexp(1.0f, 5 * i);
      out.push_back(SphereGeom{c[0], c[1], c[2], 0.4f});
    }
  }
  return out;
}

std::vector<SphereSet> sphere_sets() {
  return {{"one", random_spheres(1, 1)},          {"two", random_spheres(2, 2)},
          {"57", random_spheres(3, 57)},          {"500", random_spheres(4, 500)},
          {"ground", ground_and_marbles(5)},      {"concentric", concentric(100)},
          {"power chains", power_chains()}};
}

Hit brute_force(const std::vector<SphereGeom>& spheres, const Ray& ray, float tmin, float tmax) {
  Hit hit{tmax, -1, -1, 0.0f, 0.0f};
  for (size_t i = 0; i < spheres.size(); ++i) {
    const SphereGeom& s = spheres[i];
    float t;
    if (intersect_sphere(ray, vec3(s.x, s.y, s.z), s.w, tmin, hit.t, t)) {
      hit.t = t;
      hit.instance = 0;
      hit.prim = static_cast<int32_t>(i);
    }
  }
  return hit;
}

vec3 random_direction(std::mt19937& rng) {
  std::normal_distribution<float> n;
  for (;;) {
    vec3 d(n(rng), n(rng), n(rng));
    if (glm::dot(d, d) > 1e-6f) return glm::normalize(d);
  }
}

// Random rays from around and inside the spheres, half of them aimed near a sphere
// (so they hit, or graze, often), with either an unbounded or a short tmax.
struct RayCase {
  Ray ray;
  float tmax;
};

std::vector<RayCase> random_rays(uint32_t seed, const std::vector<SphereGeom>& spheres, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-15.0f, 15.0f), unit(-1.2f, 1.2f), short_t(0.5f, 20.0f);
  std::uniform_int_distribution<size_t> pick(0, spheres.size() - 1);
  std::vector<RayCase> out;
  while (static_cast<int>(out.size()) < count) {
    vec3 o(pos(rng), pos(rng), pos(rng));
    vec3 d = random_direction(rng);
    if (out.size() % 2 == 1) {
      const SphereGeom& s = spheres[pick(rng)];
      vec3 target = vec3(s.x, s.y, s.z) + s.w * vec3(unit(rng), unit(rng), unit(rng));
      if (glm::length(target - o) == 0.0f) continue;
      d = glm::normalize(target - o);
    }
    out.push_back(RayCase{Ray{o, d}, out.size() % 3 == 0 ? short_t(rng) : kRayTMax});
  }
  return out;
}

int depth_below(const std::vector<BvhNode>& nodes, int node) {
  if (nodes[node].count > 0) return 0;
  int left = nodes[node].left_or_first;
  return 1 + std::max(depth_below(nodes, left), depth_below(nodes, left + 1));
}


TEST(Bvh, ClosestHitMatchesBruteForce) {
  uint32_t seed = 100;
  for (const SphereSet& set : sphere_sets()) {
    SCOPED_TRACE(set.name);
    Scene scene = built(set.spheres);
    std::vector<ImageView> images;
    SceneView view = host_view(scene, 64, 64, images);
    int hits = 0;
    for (const RayCase& rc : random_rays(++seed, set.spheres, 4000)) {
      Hit expect = brute_force(set.spheres, rc.ray, kSphereTMin, rc.tmax);
      Hit got = intersect_closest(view, rc.ray, rc.tmax);
      ASSERT_EQ(got.missed(), expect.missed());
      if (expect.missed()) continue;
      ++hits;
      ASSERT_EQ(scene.sphere_materials[got.prim], static_cast<uint32_t>(expect.prim));
      ASSERT_EQ(got.t, expect.t);
    }
    EXPECT_GT(hits, 400) << "too few rays hit for the comparison to mean much";
  }
}

TEST(Bvh, EverySphereIsInExactlyOneLeafOfAtMostFour) {
  for (const SphereSet& set : sphere_sets()) {
    SCOPED_TRACE(set.name);
    Scene scene = built(set.spheres);
    ASSERT_EQ(scene.spheres.size(), set.spheres.size());
    std::vector<int> seen(scene.spheres.size(), 0);
    walk(scene.nodes, sphere_root(scene), [&](int node, int) {
      const BvhNode& n = scene.nodes[node];
      if (n.count == 0) return;
      EXPECT_LE(n.count, 4);
      for (int i = n.left_or_first; i < n.left_or_first + n.count; ++i) ++seen[i];
    });
    for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 1) << "sphere " << i;
    // And the reordering is a permutation that moved each sphere with its material.
    std::vector<int> original(set.spheres.size(), 0);
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
      uint32_t from = scene.sphere_materials[i];
      ASSERT_LT(from, set.spheres.size());
      ++original[from];
      EXPECT_EQ(scene.spheres[i].x, set.spheres[from].x);
      EXPECT_EQ(scene.spheres[i].w, set.spheres[from].w);
    }
    for (int c : original) EXPECT_EQ(c, 1);
  }
}

TEST(Bvh, EveryNodeIsReachedOnceWithChildrenAfterTheirParent) {
  for (const SphereSet& set : sphere_sets()) {
    SCOPED_TRACE(set.name);
    Scene scene = built(set.spheres);
    std::vector<int> reached(scene.nodes.size(), 0);
    reached[0] = 1;  // the top level's one leaf
    walk(scene.nodes, sphere_root(scene), [&](int node, int parent) {
      ++reached[node];
      EXPECT_GT(node, parent);  // the top level's leaf (node 0) comes first too
    });
    for (size_t i = 0; i < reached.size(); ++i) EXPECT_EQ(reached[i], 1) << "node " << i;
  }
}

TEST(Bvh, NodeBoundsContainTheirChildrenAndSpheres) {
  for (const SphereSet& set : sphere_sets()) {
    SCOPED_TRACE(set.name);
    Scene scene = built(set.spheres);
    walk(scene.nodes, sphere_root(scene), [&](int node, int parent) {
      const BvhNode& n = scene.nodes[node];
      if (parent >= 0) {
        EXPECT_TRUE(box_contains(scene.nodes[parent], n)) << "node " << node;
      }
      for (int i = n.left_or_first; n.count > 0 && i < n.left_or_first + n.count; ++i) {
        const SphereGeom& s = scene.spheres[i];
        const vec3 c(s.x, s.y, s.z);
        EXPECT_TRUE(box_contains(n, c - vec3(s.w), c + vec3(s.w))) << "sphere " << i;
      }
    });
  }
}

TEST(Bvh, DepthStaysBelowTheTraversalStack) {
  std::vector<SphereSet> sets = sphere_sets();
  sets.push_back({"20000", random_spheres(6, 20000)});
  for (const SphereSet& set : sets) {
    SCOPED_TRACE(set.name);
    Scene scene = built(set.spheres);
    EXPECT_LE(depth_below(scene.nodes, sphere_root(scene)), kMaxBvhDepth);
  }
}

TEST(Bvh, OneSphereSceneIsALeafUnderTheTopLevelsLeaf) {
  Scene scene = built({SphereGeom{1, 2, 3, 0.5f}});
  ASSERT_EQ(scene.nodes.size(), 2u);
  EXPECT_EQ(scene.nodes[0].count, 1);  // the one instance
  EXPECT_EQ(scene.nodes[0].left_or_first, 0);
  EXPECT_EQ(scene.nodes[1].count, 1);  // the one sphere
  EXPECT_EQ(scene.nodes[1].left_or_first, 0);
  std::vector<ImageView> images;
  Hit h = intersect_closest(host_view(scene, 64, 64, images), Ray{vec3(1, 2, 0), vec3(0, 0, 1)}, kRayTMax);
  EXPECT_EQ(h.instance, 0);
  EXPECT_EQ(h.prim, 0);
  EXPECT_FLOAT_EQ(h.t, 2.5f);
}

TEST(Bvh, GroundSphereIsIsolatedBelowTheRoot) {
  Scene scene = built(ground_and_marbles(7));
  const BvhNode& root = scene.nodes[sphere_root(scene)];
  ASSERT_EQ(root.count, 0);
  int ground_leaf = -1;
  for (int child : {root.left_or_first, root.left_or_first + 1}) {
    const BvhNode& n = scene.nodes[child];
    if (n.count == 1 && scene.sphere_materials[n.left_or_first] == 0) ground_leaf = child;
  }
  EXPECT_GE(ground_leaf, 0) << "the radius-1000 sphere should be a child leaf of the root, alone";
}

TEST(Bvh, NoSpheresGiveAnEmptyTreeThatMissesEverything) {
  Scene scene = built({});
  EXPECT_TRUE(scene.nodes.empty());
  std::vector<ImageView> images;
  Hit h = intersect_closest(host_view(scene, 64, 64, images), Ray{vec3(0), vec3(0, 0, 1)}, kRayTMax);
  EXPECT_TRUE(h.missed());
}

}  // namespace
}  // namespace wt

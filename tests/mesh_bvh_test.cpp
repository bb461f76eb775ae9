// The two-level traversal (intersect_closest) over meshes and instances finds what
// brute force finds, and each mesh's tree keeps the invariants traversal relies on.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numeric>
#include <random>
#include <utility>

#include "bvh_support.hpp"
#include "mesh_support.hpp"
#include "scene/mesh_load.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"
#include "wavetrace/path.hpp"

namespace wt {
namespace {

using test::box_contains;
using test::walk;

// A hit as brute force sees it: which placement, which triangle (an index into the
// built scene's arrays, or a sphere's), where, and how close to the triangle's
// edges (the smallest barycentric weight: near 0, a neighbour may claim the hit).
struct WorldHit {
  float t = kRayTMax;
  int placement = -1;
  int prim = -1;
  float edge = 1.0f;
  bool missed() const { return placement < 0; }
};

// Brute force in world space: each placement's triangles through its transform (in
// double, rounded once), each tested with the same triangle test as the traversal;
// the spheres as they stand. Also the second-closest distance, for ties.
struct BruteForce {
  struct Tri {
    TriangleGeom g;
    int placement;
    int prim;
  };
  std::vector<Tri> tris;
  std::vector<std::pair<SphereGeom, int>> spheres;  // with the placement
  std::vector<int> sphere_prim;

  BruteForce(const Scene& s, const std::vector<glm::dmat4>& transforms) {
    for (size_t p = 0; p < s.placements.size(); ++p) {
      const Placement& pl = s.placements[p];
      if (pl.mesh == kSpheres) {
        for (size_t i = 0; i < s.spheres.size(); ++i) {
          spheres.push_back({s.spheres[i], static_cast<int>(p)});
          sphere_prim.push_back(static_cast<int>(i));
        }
        continue;
      }
      const SceneMesh& m = s.meshes[pl.mesh];
      for (uint32_t i = m.first_triangle; i < m.first_triangle + m.triangle_count; ++i) {
        TriangleGeom g{};
        float* dst[3] = {g.p0, g.p1, g.p2};
        for (int c = 0; c < 3; ++c) {
          const vec3 w = test::transformed(transforms[p], s.triangles[i].corner(c));
          dst[c][0] = w.x;
          dst[c][1] = w.y;
          dst[c][2] = w.z;
        }
        tris.push_back({g, static_cast<int>(p), static_cast<int>(i)});
      }
    }
  }

  // |cos| of the angle between the ray and the hit triangle's plane normal.
  float grazing(const WorldHit& h, const Ray& ray) const {
    for (const Tri& tri : tris) {
      if (tri.placement != h.placement || tri.prim != h.prim) continue;
      const vec3 n = glm::normalize(glm::cross(tri.g.corner(1) - tri.g.corner(0), tri.g.corner(2) - tri.g.corner(0)));
      return std::fabs(glm::dot(n, ray.dir));
    }
    return 1.0f;
  }

  WorldHit closest(const Ray& ray, float tmax, float& second) const {
    WorldHit best;
    best.t = tmax;
    second = tmax;
    const TriangleRay tr = triangle_ray(ray.dir);
    for (const Tri& tri : tris) {
      float t, b1, b2;
      if (!intersect_triangle(tri.g, ray.origin, tr, tmax, t, b1, b2)) continue;
      if (t < best.t) {
        second = best.t;
        best = WorldHit{t, tri.placement, tri.prim, std::min({b1, b2, 1.0f - b1 - b2})};
      } else if (t < second) {
        second = t;
      }
    }
    for (size_t i = 0; i < spheres.size(); ++i) {
      const SphereGeom& sg = spheres[i].first;
      float t;
      if (!intersect_sphere(ray, vec3(sg.x, sg.y, sg.z), sg.w, kSphereTMin, tmax, t)) continue;
      if (t < best.t) {
        second = best.t;
        best = WorldHit{t, spheres[i].second, sphere_prim[i], 1.0f};
      } else if (t < second) {
        second = t;
      }
    }
    return best;
  }
};

// The placement an instance of the built scene stands for (build_bvh reorders
// them): the tests tag each placement's material override with its index.
int placement_of(const Scene& s, int instance) { return s.instances.at(instance).material; }

// Where the traversal and brute force may disagree, and by how much:
// - t: the traversal carries the ray into object space by float transforms, brute
//   force carries the triangle into world space; both round, by a few ulps of the
//   coordinates. 1e-4 relative (with 1e-4 absolute for hits near the origin) is
//   hundreds of such ulps, and far below the spacing of distinct surfaces here.
// - the primitive: the same, unless two surfaces are within that tolerance along
//   the ray (a tie) or the hit is within 1e-4 (in barycentric weight) of an edge,
//   where rounding may hand it to the neighbour or, on a silhouette, to nothing.
constexpr double kRelativeT = 1e-4, kAbsoluteT = 1e-4;
constexpr float kNearEdge = 1e-4f;

struct Agreement {
  int hits = 0, misses = 0, excused = 0;
};

Agreement compare(const Scene& s, const BruteForce& brute, const std::vector<Ray>& rays, float tmax) {
  std::vector<ImageView> images;
  const SceneView view = host_view(s, 8, 8, images);
  Agreement a;
  for (size_t i = 0; i < rays.size(); ++i) {
    const Ray& ray = rays[i];
    float second;
    const WorldHit expect = brute.closest(ray, tmax, second);
    const Hit got = intersect_closest(view, ray, tmax);
    const double tol_expect = kRelativeT * expect.t + kAbsoluteT;
    if (got.missed() != expect.missed()) {
      // Only a grazing hit at an edge may be found by one and not the other.
      const float got_edge = got.missed() ? 1.0f : std::min({got.b1, got.b2, 1.0f - got.b1 - got.b2});
      const bool triangle = got.missed() || s.instances[got.instance].kind == PrimitiveKind::Triangle;
      if ((!expect.missed() && expect.edge < kNearEdge) || (!got.missed() && triangle && got_edge < kNearEdge)) {
        ++a.excused;
        continue;
      }
      ADD_FAILURE() << "ray " << i << ": traversal " << (got.missed() ? "missed" : "hit") << ", brute force "
                    << (expect.missed() ? "missed" : "hit") << " (t " << expect.t << ", got " << got.t << ")";
      continue;
    }
    if (expect.missed()) {
      ++a.misses;
      continue;
    }
    ++a.hits;
    EXPECT_NEAR(got.t, expect.t, tol_expect) << "ray " << i << " from (" << ray.origin.x << ", " << ray.origin.y
                                             << ", " << ray.origin.z << ") along (" << ray.dir.x << ", " << ray.dir.y
                                             << ", " << ray.dir.z << "): brute force's hit is " << expect.edge
                                             << " (in weight) from an edge, " << brute.grazing(expect, ray)
                                             << " (cosine) off the plane";
    const bool tie = second - expect.t < 2 * tol_expect || expect.edge < kNearEdge;
    if (tie) {
      ++a.excused;
      continue;
    }
    EXPECT_EQ(placement_of(s, got.instance), expect.placement) << "ray " << i;
    EXPECT_EQ(got.prim, expect.prim) << "ray " << i;
  }
  return a;
}

// Random rays: unit directions (as the renderer's), origins in a box around the
// scene, every other one aimed at a random point on a random triangle or sphere
// of brute force's world.
std::vector<Ray> random_rays(uint32_t seed, const BruteForce& brute, float extent, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-extent, extent), w(0.0f, 1.0f);
  std::vector<Ray> out;
  while (static_cast<int>(out.size()) < count) {
    const vec3 o(pos(rng), pos(rng), pos(rng));
    vec3 d = test::random_unit(rng);
    if (out.size() % 2 == 1) {
      const size_t n = brute.tris.size() + brute.spheres.size();
      const size_t k = std::uniform_int_distribution<size_t>(0, n - 1)(rng);
      vec3 target;
      if (k < brute.tris.size()) {
        float b1 = w(rng), b2 = w(rng);
        if (b1 + b2 > 1.0f) {
          b1 = 1.0f - b1;
          b2 = 1.0f - b2;
        }
        const TriangleGeom& g = brute.tris[k].g;
        target = (1.0f - b1 - b2) * g.corner(0) + b1 * g.corner(1) + b2 * g.corner(2);
      } else {
        const SphereGeom& sg = brute.spheres[k - brute.tris.size()].first;
        target = vec3(sg.x, sg.y, sg.z) + 0.99f * sg.w * test::random_unit(rng);
      }
      if (glm::length(target - o) < 1e-3f) continue;
      d = glm::normalize(target - o);
    }
    out.push_back(Ray{o, d});
  }
  return out;
}

void expect_traversal_matches_brute_force(Scene& s, const std::vector<glm::dmat4>& transforms, float extent,
                                          uint32_t seed, int rays) {
  for (size_t p = 0; p < s.placements.size(); ++p) s.placements[p].material = static_cast<int32_t>(p);
  build_bvh(s);
  const BruteForce brute(s, transforms);
  const std::vector<Ray> all = random_rays(seed, brute, extent, rays);
  const Agreement unbounded = compare(s, brute, all, kRayTMax);
  // And with a short tmax, which the traversal's culling must honour.
  const Agreement bounded = compare(s, brute, all, extent * 0.5f);
  EXPECT_GT(unbounded.hits, rays / 3) << "too few hits for the comparison to mean much";
  EXPECT_GT(bounded.misses, 0);
  EXPECT_LT(unbounded.excused + bounded.excused, rays / 50) << "ties and edges should be rare";
}

TEST(MeshBvh, RandomTriangleSoupsMatchBruteForce) {
  const std::pair<int, float> soups[] = {{1, 1.0f}, {7, 2.0f}, {300, 1.0f}, {3000, 0.5f}};
  uint32_t seed = 10;
  for (const auto& [count, size] : soups) {
    SCOPED_TRACE(std::to_string(count) + " triangles");
    Scene s;
    s.source = "soup";
    test::add_mesh(s, test::triangle_soup(++seed, count, 10.0f, size * 3.0f), "soup");
    test::place(s, 0, glm::dmat4(1.0));
    expect_traversal_matches_brute_force(s, {glm::dmat4(1.0)}, 15.0f, ++seed, 3000);
  }
}

TEST(MeshBvh, RealMeshMatchesBruteForce) {
  const std::filesystem::path path = std::filesystem::path(test::models_dir()) / "stanford-bunny.obj";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "no " << path.string() << " (the shared models are optional)";
  const TriangleMesh loaded = load_mesh(path.string());
  test::MeshData mesh;
  mesh.v = loaded.positions;
  mesh.f = loaded.triangles;
  // Scaled to about 2 units across, as the shipped scenes place it.
  Aabb box;
  for (const vec3& p : mesh.v) box.grow(p);
  const vec3 size = box.hi - box.lo;
  const double k = 2.0 / std::max({size.x, size.y, size.z});
  const glm::dvec3 centre(box.centre());
  const glm::dmat4 fit = glm::scale(glm::dmat4(1.0), glm::dvec3(k)) * glm::translate(glm::dmat4(1.0), -centre);
  const glm::dmat4 turned = test::trs({3, 0, 0}, {0, 90, 20}, {1, 2, 1}) * fit;
  Scene s;
  s.source = "bunny";
  test::add_mesh(s, mesh, "bunny");
  test::place(s, 0, fit);
  test::place(s, 0, turned);
  expect_traversal_matches_brute_force(s, {fit, turned}, 4.0f, 3, 3000);
}

// Spheres (untransformed, as spheres are placed) among several meshes, each placed
// more than once, by rotations and non-uniform scales.
TEST(MeshBvh, SpheresAndTransformedInstancesMatchBruteForce) {
  Scene s;
  s.source = "mix";
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> pos(-8.0f, 8.0f), radius(0.2f, 1.5f);
  for (int i = 0; i < 40; ++i) {
    s.spheres.push_back(SphereGeom{pos(rng), pos(rng), pos(rng), radius(rng)});
    s.sphere_materials.push_back(static_cast<uint32_t>(i));
  }
  const int32_t ball = test::add_mesh(s, test::icosphere(2), "ball");
  const int32_t ring = test::add_mesh(s, test::torus(1.0f, 0.3f, 24, 12), "ring");
  const int32_t soup = test::add_mesh(s, test::triangle_soup(4, 200, 1.5f, 0.4f), "soup");
  std::vector<glm::dmat4> transforms;
  auto put = [&](int32_t mesh, const glm::dmat4& m) {
    test::place(s, mesh, m);
    transforms.push_back(m);
  };
  put(kSpheres, glm::dmat4(1.0));
  std::uniform_real_distribution<double> angle(-180, 180), scale(0.3, 3.0);
  for (int i = 0; i < 12; ++i) {
    const int32_t mesh = i % 3 == 0 ? ball : (i % 3 == 1 ? ring : soup);
    const glm::dvec3 t(pos(rng), pos(rng), pos(rng));
    put(mesh, test::trs(t, {angle(rng), angle(rng), angle(rng)}, {scale(rng), scale(rng), scale(rng)}));
  }
  put(ring, glm::dmat4(1.0));
  put(ball, test::trs({0, 0, 0}, {0, 0, 0}, {-1, 1, 1}));  // a mirror: the winding flips
  expect_traversal_matches_brute_force(s, transforms, 12.0f, 21, 6000);
}

// ---- The trees ----

Scene three_meshes_placed_twice() {
  Scene s;
  s.source = "trees";
  test::add_mesh(s, test::icosphere(3), "ball");
  test::add_mesh(s, test::triangle_soup(8, 5000, 10.0f, 1.0f), "soup");
  test::add_mesh(s, test::cube(), "cube");
  for (int32_t m = 0; m < 3; ++m) {
    test::place(s, m, glm::dmat4(1.0), 2 * m);
    test::place(s, m, test::trs({5.0 * m, 1, 2}, {10, 20, 30}, {1, 2, 3}), 2 * m + 1);
  }
  build_bvh(s);
  return s;
}

// The root each mesh's instances enter, and that both of its placements share it.
std::vector<int> mesh_roots(const Scene& s) {
  std::vector<int> roots(s.meshes.size(), -1);
  for (const Instance& in : s.instances) {
    const int mesh = in.material / 2;
    if (roots[mesh] < 0) roots[mesh] = in.root;
    EXPECT_EQ(roots[mesh], in.root) << "mesh " << mesh << " has two trees";
  }
  return roots;
}

TEST(MeshBvh, EveryTriangleIsInExactlyOneLeafOfItsMeshsTree) {
  const Scene s = three_meshes_placed_twice();
  const std::vector<int> roots = mesh_roots(s);
  std::vector<int> seen(s.triangles.size(), 0);
  for (size_t m = 0; m < s.meshes.size(); ++m) {
    const SceneMesh& mesh = s.meshes[m];
    walk(s.nodes, roots[m], [&](int node, int) {
      const BvhNode& n = s.nodes[node];
      if (n.count == 0) return;
      EXPECT_LE(n.count, 4);
      for (int i = n.left_or_first; i < n.left_or_first + n.count; ++i) {
        ASSERT_GE(i, static_cast<int>(mesh.first_triangle)) << "mesh " << m;
        ASSERT_LT(i, static_cast<int>(mesh.first_triangle + mesh.triangle_count)) << "mesh " << m;
        ++seen[i];
      }
    });
  }
  for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 1) << "triangle " << i;
  // The reordering moved each triangle with its material (the test's original index).
  std::vector<int> original(s.triangles.size(), 0);
  for (uint32_t from : s.triangle_materials) {
    ASSERT_LT(from, original.size());
    ++original[from];
  }
  for (int c : original) EXPECT_EQ(c, 1);
}

TEST(MeshBvh, NodeBoundsContainTheirChildrenAndTriangles) {
  const Scene s = three_meshes_placed_twice();
  const std::vector<int> roots = mesh_roots(s);
  int leaves = 0;
  for (int root : roots) {
    walk(s.nodes, root, [&](int node, int parent) {
      const BvhNode& n = s.nodes[node];
      if (parent >= 0) {
        EXPECT_TRUE(box_contains(s.nodes[parent], n))
            << "node " << node;
      }
      if (n.count == 0) return;
      ++leaves;
      for (int i = n.left_or_first; i < n.left_or_first + n.count; ++i) {
        for (int c = 0; c < 3; ++c) {
          const vec3 p = s.triangles[i].corner(c);
          EXPECT_TRUE(box_contains(n, p, p)) << "triangle " << i << " corner " << c;
        }
      }
    });
  }
  EXPECT_GE(leaves, 5000 / 4);
}

// The top level: one instance a leaf, each exactly once, and every box holds its
// children and its instance's world box (the corners of the mesh's root box through
// the transform).
TEST(MeshBvh, TopLevelHoldsEachInstanceOnceInsideItsBounds) {
  const Scene s = three_meshes_placed_twice();
  std::vector<int> seen(s.instances.size(), 0);
  std::vector<std::pair<int, int>> todo = {{0, -1}};
  while (!todo.empty()) {
    auto [node, parent] = todo.back();
    todo.pop_back();
    const BvhNode& n = s.nodes[node];
    if (parent >= 0) {
      EXPECT_TRUE(box_contains(s.nodes[parent], n))
          << "node " << node;
    }
    if (n.count == 0) {
      todo.push_back({n.left_or_first, node});
      todo.push_back({n.left_or_first + 1, node});
      continue;
    }
    ASSERT_EQ(n.count, 1);
    const Instance& in = s.instances.at(n.left_or_first);
    ++seen[n.left_or_first];
    const BvhNode& root = s.nodes[in.root];
    for (int corner = 0; corner < 8; ++corner) {
      const vec3 c((corner & 1) ? root.hi[0] : root.lo[0], (corner & 2) ? root.hi[1] : root.lo[1],
                   (corner & 4) ? root.hi[2] : root.lo[2]);
      const vec3 w = in.world_from_object.point(c);
      EXPECT_TRUE(box_contains(n, w, w)) << "instance " << n.left_or_first << " corner " << corner;
    }
  }
  for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 1) << "instance " << i;
  EXPECT_EQ(seen.size(), 6u);
}

}  // namespace
}  // namespace wt

// The triangle primitive (include/wavetrace/geometry/triangle.hpp): hits against
// values known by construction, misses, watertightness of closed meshes through the
// scene's two-level traversal, and secondary rays that never hit the triangle they
// leave, even far from the origin.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>

#include "mesh_support.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"
#include "wavetrace/path.hpp"

namespace wt {
namespace {

TriangleGeom tri(const vec3& a, const vec3& b, const vec3& c) {
  TriangleGeom g{};
  const vec3 p[3] = {a, b, c};
  float* dst[3] = {g.p0, g.p1, g.p2};
  for (int i = 0; i < 3; ++i) {
    dst[i][0] = p[i].x;
    dst[i][1] = p[i].y;
    dst[i][2] = p[i].z;
  }
  return g;
}

struct TriHit {
  bool hit = false;
  float t = 0, b1 = 0, b2 = 0;
};

TriHit shoot(const TriangleGeom& g, const vec3& o, const vec3& d, float tmax = kRayTMax) {
  TriHit h;
  h.hit = intersect_triangle(g, o, triangle_ray(d), tmax, h.t, h.b1, h.b2);
  return h;
}

// ---- (a) hits and misses of single triangles ----

TEST(Triangle, AxisAlignedRayHitsAtKnownDistanceAndWeights) {
  const TriangleGeom g = tri(vec3(0, 0, 5), vec3(2, 0, 5), vec3(0, 2, 5));
  // (0.5, 0.5, 5) = 0.5 p0 + 0.25 p1 + 0.25 p2; every value is exact in float.
  TriHit h = shoot(g, vec3(0.5f, 0.5f, 0), vec3(0, 0, 1));
  ASSERT_TRUE(h.hit);
  EXPECT_FLOAT_EQ(h.t, 5.0f);
  EXPECT_NEAR(h.b1, 0.25f, 1e-7f);
  EXPECT_NEAR(h.b2, 0.25f, 1e-7f);
  // A direction of length 2: t counts lengths of the direction, not distances.
  h = shoot(g, vec3(0.5f, 0.5f, 0), vec3(0, 0, 2));
  ASSERT_TRUE(h.hit);
  EXPECT_FLOAT_EQ(h.t, 2.5f);
  // From the other side, along -z: the same weights.
  h = shoot(g, vec3(0.5f, 0.5f, 9), vec3(0, 0, -0.5f));
  ASSERT_TRUE(h.hit);
  EXPECT_FLOAT_EQ(h.t, 8.0f);
  EXPECT_NEAR(h.b1, 0.25f, 1e-7f);
  EXPECT_NEAR(h.b2, 0.25f, 1e-7f);
}

TEST(Triangle, OppositeWindingHitsAtTheSameDistanceWithWeightsSwapped) {
  const TriangleGeom ccw = tri(vec3(0, 0, 5), vec3(2, 0, 5), vec3(0, 2, 5));
  const TriangleGeom cw = tri(vec3(0, 0, 5), vec3(0, 2, 5), vec3(2, 0, 5));
  const vec3 o(0.25f, 0.5f, -1.0f), d(0.05f, 0.05f, 1.0f);  // through (0.55, 0.8, 5)
  const TriHit a = shoot(ccw, o, d);
  const TriHit b = shoot(cw, o, d);
  ASSERT_TRUE(a.hit);
  ASSERT_TRUE(b.hit);
  EXPECT_FLOAT_EQ(a.t, b.t);
  EXPECT_FLOAT_EQ(a.b1, b.b2);
  EXPECT_FLOAT_EQ(a.b2, b.b1);
}

// Random triangles and a point of known weights on each; the ray is aimed at it
// from a known distance along a direction of random length (0.01 to 100). Origins
// and corners are rounded to float, so t and the weights are compared to the
// construction's values within 1e-4 relative (t) and 1e-4 absolute (weights):
// hundreds of ulps of float rounding, far below any real error.
TEST(Triangle, RandomRaysHitAtConstructedDistanceWeightsAndPoint) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> pos(-10, 10), w(0.05, 0.9), dist(0.1, 50), log_len(std::log(0.01), std::log(100.0));
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const glm::dvec3 A(pos(rng), pos(rng), pos(rng)), B(pos(rng), pos(rng), pos(rng)), C(pos(rng), pos(rng), pos(rng));
    const TriangleGeom g = tri(vec3(A), vec3(B), vec3(C));
    const glm::dvec3 a{vec3(A)}, b{vec3(B)}, c{vec3(C)};  // the corners as stored
    const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    double b1 = w(rng), b2 = w(rng);
    if (b1 + b2 > 0.95) continue;
    const glm::dvec3 p = (1 - b1 - b2) * a + b1 * b + b2 * c;
    glm::dvec3 dir = glm::dvec3(test::random_unit(rng));
    if (std::fabs(glm::dot(dir, n)) < 0.2) continue;  // not grazing: the check is of values
    const double len = std::exp(log_len(rng)), d0 = dist(rng);
    const vec3 d(dir * len);
    const vec3 o(p - glm::dvec3(d) * (d0 / len));
    // The expected values for the ray as rounded: solve o + t d = a + b1 (b-a) + b2 (c-a) in double.
    const glm::dmat3 m(glm::dvec3(d), a - b, a - c);
    const glm::dvec3 x = glm::inverse(m) * (a - glm::dvec3(o));
    TriHit h = shoot(g, o, d);
    ASSERT_TRUE(h.hit) << "triangle " << i;
    EXPECT_NEAR(h.t, x.x, 1e-4 * x.x) << "triangle " << i;
    EXPECT_NEAR(h.b1, x.y, 1e-4) << "triangle " << i;
    EXPECT_NEAR(h.b2, x.z, 1e-4) << "triangle " << i;
    vec3 err;
    const vec3 q = triangle_point(g, h.b1, h.b2, err);
    EXPECT_LT(glm::length(glm::dvec3(q) - (glm::dvec3(o) + x.x * glm::dvec3(d))), 1e-3) << "triangle " << i;
    ++checked;
  }
  EXPECT_GT(checked, 500);
}

TEST(Triangle, RayOutsideTheEdgesMisses) {
  const TriangleGeom g = tri(vec3(0, 0, 5), vec3(2, 0, 5), vec3(0, 2, 5));
  const vec3 d(0, 0, 1);
  EXPECT_FALSE(shoot(g, vec3(-0.01f, 0.5f, 0), d).hit);   // beyond edge p0-p2
  EXPECT_FALSE(shoot(g, vec3(0.5f, -0.01f, 0), d).hit);   // beyond edge p0-p1
  EXPECT_FALSE(shoot(g, vec3(1.01f, 1.01f, 0), d).hit);   // beyond the hypotenuse
  EXPECT_FALSE(shoot(g, vec3(3, 3, 0), d).hit);
  EXPECT_TRUE(shoot(g, vec3(0.99f, 0.99f, 0), d).hit);    // just inside it
  EXPECT_FALSE(shoot(g, vec3(0.5f, 0.5f, 0), vec3(1, 0, 0)).hit);  // parallel to the plane
}

TEST(Triangle, TriangleBehindTheOriginMisses) {
  const TriangleGeom g = tri(vec3(0, 0, 5), vec3(2, 0, 5), vec3(0, 2, 5));
  EXPECT_FALSE(shoot(g, vec3(0.5f, 0.5f, 6), vec3(0, 0, 1)).hit);
  EXPECT_FALSE(shoot(g, vec3(0.5f, 0.5f, 4), vec3(0.01f, 0, -1)).hit);
  EXPECT_FALSE(shoot(g, vec3(0.5f, 0.5f, 5), vec3(0, 0, 1)).hit);  // starting on it: t = 0 is no hit
}

TEST(Triangle, HitBeyondTmaxMisses) {
  const TriangleGeom g = tri(vec3(0, 0, 5), vec3(2, 0, 5), vec3(0, 2, 5));
  const vec3 o(0.5f, 0.5f, 0);
  EXPECT_FALSE(shoot(g, o, vec3(0, 0, 1), 4.99f).hit);
  EXPECT_TRUE(shoot(g, o, vec3(0, 0, 1), 5.01f).hit);
  // tmax counts lengths of the direction too: t = 2.5 with a direction of length 2.
  EXPECT_FALSE(shoot(g, o, vec3(0, 0, 2), 2.49f).hit);
  EXPECT_TRUE(shoot(g, o, vec3(0, 0, 2), 2.51f).hit);
}

// A ray that grazes a small triangle (0.17 degrees off its plane) through its
// middle: in double the hit is at t = 2.6595607 with weights (0.3256, 0.2168),
// far from every edge. The values are a triangle of the Stanford bunny and a ray
// carried into its object space by an instance that scales by 12.85 (so the
// direction has length 0.078), as MeshBvh.RealMeshMatchesBruteForce met them. The
// hit must be found whatever the direction's length: t scales inversely with it.
TEST(Triangle, GrazingHitWellInsideIsFoundWhateverTheDirectionsLength) {
  const TriangleGeom g = tri(vec3(-0.0263139997f, 0.182659f, -0.0105579998f),
                             vec3(-0.0272799991f, 0.181916997f, -0.0121060004f),
                             vec3(-0.0281160008f, 0.181397006f, -0.0109689999f));
  const vec3 o(-0.0996553227f, 0.123702846f, -0.196019873f);
  const vec3 d(0.0273113362f, 0.0219739247f, 0.0695110187f);
  const float len = glm::length(d);
  for (float k : {1.0f, 1.0f / len, 10.0f / len}) {
    SCOPED_TRACE("direction of length " + std::to_string(k * len));
    const TriHit h = shoot(g, o, k * d);
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t * k, 2.6595607, 1e-4 * 2.6595607);
    // The weights of a grazing hit are ill-conditioned: float rounding of corners
    // 90 triangle-sizes from the origin, amplified by 1 / sin(0.17 degrees) = 340,
    // moves them by up to about 3e-3.
    EXPECT_NEAR(h.b1, 0.325579, 5e-3);
    EXPECT_NEAR(h.b2, 0.216791, 5e-3);
  }
}

// ---- (b) watertightness through the scene's traversal ----

struct MeshScene {
  Scene scene;
  std::vector<ImageView> images;
  SceneView view;
  glm::dmat4 world_from_object;
};

// One mesh placed by m (identity or not); the scene's view for intersect_closest.
std::unique_ptr<MeshScene> mesh_scene(const test::MeshData& mesh, const glm::dmat4& m) {
  auto s = std::make_unique<MeshScene>();
  s->scene.source = "triangle-test";
  test::add_mesh(s->scene, mesh, "mesh");
  test::place(s->scene, 0, m);
  build_bvh(s->scene);
  s->view = host_view(s->scene, 8, 8, s->images);
  s->world_from_object = m;
  return s;
}

struct Placing {
  const char* name;
  glm::dmat4 m;
};

std::vector<Placing> placings() {
  return {{"identity", glm::dmat4(1.0)},
          {"rotated, scaled, moved", test::trs({0.5, -2, 3}, {30, -50, 70}, {1.5, 0.7, 2.0})}};
}

// Rays aimed at `local` (an object-space point on the closed convex mesh, with n
// its outward normal there) from random points outside, at least half head-on in
// object space: every facet around the point faces them (a level-3 icosphere's
// facets lean less than 0.2 from the sphere's normal), so none of these rays
// touches a silhouette. Origin and target go through the placing to world space;
// every ray must hit the near side, at the target's distance (the mesh is convex:
// nothing is in front of the target). Returns the misses.
int aimed_misses(const MeshScene& s, const vec3& local, const glm::dvec3& n, std::mt19937& rng, int rays,
                 const std::string& what) {
  std::uniform_real_distribution<double> dist(0.5, 10.0);
  const vec3 target = test::transformed(s.world_from_object, local);
  int misses = 0;
  for (int i = 0; i < rays; ++i) {
    glm::dvec3 from = glm::dvec3(test::random_unit(rng));
    if (glm::dot(from, n) < 0.0) from = -from;
    if (glm::dot(from, n) < 0.5) from = glm::normalize(from + n);
    const vec3 o = test::transformed(s.world_from_object, vec3(glm::dvec3(local) + from * dist(rng)));
    const vec3 d = glm::normalize(target - o);
    const Ray ray{o, d};
    const Hit h = intersect_closest(s.view, ray, kRayTMax);
    if (h.missed()) {
      ++misses;
      ADD_FAILURE() << what << ": ray from (" << o.x << ", " << o.y << ", " << o.z << ") along (" << d.x << ", "
                    << d.y << ", " << d.z << ") missed";
      continue;
    }
    const float expect = glm::length(target - o);
    EXPECT_NEAR(h.t, expect, 1e-4f * expect + 1e-5f) << what << ": hit something else than the near side";
  }
  return misses;
}

TEST(TriangleWatertight, RaysAimedAtSharedEdgesAndVerticesOfAClosedMeshNeverMiss) {
  const test::MeshData mesh = test::icosphere(3);  // 1280 triangles
  for (const Placing& pl : placings()) {
    SCOPED_TRACE(pl.name);
    auto s = mesh_scene(mesh, pl.m);
    std::mt19937 rng(7);
    int misses = 0;
    // Vertices: the exact corners.
    for (size_t v = 0; v < mesh.v.size(); v += 3) {
      misses += aimed_misses(*s, mesh.v[v], glm::dvec3(mesh.v[v]), rng, 4, "vertex " + std::to_string(v));
    }
    // Points along shared edges, including their midpoints and points a rounding
    // step from the corners.
    std::uniform_real_distribution<float> along(0.0f, 1.0f);
    for (size_t t = 0; t < mesh.f.size(); t += 5) {
      for (int e = 0; e < 3; ++e) {
        const vec3 a = mesh.corner(t, e), b = mesh.corner(t, (e + 1) % 3);
        for (float u : {0.5f, 1e-6f, along(rng)}) {
          const vec3 p = a + u * (b - a);
          misses += aimed_misses(*s, p, glm::normalize(glm::dvec3(a) + glm::dvec3(b)), rng, 2,
                                 "edge of triangle " + std::to_string(t));
        }
      }
    }
    EXPECT_EQ(misses, 0);
  }
}

// Rays along an axis through every point of a lattice on the cube's faces, the
// diagonal each face is split along and the cube's own edges included (the values
// are exact in float, so these rays run exactly along the shared edges): a ray
// through the face's closed square hits it at distance 1 from z = +-2.
TEST(TriangleWatertight, AxisRaysThroughACubesDiagonalsAndEdgesNeverMiss) {
  auto s = mesh_scene(test::cube(), glm::dmat4(1.0));
  int rays = 0;
  std::vector<std::string> missed;
  for (int axis = 0; axis < 3; ++axis) {
    for (float sign : {-1.0f, 1.0f}) {
      for (int i = 0; i <= 16; ++i) {
        for (int j = 0; j <= 16; ++j) {
          const float u = -1.0f + i / 8.0f, v = -1.0f + j / 8.0f;
          vec3 o, d(0.0f);
          o[axis] = -2.0f * sign;
          o[(axis + 1) % 3] = u;
          o[(axis + 2) % 3] = v;
          d[axis] = sign;
          const Hit h = intersect_closest(s->view, Ray{o, d}, kRayTMax);
          ++rays;
          std::ostringstream at;
          at << "axis " << axis << " sign " << sign << " at (" << u << ", " << v << ")";
          if (h.missed()) {
            missed.push_back(at.str());
            continue;
          }
          EXPECT_FLOAT_EQ(h.t, 1.0f) << at.str();
        }
      }
    }
  }
  EXPECT_EQ(rays, 6 * 17 * 17);
  std::string listed;
  for (size_t i = 0; i < missed.size() && i < 8; ++i) listed += "\n  " + missed[i];
  EXPECT_TRUE(missed.empty()) << missed.size() << " of " << rays << " rays missed, e.g." << listed;
}

// From points inside a closed mesh every direction hits it: nothing leaks out
// through the cracks between triangles.
TEST(TriangleWatertight, RaysFromInsideAClosedMeshAllHit) {
  struct Case {
    const char* name;
    test::MeshData mesh;
    float inside;  // points within this of the centre are inside
  };
  const Case cases[] = {{"icosphere", test::icosphere(2), 0.7f}, {"cube", test::cube(), 0.9f}};
  for (const Case& c : cases) {
    for (const Placing& pl : placings()) {
      SCOPED_TRACE(std::string(c.name) + ", " + pl.name);
      auto s = mesh_scene(c.mesh, pl.m);
      std::mt19937 rng(11);
      std::uniform_real_distribution<float> in(-c.inside / 1.8f, c.inside / 1.8f);
      int misses = 0;
      for (int i = 0; i < 20000; ++i) {
        // Every tenth from the exact centre, whose rays cross vertices often.
        const vec3 local = i % 10 == 0 ? vec3(0.0f) : vec3(in(rng), in(rng), in(rng));
        const vec3 o = test::transformed(pl.m, local);
        const vec3 d = test::random_unit(rng);
        if (intersect_closest(s->view, Ray{o, d}, kRayTMax).missed()) ++misses;
      }
      EXPECT_EQ(misses, 0);
    }
  }
}

// A ray through a closed mesh, re-spawned from each hit with spawn_ray: it crosses
// the surface an even number of times, alternately entering (front) and leaving,
// never twice at the same point (a shared edge counted by both its triangles),
// with the distance strictly increasing. Rays aimed at edges and vertices.
void expect_even_crossings(const MeshScene& s, const vec3& origin, const vec3& target, int expect_crossings,
                           const std::string& what) {
  const vec3 d = glm::normalize(target - origin);
  Ray ray{origin, d};
  std::vector<vec3> points;
  for (int i = 0; i < 64; ++i) {
    const Hit h = intersect_closest(s.view, ray, kRayTMax);
    if (h.missed()) break;
    const SurfacePoint sp = surface_at(s.view, ray, h);
    ASSERT_EQ(sp.front, points.size() % 2 == 0) << what << ": crossing " << points.size();
    if (!points.empty()) {
      const float step = glm::dot(sp.p - points.back(), d);
      ASSERT_GT(step, 1e-4f) << what << ": hit again " << step << " after crossing " << points.size() - 1;
    }
    points.push_back(sp.p);
    ray = spawn_ray(sp, d);
  }
  if (expect_crossings > 0) {
    EXPECT_EQ(static_cast<int>(points.size()), expect_crossings) << what;
  } else {
    EXPECT_EQ(points.size() % 2, 0u) << what << ": " << points.size() << " crossings";
  }
}

TEST(TriangleWatertight, RaysThroughAConvexMeshCrossItExactlyTwice) {
  const test::MeshData mesh = test::icosphere(3);
  for (const Placing& pl : placings()) {
    SCOPED_TRACE(pl.name);
    auto s = mesh_scene(mesh, pl.m);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> along(0.0f, 1.0f);
    for (size_t t = 0; t < mesh.f.size(); t += 7) {
      const vec3 a = mesh.corner(t, 0), b = mesh.corner(t, 1);
      for (const vec3& p : {a, a + 0.5f * (b - a), a + along(rng) * (b - a)}) {
        const vec3 target = test::transformed(pl.m, p);
        // From outside, through the target towards a point well inside: the ray enters there.
        const vec3 inner = test::transformed(pl.m, 0.3f * test::random_unit(rng));
        const vec3 origin = target + 4.0f * glm::normalize(target - inner) * 3.0f;
        expect_even_crossings(*s, origin, target, 2, "triangle " + std::to_string(t));
      }
    }
  }
}

TEST(TriangleWatertight, RaysThroughATorusCrossItAnEvenNumberOfTimes) {
  const test::MeshData mesh = test::torus(2.0f, 0.6f, 48, 24);
  for (const Placing& pl : placings()) {
    SCOPED_TRACE(pl.name);
    auto s = mesh_scene(mesh, pl.m);
    std::mt19937 rng(9);
    int through = 0;
    const glm::dmat3 normal_m = glm::transpose(glm::inverse(glm::dmat3(pl.m)));
    for (size_t v = 0; v < mesh.v.size(); v += 3) {
      const vec3 target = test::transformed(pl.m, mesh.v[v]);  // a vertex: six triangles meet there
      // From the outside of the tube at the vertex, at least half head-on: the ray
      // crosses there rather than touching the surface's silhouette.
      const glm::dvec3 local(mesh.v[v]);
      const glm::dvec3 n = glm::normalize(normal_m * (local - 2.0 * glm::normalize(glm::dvec3(local.x, 0, local.z))));
      glm::dvec3 from = glm::dvec3(test::random_unit(rng));
      if (glm::dot(from, n) < 0.0) from = -from;
      if (glm::dot(from, n) < 0.5) from = glm::normalize(from + n);
      const vec3 origin = target + vec3(8.0 * from);
      expect_even_crossings(*s, origin, target, -1, "vertex " + std::to_string(v));
      ++through;
    }
    EXPECT_GT(through, 300);
  }
}

// ---- (c) secondary rays never hit the triangle they leave ----

// Triangles far from the origin (1e4 and beyond, where a float's step is 1e-3),
// hit by a ray, then left by rays spawned from the hit in every direction: towards
// either side, and grazing (1e-2 to 1e-5 off the plane). The scene holds only the
// one triangle, so any hit is the triangle hit again.
// `offset`: where the triangles lie in object space; `placing` moves them.
void expect_no_self_hits(const glm::dmat4& placing, float offset, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-1.0f, 1.0f), w(0.01f, 0.98f);
  int spawned = 0;
  for (int i = 0; i < 200; ++i) {
    test::MeshData m;
    const vec3 centre = vec3(offset) + vec3(pos(rng), pos(rng), pos(rng)) * (offset * 0.1f + 1.0f);
    for (int k = 0; k < 3; ++k) m.v.push_back(centre + vec3(pos(rng), pos(rng), pos(rng)));
    m.f.push_back({0, 1, 2});
    const glm::dvec3 A(m.v[0]), B(m.v[1]), C(m.v[2]);
    if (glm::length(glm::cross(B - A, C - A)) < 0.1) continue;
    auto s = mesh_scene(m, placing);
    float b1 = w(rng), b2 = w(rng);
    if (b1 + b2 > 0.99f) {
      b1 = 1.0f - b1;
      b2 = 1.0f - b2;
    }
    const vec3 target = test::transformed(placing, (1.0f - b1 - b2) * m.v[0] + b1 * m.v[1] + b2 * m.v[2]);
    const vec3 o = target + 3.0f * test::random_unit(rng);
    const Ray ray{o, glm::normalize(target - o)};
    const Hit h = intersect_closest(s->view, ray, kRayTMax);
    if (h.missed()) continue;  // a ray that grazes the triangle's plane
    const SurfacePoint sp = surface_at(s->view, ray, h);
    const vec3 tangent = glm::normalize(glm::cross(sp.ng, test::random_unit(rng)));
    std::vector<vec3> dirs;
    for (int k = 0; k < 16; ++k) dirs.push_back(test::random_unit(rng));
    for (float eps : {1e-2f, 1e-3f, 1e-4f, 1e-5f}) {
      dirs.push_back(glm::normalize(tangent + eps * sp.ng));
      dirs.push_back(glm::normalize(tangent - eps * sp.ng));
    }
    for (const vec3& d : dirs) {
      const Ray next = spawn_ray(sp, d);
      const Hit again = intersect_closest(s->view, next, kRayTMax);
      ++spawned;
      ASSERT_TRUE(again.missed()) << "triangle " << i << " near (" << centre.x << ", " << centre.y << ", "
                                  << centre.z << "): left along (" << d.x << ", " << d.y << ", " << d.z
                                  << "), hit again at t = " << again.t << " (offset " << sp.offset << ")";
    }
  }
  EXPECT_GT(spawned, 4000);
}

TEST(TriangleSelfHit, RaysLeavingATriangleFarFromTheOriginNeverHitItAgain) {
  expect_no_self_hits(glm::dmat4(1.0), 1e4f, 1);
  expect_no_self_hits(glm::dmat4(1.0), 1e5f, 2);
}

TEST(TriangleSelfHit, RaysLeavingAnInstanceMovedFarFromTheOriginNeverHitItAgain) {
  // The mesh near the origin, placed 1e4 away by a rotation, a scale and a move.
  expect_no_self_hits(test::trs({1e4, -2e4, 1.5e4}, {20, 40, -60}, {3, 0.5, 1.25}), 0.0f, 3);
}

}  // namespace
}  // namespace wt

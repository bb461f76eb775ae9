// intersect_sphere: analytic distances, the (tmin, tmax) window, rays from inside,
// tangent rays, and the two precision regimes the form is designed for (a small
// sphere seen from far away, and the huge ground sphere hit from just above it),
// both checked against a double-precision reference on the same float inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "wavetrace/geometry/sphere.hpp"

namespace wt {
namespace {

// The double-precision roots of |o + t d - c|^2 = r^2 for the float inputs as given
// (d is not assumed unit: the reference solves the exact problem the floats state).
// Returns false when the line misses.
struct Roots {
  double near, far;
  double disc;  // the reduced discriminant r^2 |d|^2 - |f x d|^2 (>= 0 on a hit)
};

bool reference_roots(const vec3& o, const vec3& d, const vec3& c, double r, Roots& out) {
  const double fx = double(o.x) - c.x, fy = double(o.y) - c.y, fz = double(o.z) - c.z;
  const double dx = d.x, dy = d.y, dz = d.z;
  const double a = dx * dx + dy * dy + dz * dz;
  const double b = -(fx * dx + fy * dy + fz * dz);
  // |f x d|^2 is the squared perpendicular distance times |d|^2; computed from the
  // cross product so that the reference has no cancellation of its own.
  const double cx = fy * dz - fz * dy, cy = fz * dx - fx * dz, cz = fx * dy - fy * dx;
  const double disc = r * r * a - (cx * cx + cy * cy + cz * cz);
  out.disc = disc;
  if (disc < 0) return false;
  const double s = std::sqrt(disc);
  const double q = b + std::copysign(s, b);
  const double cc = fx * fx + fy * fy + fz * fz - r * r;
  double t0 = cc / q, t1 = q / a;
  if (t0 > t1) std::swap(t0, t1);
  out.near = t0;
  out.far = t1;
  return true;
}

double distance_to_center(const Ray& ray, float t, const vec3& c) {
  const double px = double(ray.origin.x) + double(t) * ray.dir.x - c.x;
  const double py = double(ray.origin.y) + double(t) * ray.dir.y - c.y;
  const double pz = double(ray.origin.z) + double(t) * ray.dir.z - c.z;
  return std::sqrt(px * px + py * py + pz * pz);
}

constexpr float kBig = 1e30f;

TEST(Sphere, HeadOnAndParallelRaysHitAtAnalyticDistance) {
  // Ray along +z at lateral offset h from the centre of a unit sphere 5 away:
  // the near hit is at 5 - sqrt(1 - h^2).
  for (float h : {0.0f, 0.1f, 0.5f, 0.9f, 0.99f}) {
    Ray ray{vec3(h, 0.0f, -5.0f), vec3(0.0f, 0.0f, 1.0f)};
    float t = -1.0f;
    ASSERT_TRUE(intersect_sphere(ray, vec3(0.0f), 1.0f, 0.0f, kBig, t)) << "h=" << h;
    EXPECT_NEAR(t, 5.0 - std::sqrt(1.0 - double(h) * h), 2e-6) << "h=" << h;
  }
  // A displaced sphere of radius 2, approached along -x.
  Ray ray{vec3(10.0f, 1.0f, -2.0f), vec3(-1.0f, 0.0f, 0.0f)};
  float t = -1.0f;
  ASSERT_TRUE(intersect_sphere(ray, vec3(3.0f, 1.0f, -2.0f), 2.0f, 0.0f, kBig, t));
  EXPECT_FLOAT_EQ(t, 5.0f);
}

TEST(Sphere, MissesWhenRayPassesBesideOrPointsAway) {
  float t = 123.0f;
  // Passes at distance 1.5 from the centre of a unit sphere.
  EXPECT_FALSE(intersect_sphere(Ray{vec3(1.5f, 0.0f, -5.0f), vec3(0, 0, 1)}, vec3(0.0f), 1.0f, 0.0f, kBig, t));
  // Diagonal pass at distance 1.2.
  vec3 d = glm::normalize(vec3(1.0f, 1.0f, 0.0f));
  vec3 side = glm::normalize(vec3(1.0f, -1.0f, 0.0f));
  EXPECT_FALSE(intersect_sphere(Ray{1.2f * side - 7.0f * d, d}, vec3(0.0f), 1.0f, 0.0f, kBig, t));
  // The sphere is behind the origin: both roots negative.
  EXPECT_FALSE(intersect_sphere(Ray{vec3(0.0f, 0.0f, -5.0f), vec3(0, 0, -1)}, vec3(0.0f), 1.0f, 0.0f, kBig, t));
}

TEST(Sphere, RayStartingInsideReturnsTheFarRoot) {
  float t = -1.0f;
  // From the centre: the far root is the radius in every direction.
  for (vec3 d : {vec3(1, 0, 0), vec3(0, -1, 0), glm::normalize(vec3(1, 2, -3))}) {
    ASSERT_TRUE(intersect_sphere(Ray{vec3(2.0f, 3.0f, 4.0f), d}, vec3(2.0f, 3.0f, 4.0f), 1.5f, 1e-4f, kBig, t));
    EXPECT_NEAR(t, 1.5f, 1e-6f);
  }
  // Off-centre at z = 0.5 of a unit sphere: 0.5 forwards, 1.5 backwards.
  ASSERT_TRUE(intersect_sphere(Ray{vec3(0.0f, 0.0f, 0.5f), vec3(0, 0, 1)}, vec3(0.0f), 1.0f, 1e-4f, kBig, t));
  EXPECT_NEAR(t, 0.5f, 1e-6f);
  ASSERT_TRUE(intersect_sphere(Ray{vec3(0.0f, 0.0f, 0.5f), vec3(0, 0, -1)}, vec3(0.0f), 1.0f, 1e-4f, kBig, t));
  EXPECT_NEAR(t, 1.5f, 1e-6f);
  // A refracted ray just inside the surface (the dielectric case): it must find the
  // far side, not the surface it just crossed.
  vec3 d = glm::normalize(vec3(0.3f, -1.0f, 0.2f));
  vec3 o = vec3(0.0f, 1.0f - 1e-3f, 0.0f);
  ASSERT_TRUE(intersect_sphere(Ray{o, d}, vec3(0.0f), 1.0f, 1e-4f, kBig, t));
  Roots ref;
  ASSERT_TRUE(reference_roots(o, d, vec3(0.0f), 1.0, ref));
  EXPECT_NEAR(t, ref.far, 1e-5 * ref.far);
}

TEST(Sphere, TangentAndNearTangentRaysHitCleanlyOrMiss) {
  // Rays at lateral offset h from a unit sphere 5 away, for h at and around 1,
  // along an axis and along a skew direction (so the arithmetic rounds).
  const vec3 skew = glm::normalize(vec3(0.3f, -0.4f, 0.866f));
  const vec3 lateral = glm::normalize(glm::cross(skew, vec3(1.0f, 0.0f, 0.0f)));
  for (vec3 d : {vec3(0.0f, 0.0f, 1.0f), skew}) {
    vec3 side = d.z == 1.0f ? vec3(0.0f, 1.0f, 0.0f) : lateral;
    for (float h : {1.0f - 1e-3f, 1.0f - 1e-5f, std::nextafter(1.0f, 0.0f), 1.0f, std::nextafter(1.0f, 2.0f),
                    1.0f + 1e-5f, 1.0f + 1e-3f}) {
      Ray ray{h * side - 5.0f * d, d};
      float t = 777.0f;
      bool hit = intersect_sphere(ray, vec3(0.0f), 1.0f, 0.0f, kBig, t);
      if (hit) {
        // A hit must be a finite point on the sphere near the tangent point (t = 5).
        ASSERT_TRUE(std::isfinite(t)) << "h=" << h;
        EXPECT_NEAR(t, 5.0f, 0.05f) << "h=" << h;
        EXPECT_NEAR(distance_to_center(ray, t, vec3(0.0f)), 1.0, 1e-5) << "h=" << h;
      }
      // Clearly inside the silhouette must hit, clearly outside must miss
      // (1e-3 is far beyond float rounding at these magnitudes).
      if (h <= 1.0f - 1e-3f) {
        EXPECT_TRUE(hit) << "h=" << h;
      }
      if (h >= 1.0f + 1e-3f) {
        EXPECT_FALSE(hit) << "h=" << h;
      }
    }
  }
  // A ray that starts exactly on the sphere and leaves along the tangent: t = 0 is
  // not in (tmin, tmax), so no self-hit.
  float t = 0.0f;
  EXPECT_FALSE(intersect_sphere(Ray{vec3(0.0f, 1.0f, 0.0f), vec3(0, 0, 1)}, vec3(0.0f), 1.0f, 1e-4f, kBig, t));
}

TEST(Sphere, OnlyRootsStrictlyInsideTheWindowAreReturned) {
  // Roots at exactly 4 and 6 (c / q = 24 / 6 and q = 6 are exact in float).
  const Ray ray{vec3(0.0f, 0.0f, -5.0f), vec3(0, 0, 1)};
  const vec3 c(0.0f);
  float t = -1.0f;
  EXPECT_FALSE(intersect_sphere(ray, c, 1.0f, 0.0f, 3.0f, t));  // both beyond tmax
  ASSERT_TRUE(intersect_sphere(ray, c, 1.0f, 0.0f, 5.0f, t));
  EXPECT_EQ(t, 4.0f);
  ASSERT_TRUE(intersect_sphere(ray, c, 1.0f, 4.5f, 10.0f, t));  // near root before tmin
  EXPECT_EQ(t, 6.0f);
  EXPECT_FALSE(intersect_sphere(ray, c, 1.0f, 4.5f, 5.5f, t));  // window between roots
  EXPECT_FALSE(intersect_sphere(ray, c, 1.0f, 6.5f, 10.0f, t));  // both before tmin
  // The window is open: a root equal to tmax is excluded (the BVH passes the best
  // hit so far as tmax and must not take an equal one again), as is one equal to tmin.
  EXPECT_FALSE(intersect_sphere(ray, c, 1.0f, 0.0f, 4.0f, t));
  ASSERT_TRUE(intersect_sphere(ray, c, 1.0f, 4.0f, 10.0f, t));
  EXPECT_EQ(t, 6.0f);
}

TEST(Sphere, SmallSphereFarAwayMatchesDoubleReference) {
  // r = 0.2 at 1000 to 5000 units: b^2 - c would cancel all of r^2 away. Rays are
  // aimed at points of the sphere's silhouette disk within 0.95 r of its centre, so
  // every one must hit; t must match the reference to 1e-4 relative.
  std::mt19937 gen(12345);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const float r = 0.2f;
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    vec3 center(unit(gen) * 10.0f, unit(gen) * 10.0f, unit(gen) * 10.0f);
    vec3 away = glm::normalize(vec3(unit(gen), unit(gen), unit(gen)) + vec3(0.0f, 0.0f, 1e-3f));
    float dist = 1000.0f + 4000.0f * (0.5f + 0.5f * unit(gen));
    vec3 o = center + dist * away;
    // A point on the silhouette disk: perpendicular to the view direction.
    vec3 p1 = glm::normalize(glm::cross(away, std::fabs(away.x) < 0.9f ? vec3(1, 0, 0) : vec3(0, 1, 0)));
    vec3 p2 = glm::cross(away, p1);
    float rho = 0.95f * r * std::sqrt(0.5f + 0.5f * unit(gen));
    float phi = kPi * unit(gen);
    vec3 target = center + rho * (std::cos(phi) * p1 + std::sin(phi) * p2);
    Ray ray{o, glm::normalize(target - o)};
    Roots ref;
    ASSERT_TRUE(reference_roots(ray.origin, ray.dir, center, r, ref)) << i;
    float t = -1.0f;
    ASSERT_TRUE(intersect_sphere(ray, center, r, 1e-4f, kBig, t)) << "case " << i << " dist " << dist;
    EXPECT_NEAR(t, ref.near, 1e-4 * ref.near) << "case " << i;
    ++checked;
  }
  EXPECT_EQ(checked, 2000);
}

TEST(Sphere, HugeGroundSphereAtGrazingAnglesMatchesDoubleReference) {
  // The reference scene's ground: r = 1000 at (0, -1000, 0). Origins 1e-3 (a spawned
  // secondary ray) to 10 units above its surface, directions from 1e-4 rad to 0.5 rad
  // below the local tangent plane, and some above it. Near tangency the answer is
  // ill-conditioned in the inputs, so the reference is a bracket: the exact roots for
  // the radius perturbed by +-8 float ulps (8 * 2^-24 relative, about 5e-4 units),
  // which is well below the precision the float inputs themselves carry at 1000.
  // The float t must lie in that bracket (plus 1e-6 relative for its own rounding);
  // where the perturbed radii disagree on hit or miss, either answer is accepted but
  // a hit must still lie on the sphere.
  const vec3 c(0.0f, -1000.0f, 0.0f);
  const float r = 1000.0f;
  const double dr = 8.0 * r * std::ldexp(1.0, -24);
  std::mt19937 gen(777);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  int hits = 0, misses = 0, ambiguous = 0;
  for (float h : {1e-3f, 1e-2f, 0.1f, 1.0f, 10.0f}) {
    for (int k = 0; k < 400; ++k) {
      // Origin above a point within ~3 degrees of the top of the sphere.
      vec3 n0 = glm::normalize(vec3(0.05f * unit(gen), 1.0f, 0.05f * unit(gen)));
      vec3 o = c + (r + h) * n0;
      // Tangent frame at the origin's foot point.
      vec3 t1 = glm::normalize(glm::cross(n0, vec3(0.0f, 0.0f, 1.0f)));
      vec3 t2 = glm::cross(n0, t1);
      float az = kPi * unit(gen);
      vec3 horiz = std::cos(az) * t1 + std::sin(az) * t2;
      // Elevation: log-uniform in [1e-4, 0.5] rad, below the plane 85% of the time.
      float mag = std::exp(std::log(1e-4f) + (std::log(0.5f) - std::log(1e-4f)) * (0.5f + 0.5f * unit(gen)));
      float elev = (k % 7 == 0) ? mag : -mag;
      Ray ray{o, glm::normalize(std::cos(elev) * horiz + std::sin(elev) * n0)};

      Roots lo, hi;
      bool hit_small = reference_roots(ray.origin, ray.dir, c, r - dr, lo);
      bool hit_large = reference_roots(ray.origin, ray.dir, c, r + dr, hi);
      // Only positive roots count (tmin 1e-4); the origin is outside both radii.
      hit_small = hit_small && lo.near > 1e-4;
      hit_large = hit_large && hi.near > 1e-4;
      float t = -1.0f;
      bool hit = intersect_sphere(ray, c, r, 1e-4f, kBig, t);
      if (hit) {
        ASSERT_TRUE(std::isfinite(t));
        EXPECT_NEAR(distance_to_center(ray, t, c), r, 2.0 * dr + 1e-6 * t)
            << "h=" << h << " elev=" << elev << " t=" << t;
      }
      if (hit_small && hit_large) {
        ++hits;
        ASSERT_TRUE(hit) << "h=" << h << " elev=" << elev;
        // The larger radius is met first.
        EXPECT_GE(t, hi.near * (1.0 - 1e-6)) << "h=" << h << " elev=" << elev;
        EXPECT_LE(t, lo.near * (1.0 + 1e-6)) << "h=" << h << " elev=" << elev;
      } else if (!hit_small && !hit_large) {
        ++misses;
        EXPECT_FALSE(hit) << "h=" << h << " elev=" << elev << " t=" << t;
      } else {
        ++ambiguous;
      }
    }
  }
  // The sweep must exercise both outcomes, not only one of them.
  EXPECT_GT(hits, 500);
  EXPECT_GT(misses, 200);
  EXPECT_LT(ambiguous, 50);
}

TEST(Sphere, ReturnedPointLiesOnTheSphere) {
  std::mt19937 gen(99);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  for (int i = 0; i < 5000; ++i) {
    vec3 c(unit(gen) * 5.0f, unit(gen) * 5.0f, unit(gen) * 5.0f);
    float r = 0.1f + 3.0f * (0.5f + 0.5f * unit(gen));
    // Origins outside and inside the sphere, rays towards random points of it.
    vec3 o = c + (i % 3 == 0 ? 0.5f * r : 4.0f * r) * glm::normalize(vec3(unit(gen), unit(gen), unit(gen)));
    vec3 target = c + 0.99f * r * glm::normalize(vec3(unit(gen), unit(gen), unit(gen)));
    Ray ray{o, glm::normalize(target - o)};
    float t = -1.0f;
    ASSERT_TRUE(intersect_sphere(ray, c, r, 1e-4f, kBig, t)) << i;
    // float positions of magnitude ~20 carry ~2e-6 absolute rounding.
    EXPECT_NEAR(distance_to_center(ray, t, c), r, 1e-5 + 4e-6 * r) << i;
  }
}

}  // namespace
}  // namespace wt

// Sampling emitters (wavetrace/lights.hpp): every sample meets its light where it
// says, the densities are what the samplers draw from (their integrals are the
// lights' solid angles, checked against closed forms), the sphere's cone sampler
// gives the analytic irradiance under a spherical lamp, and the two MIS weights of
// a direction sum to one.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "wavetrace/geometry/sphere.hpp"
#include "wavetrace/lights.hpp"

namespace wt {
namespace {

constexpr double kPiD = 3.14159265358979323846;

struct Stats {
  double sum = 0, sum2 = 0;
  int n = 0;
  void add(double x) {
    sum += x;
    sum2 += x * x;
    ++n;
  }
  double mean() const { return sum / n; }
  double standard_error() const { return std::sqrt(std::max(0.0, sum2 / n - mean() * mean()) / n); }
};

TEST(LightSampling, OrthonormalBasisIsOrthonormal) {
  std::mt19937 rng(1);
  std::normal_distribution<float> g;
  for (int i = 0; i < 1000; ++i) {
    vec3 n = glm::normalize(vec3(g(rng), g(rng), g(rng)));
    if (i == 0) n = vec3(0, 0, -1);  // the sign's edge
    if (i == 1) n = vec3(0, 0, 1);
    vec3 t, b;
    orthonormal_basis(n, t, b);
    EXPECT_NEAR(glm::dot(t, t), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(b, b), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(t, n), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(b, n), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(t, b), 0.0f, 1e-5f);
    EXPECT_GT(glm::dot(glm::cross(t, b), n), 0.99f);  // right-handed
  }
}

// Every cone sample meets the sphere, at the distance it says, with the density
// the pdf function gives.
TEST(LightSampling, SphereSamplesMeetTheSphereWhereTheySay) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const vec3 c(1.0f, 2.0f, -3.0f);
  for (float d : {1.01f, 1.5f, 4.0f, 100.0f}) {
    const vec3 p = c + d * glm::normalize(vec3(0.3f, -1.0f, 0.2f));
    for (int i = 0; i < 2000; ++i) {
      const LightSample s = sample_sphere_light(c, 1.0f, p, u(rng), u(rng));
      ASSERT_GT(s.pdf, 0.0f);
      EXPECT_FLOAT_EQ(s.pdf, sphere_light_pdf(c, 1.0f, p));
      float t;
      ASSERT_TRUE(intersect_sphere(Ray{p, s.dir}, c, 1.0f, 0.0f, 1e30f, t)) << "d " << d << " sample " << i;
      EXPECT_NEAR(s.dist, t, 2e-4f * d) << "d " << d;
    }
  }
  EXPECT_EQ(sample_sphere_light(c, 1.0f, c + vec3(0.5f, 0, 0), 0.3f, 0.6f).pdf, 0.0f) << "inside";
  EXPECT_EQ(sphere_light_pdf(c, 1.0f, c + vec3(0, 0.99f, 0)), 0.0f) << "inside";
}

// The integral of 1 / pdf over the samples is the cone's solid angle; so is 4 pi
// times the fraction of uniform directions that meet the sphere. Both against the
// closed form 2 pi (1 - sqrt(1 - r^2 / d^2)), each within four of its standard errors.
TEST(LightSampling, SphereDensityIsUniformOverItsSolidAngle) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const vec3 c(0.0f);
  for (double d : {1.2, 3.0, 10.0}) {
    const vec3 p(0.0f, 0.0f, static_cast<float>(d));
    const double exact = 2.0 * kPiD * (1.0 - std::sqrt(1.0 - 1.0 / (d * d)));
    EXPECT_NEAR(1.0 / sphere_light_pdf(c, 1.0f, p), exact, 1e-5 * exact) << d;
    const int n = 400000;
    int met = 0;
    for (int i = 0; i < n; ++i) {
      const float z = 1.0f - 2.0f * u(rng), phi = 2.0f * kPi * u(rng), r = std::sqrt(std::max(0.0f, 1.0f - z * z));
      float t;
      met += intersect_sphere(Ray{p, vec3(r * std::cos(phi), r * std::sin(phi), z)}, c, 1.0f, 0.0f, 1e30f, t);
    }
    const double f = static_cast<double>(met) / n;
    EXPECT_NEAR(4.0 * kPiD * f, exact, 4.0 * 4.0 * kPiD * std::sqrt(f * (1.0 - f) / n)) << d;
    // The cosines of the cone samples are uniform on [cos theta_max, 1]: 20 bins,
    // chi-square against the 0.1% critical value of 19 degrees of freedom (43.82).
    const double cos_max = std::sqrt(1.0 - 1.0 / (d * d));
    std::vector<int> bins(20, 0);
    const int m = 100000;
    for (int i = 0; i < m; ++i) {
      const LightSample s = sample_sphere_light(c, 1.0f, p, u(rng), u(rng));
      const double cos_theta = -s.dir.z;
      const int bin = static_cast<int>((cos_theta - cos_max) / (1.0 - cos_max) * 20.0);
      ++bins[std::min(19, std::max(0, bin))];
    }
    double chi2 = 0;
    for (int b : bins) chi2 += (b - m / 20.0) * (b - m / 20.0) / (m / 20.0);
    EXPECT_LT(chi2, 43.82) << d;
  }
}

// Small and far: 1 - cos(theta_max) is near 1e-8, within a rounding of 1 of the
// cosine itself; the density keeps its precision.
TEST(LightSampling, TinyFarSphereKeepsItsDensity) {
  const double d = 1e4, r = 1.0;
  const double exact = 2.0 * kPiD * (r * r / (d * d)) / (1.0 + std::sqrt(1.0 - r * r / (d * d)));
  const float pdf = sphere_light_pdf(vec3(0.0f), 1.0f, vec3(0.0f, 0.0f, static_cast<float>(d)));
  EXPECT_NEAR(1.0 / pdf, exact, 1e-5 * exact);
}

// Under a sphere of radiance L seen at angular radius alpha straight overhead, a
// surface receives E = pi L sin^2(alpha). The cone-sampled estimator of E (L cos /
// pdf, averaged) must agree within four standard errors, and the standard error
// must be small (the estimator is nearly constant for a small lamp).
TEST(LightSampling, ConeSamplingGivesTheAnalyticIrradianceUnderASphere) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float radiance = 5.0f;
  for (double d : {1.5, 4.0, 20.0}) {
    const vec3 c(0.0f, static_cast<float>(d), 0.0f), p(0.0f), normal(0, 1, 0);
    Stats e;
    for (int i = 0; i < 100000; ++i) {
      const LightSample s = sample_sphere_light(c, 1.0f, p, u(rng), u(rng));
      e.add(radiance * std::max(0.0f, glm::dot(s.dir, normal)) / s.pdf);
    }
    const double exact = kPiD * radiance / (d * d);
    EXPECT_NEAR(e.mean(), exact, 4.0 * e.standard_error() + 1e-6 * exact) << d;
    EXPECT_LT(e.standard_error(), 0.01 * exact) << d;
  }
}

// The solid angle of a triangle seen from the origin (Van Oosterom and Strackee).
double triangle_solid_angle(const vec3& a, const vec3& b, const vec3& c) {
  const glm::dvec3 r1(a), r2(b), r3(c);
  const double l1 = glm::length(r1), l2 = glm::length(r2), l3 = glm::length(r3);
  const double numerator = std::fabs(glm::dot(r1, glm::cross(r2, r3)));
  const double denominator =
      l1 * l2 * l3 + glm::dot(r1, r2) * l3 + glm::dot(r1, r3) * l2 + glm::dot(r2, r3) * l1;
  double omega = 2.0 * std::atan2(numerator, denominator);
  return omega < 0 ? omega + 2.0 * kPiD : omega;
}

// Every triangle sample lies on the triangle (inside it, on its plane), its
// density is the pdf function's, and 1 / pdf averages to the triangle's solid
// angle (within four standard errors), seen face-on, obliquely and from behind.
TEST(LightSampling, TriangleSamplesAreUniformByAreaAndIntegrateToItsSolidAngle) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const vec3 a(-1.0f, 2.0f, -1.0f), b(2.0f, 2.5f, -1.0f), c(0.0f, 2.0f, 1.5f);
  for (const vec3& p : {vec3(0.2f, 0.0f, 0.1f), vec3(5.0f, 1.0f, 3.0f), vec3(0.0f, 4.0f, 0.0f)}) {
    Stats inverse;
    for (int i = 0; i < 200000; ++i) {
      const LightSample s = sample_triangle_light(a, b, c, p, u(rng), u(rng));
      ASSERT_GT(s.pdf, 0.0f);
      const vec3 q = p + s.dist * s.dir;
      // Barycentric coordinates of q: all in [0, 1] (up to rounding), and q on the plane.
      const glm::dvec3 e1 = glm::dvec3(b - a), e2 = glm::dvec3(c - a), w = glm::dvec3(q - a);
      const glm::dvec3 n = glm::cross(e1, e2);
      const double beta = glm::dot(glm::cross(w, e2), n) / glm::dot(n, n);
      const double gamma = glm::dot(glm::cross(e1, w), n) / glm::dot(n, n);
      EXPECT_GE(beta, -1e-5);
      EXPECT_GE(gamma, -1e-5);
      EXPECT_LE(beta + gamma, 1.0 + 1e-5);
      EXPECT_NEAR(glm::dot(w, n) / glm::length(n), 0.0, 1e-5);
      EXPECT_FLOAT_EQ(s.pdf, triangle_light_pdf(a, b, c, s.dir, s.dist));
      inverse.add(1.0 / s.pdf);
    }
    const double exact = triangle_solid_angle(a - p, b - p, c - p);
    EXPECT_NEAR(inverse.mean(), exact, 4.0 * inverse.standard_error() + 1e-6) << p.x << ", " << p.y << ", " << p.z;
  }
  // Seen edge-on the triangle has no density (and no sample with one).
  EXPECT_EQ(triangle_light_pdf(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 0, 1), vec3(1, 0, 0), 2.0f), 0.0f);
}

TEST(LightSampling, PowerHeuristicWeightsSumToOne) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> logd(-10.0f, 10.0f);
  for (int i = 0; i < 10000; ++i) {
    const float f = std::exp(logd(rng)), g = std::exp(logd(rng));
    EXPECT_NEAR(power_heuristic(f, g) + power_heuristic(g, f), 1.0f, 1e-6f);
    EXPECT_GE(power_heuristic(f, g), 0.0f);
  }
  EXPECT_EQ(power_heuristic(3.0f, 0.0f), 1.0f);  // the other strategy cannot draw it
  EXPECT_EQ(power_heuristic(0.0f, 3.0f), 0.0f);
  EXPECT_FLOAT_EQ(power_heuristic(1.0f, 1.0f), 0.5f);
  EXPECT_FLOAT_EQ(power_heuristic(2.0f, 1.0f), 0.8f);
}

}  // namespace
}  // namespace wt

// reflect, refract and schlick against the laws they implement: the mirror law,
// Snell's law as a ratio of sines, the critical angle, and Schlick's end points.
#include <gtest/gtest.h>

#include <cmath>

#include "wavetrace/optics.hpp"

namespace wt {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// A unit direction arriving at the surface with normal +y at angle theta from the
// normal, travelling in the x-y plane (and a little along z when skewed, so the
// test is not only axis-aligned arithmetic).
vec3 incoming(double theta_deg, bool skew = false) {
  double s = std::sin(theta_deg * kDeg), c = std::cos(theta_deg * kDeg);
  vec3 d(float(s), float(-c), 0.0f);
  if (skew) d = vec3(float(s * 0.6), float(-c), float(s * 0.8));
  return glm::normalize(d);
}

double sin_to_normal(const vec3& d, const vec3& n) {
  // |d x n| / |d|: sin of the angle between the line of d and the normal.
  return double(glm::length(glm::cross(d, n))) / double(glm::length(d));
}

TEST(Optics, ReflectMirrorsAboutTheNormal) {
  const vec3 n(0.0f, 1.0f, 0.0f);
  vec3 r = reflect(glm::normalize(vec3(1.0f, -1.0f, 0.0f)), n);
  EXPECT_NEAR(r.x, std::sqrt(0.5), 1e-7);
  EXPECT_NEAR(r.y, std::sqrt(0.5), 1e-7);
  EXPECT_EQ(r.z, 0.0f);
  // Normal incidence comes straight back.
  r = reflect(vec3(0.0f, -1.0f, 0.0f), n);
  EXPECT_EQ(r, vec3(0.0f, 1.0f, 0.0f));
  // Against a tilted normal: the normal component flips, the tangential one stays,
  // the length is kept.
  const vec3 tn = glm::normalize(vec3(1.0f, 2.0f, -2.0f));
  const vec3 d = glm::normalize(vec3(-0.3f, -0.9f, 0.4f));
  r = reflect(d, tn);
  EXPECT_NEAR(glm::dot(r, tn), -glm::dot(d, tn), 1e-6f);
  vec3 tan_d = d - glm::dot(d, tn) * tn, tan_r = r - glm::dot(r, tn) * tn;
  EXPECT_NEAR(glm::length(tan_r - tan_d), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(r), 1.0f, 1e-6f);
}

TEST(Optics, RefractObeysSnellBothWays) {
  const vec3 n(0.0f, 1.0f, 0.0f);
  // eta < 1 (into glass) at any angle; eta > 1 (out of glass) only below the
  // critical angle asin(1/1.5) = 41.8 degrees.
  struct Case {
    float eta;
    double max_deg;
  };
  for (Case cs : {Case{1.0f / 1.5f, 89.0}, Case{1.0f / 1.33f, 89.0}, Case{1.5f, 41.0}, Case{2.4f, 24.0}}) {
    for (double deg : {0.0, 5.0, 15.0, 30.0, 40.0, 60.0, 75.0, 89.0}) {
      if (deg > cs.max_deg) continue;
      for (bool skew : {false, true}) {
        vec3 d = incoming(deg, skew);
        vec3 out(0.0f);
        ASSERT_TRUE(refract(d, n, cs.eta, out)) << "eta=" << cs.eta << " deg=" << deg;
        // Snell: sin(theta_t) = eta * sin(theta_i).
        EXPECT_NEAR(sin_to_normal(out, n), cs.eta * sin_to_normal(d, n), 2e-6) << "eta=" << cs.eta << " deg=" << deg;
        // It stays unit length, goes on through the surface, and stays in the plane
        // of incidence on the same side as the incoming tangential direction.
        EXPECT_NEAR(glm::length(out), 1.0f, 2e-6f);
        EXPECT_LT(out.y, 0.0f);
        EXPECT_NEAR(glm::dot(out, glm::cross(d, n)), 0.0f, 2e-6f);
        vec3 tan_d = d - d.y * n, tan_o = out - out.y * n;
        EXPECT_GE(glm::dot(tan_d, tan_o), 0.0f);
      }
    }
  }
}

TEST(Optics, TotalInternalReflectionExactlyBeyondTheCriticalAngle) {
  const vec3 n(0.0f, 1.0f, 0.0f);
  const float eta = 1.5f;  // glass to air
  const double critical = std::asin(1.0 / 1.5) / kDeg;  // 41.81 degrees
  vec3 out;
  for (double deg : {0.0, 20.0, 41.0, critical - 0.05}) {
    EXPECT_TRUE(refract(incoming(deg), n, eta, out)) << deg;
  }
  for (double deg : {critical + 0.05, 45.0, 60.0, 80.0, 89.9}) {
    EXPECT_FALSE(refract(incoming(deg), n, eta, out)) << deg;
  }
  // Into the denser medium there is no critical angle.
  for (double deg : {45.0, 60.0, 89.9}) {
    EXPECT_TRUE(refract(incoming(deg), n, 1.0f / eta, out)) << deg;
  }
}

TEST(Optics, SchlickEndPointsAndMonotonic) {
  for (float eta : {1.0f / 1.5f, 1.5f, 1.0f / 1.33f, 1.0f / 2.4f}) {
    // Normal incidence: r0 = ((1 - eta) / (1 + eta))^2; (1/1.5 and 1.5 both give 0.04).
    double r0 = std::pow((1.0 - eta) / (1.0 + eta), 2.0);
    EXPECT_NEAR(schlick(1.0f, eta), r0, 1e-7) << eta;
    // Grazing incidence reflects everything.
    EXPECT_NEAR(schlick(0.0f, eta), 1.0f, 1e-7f) << eta;
    // Reflectance falls monotonically from grazing to normal incidence.
    float prev = schlick(0.0f, eta);
    for (int i = 1; i <= 1000; ++i) {
      float cur = schlick(float(i) / 1000.0f, eta);
      EXPECT_LE(cur, prev) << "eta=" << eta << " cos=" << float(i) / 1000.0f;
      prev = cur;
    }
  }
  EXPECT_NEAR(schlick(1.0f, 1.0f / 1.5f), 0.04f, 1e-7f);
  // The quintic in between: at cos = 0.5, r0 + (1 - r0) / 32.
  EXPECT_NEAR(schlick(0.5f, 1.0f / 1.5f), 0.04 + 0.96 / 32.0, 1e-7);
  // Matched media do not reflect at all except at grazing incidence.
  EXPECT_EQ(schlick(1.0f, 1.0f), 0.0f);
}

}  // namespace
}  // namespace wt

// The direction samplers: each maps two uniforms to the distribution it promises.
// Uniforms come from the project's Rng (dims kDimScatterA / kDimScatterB, the pixel
// varying), so the test also covers the combination the renderer actually runs.
//
// Statistical thresholds: each chi-square test uses 50 equiprobable bins
// (df = 49) over 200k samples (4000 expected per bin) and rejects above 111.14,
// the chi-square(49) upper-tail 1e-6 critical value (computed with mpmath). With the
// 9 such tests here, a correct sampler with an ideal Rng fails one of them with
// probability about 9e-6. Streams are fixed, so results are reproducible.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "wavetrace/rng.hpp"
#include "wavetrace/sampling.hpp"

namespace wt {
namespace {

constexpr int kSamples = 200000;
constexpr int kBins = 50;
constexpr double kChi2Crit49 = 111.14;

struct Histogram {
  std::vector<long> counts = std::vector<long>(kBins, 0);
  long total = 0;
  // x in [0, 1]; x == 1 goes to the last bin.
  void add(double x) {
    int b = int(x * kBins);
    if (b < 0) b = 0;  // rounding of values that are analytically >= 0
    if (b >= kBins) b = kBins - 1;
    counts[size_t(b)]++;
    ++total;
  }
  double chi2() const {
    double e = double(total) / kBins, s = 0.0;
    for (long c : counts) s += (c - e) * (c - e) / e;
    return s;
  }
};

// The two uniforms the materials use, for path i.
void uniforms(int i, float& u1, float& u2) {
  Rng rng = Rng::at(2024, uint32_t(i), 0, 1);
  u1 = rng.uniform(kDimScatterA);
  u2 = rng.uniform(kDimScatterB);
}

// An orthonormal frame (t1, t2, n) around unit n.
void frame(const vec3& n, vec3& t1, vec3& t2) {
  t1 = glm::normalize(glm::cross(std::fabs(n.x) < 0.9f ? vec3(1, 0, 0) : vec3(0, 1, 0), n));
  t2 = glm::cross(n, t1);
}

double phi01(double x, double y) {
  double phi = std::atan2(y, x);
  return (phi < 0 ? phi + 2.0 * 3.14159265358979323846 : phi) / (2.0 * 3.14159265358979323846);
}

TEST(Sampling, CosineDirectionIsCosineDistributedAboutTheNormal) {
  // For density cos(theta) / pi, cos^2(theta) is uniform on [0, 1] and the azimuth
  // is uniform; both are binned equiprobably. Checked about +z and about a skew normal.
  for (vec3 n : {vec3(0.0f, 0.0f, 1.0f), glm::normalize(vec3(-0.4f, 0.7f, 0.2f))}) {
    vec3 t1, t2;
    frame(n, t1, t2);
    Histogram cos2, az;
    for (int i = 0; i < kSamples; ++i) {
      float u1, u2;
      uniforms(i, u1, u2);
      vec3 d = cosine_direction(n, u1, u2);
      ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f) << i;
      double c = glm::dot(d, n);
      ASSERT_GE(c, -1e-6) << "below the surface, sample " << i;
      cos2.add(c * c);
      az.add(phi01(glm::dot(d, t1), glm::dot(d, t2)));
    }
    EXPECT_LT(cos2.chi2(), kChi2Crit49) << "cos^2(theta) about " << n.x << "," << n.y << "," << n.z;
    EXPECT_LT(az.chi2(), kChi2Crit49) << "azimuth about " << n.x << "," << n.y << "," << n.z;
  }
}

TEST(Sampling, CosineDirectionFallsBackToTheNormalWhenTheSumVanishes) {
  // unit_sphere_point(0, u2) is exactly +z, so with n = -z the sum is zero.
  vec3 n(0.0f, 0.0f, -1.0f);
  vec3 d = cosine_direction(n, 0.0f, 0.3f);
  EXPECT_EQ(d, n);
  // The extreme uniforms the Rng can produce still give finite unit vectors.
  const float top = 1.0f - std::ldexp(1.0f, -24);
  for (float u1 : {0.0f, top})
    for (float u2 : {0.0f, 0.5f, top}) {
      for (vec3 nn : {vec3(0, 0, 1), vec3(0, 0, -1), vec3(1, 0, 0)}) {
        vec3 e = cosine_direction(nn, u1, u2);
        ASSERT_TRUE(std::isfinite(e.x) && std::isfinite(e.y) && std::isfinite(e.z));
        EXPECT_NEAR(glm::length(e), 1.0f, 1e-5f);
        EXPECT_GE(glm::dot(e, nn), 0.0f);
      }
    }
}

TEST(Sampling, UnitSpherePointIsUniformOnTheSphere) {
  // Archimedes: z is uniform on [-1, 1] for a uniform point on the sphere, and the
  // azimuth is uniform and independent; the z-x plane azimuth is checked too so the
  // test is not blind to a distribution symmetric about z only.
  Histogram z, az, az_y;
  for (int i = 0; i < kSamples; ++i) {
    float u1, u2;
    uniforms(i, u1, u2);
    vec3 p = unit_sphere_point(u1, u2);
    ASSERT_NEAR(glm::length(p), 1.0f, 1e-6f) << i;
    z.add(0.5 * (double(p.z) + 1.0));
    az.add(phi01(p.x, p.y));
    az_y.add(phi01(p.z, p.x));
  }
  EXPECT_LT(z.chi2(), kChi2Crit49);
  EXPECT_LT(az.chi2(), kChi2Crit49);
  // The uniform distribution is rotation invariant: the azimuth about y is uniform too.
  EXPECT_LT(az_y.chi2(), kChi2Crit49);
}

TEST(Sampling, UnitDiskPointIsInsideAndUniformInArea) {
  // Uniform in area: r^2 is uniform on [0, 1], the angle uniform; and x alone has
  // the semicircle law, so the fraction with |x| < 0.5 is (pi/6 + sqrt(3)/4) / (pi/2).
  Histogram r2, az;
  long inner_x = 0;
  for (int i = 0; i < kSamples; ++i) {
    float u1, u2;
    uniforms(i, u1, u2);
    vec2 p = unit_disk_point(u1, u2);
    double rr = double(p.x) * p.x + double(p.y) * p.y;
    ASSERT_LE(rr, 1.0 + 1e-6) << i;
    r2.add(rr);
    az.add(phi01(p.x, p.y));
    if (std::fabs(p.x) < 0.5f) ++inner_x;
  }
  EXPECT_LT(r2.chi2(), kChi2Crit49);
  EXPECT_LT(az.chi2(), kChi2Crit49);
  const double pi = 3.14159265358979323846;
  const double expect = (pi / 6.0 + std::sqrt(3.0) / 4.0) / (pi / 2.0);  // 0.609
  // Binomial sd = sqrt(p(1-p)/N) = 1.09e-3; 5.3 sd is a two-sided 1.2e-7 tail.
  EXPECT_NEAR(double(inner_x) / kSamples, expect, 5.3 * std::sqrt(expect * (1 - expect) / kSamples));
}

TEST(Sampling, ExtremeUniformsGiveUnitVectorsAndDiskPoints) {
  const float top = 1.0f - std::ldexp(1.0f, -24);
  for (float u1 : {0.0f, 0.5f, top})
    for (float u2 : {0.0f, 0.25f, top}) {
      vec3 p = unit_sphere_point(u1, u2);
      EXPECT_NEAR(glm::length(p), 1.0f, 1e-6f);
      vec2 q = unit_disk_point(u1, u2);
      EXPECT_LE(glm::length(q), 1.0f);
    }
  // The poles: u1 = 0 is +z.
  EXPECT_EQ(unit_sphere_point(0.0f, 0.7f), vec3(0.0f, 0.0f, 1.0f));
  EXPECT_EQ(unit_disk_point(0.0f, 0.7f), vec2(0.0f, 0.0f));
}

}  // namespace
}  // namespace wt

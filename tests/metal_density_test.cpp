// The density of the fuzzy metal's scattering (metal_fuzz_pdf in
// wavetrace/material.hpp) against what scatter_metal draws: it integrates to 1
// over the sphere of directions, directions drawn the way scatter_metal draws them
// follow it (Pearson's chi-square, which a density off by a factor or of the wrong
// shape fails by far), it is the same all around the mirror direction and agrees
// with the geometry solved in double, it is 0 outside the cone the fuzz reaches, and
// it is finite everywhere, the rim of the cone included.
//
// Uniforms come from the project's Rng with fixed keys, so the statistical test is
// reproducible; its threshold is stated where it is used.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "wavetrace/bsdf.hpp"
#include "wavetrace/rng.hpp"

namespace wt {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// The fuzz values tested: small, middling, an arbitrary one, just below 1 (the
// cone's rim near the horizon of r), 1 exactly (the cosine lobe), and two above 1
// (every direction reachable).
const float kFuzzes[] = {0.05f, 0.3f, 0.5297f, 0.99f, 1.0f, 1.5f, 3.0f};

// Mirror directions: an axis and two that are not, so that no component is 0.
const vec3 kReflected[] = {vec3(0.0f, 0.0f, 1.0f), glm::normalize(vec3(1.0f, 2.0f, 3.0f)),
                           glm::normalize(vec3(-0.3f, 0.8f, -0.52f))};

using Density = std::function<double(const vec3& reflected, float fuzz, const vec3& dir)>;

double tested_density(const vec3& reflected, float fuzz, const vec3& dir) {
  return metal_fuzz_pdf(reflected, fuzz, dir);
}

// scatter_metal's direction before its absorption test, with the same arithmetic
// (FuzzyDirectionIsScatterMetals checks that they agree). False where r + fuzz s
// vanishes, where scatter_metal absorbs the path.
bool fuzzy_direction(const vec3& reflected, float fuzz, const Rng& rng, vec3& dir) {
  vec3 d = reflected + fuzz * unit_sphere_point(rng.uniform(kDimFuzzA), rng.uniform(kDimFuzzB));
  const float len2 = glm::dot(d, d);
  if (len2 < 1e-12f) return false;
  dir = d * (1.0f / sqrtf(len2));
  return true;
}

// An orthonormal frame (t, b, r) about a mirror direction, in double.
struct Frame {
  glm::dvec3 t, b, r;
  explicit Frame(const vec3& reflected) : r(glm::normalize(glm::dvec3(reflected))) {
    const glm::dvec3 helper = std::fabs(r.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    t = glm::normalize(glm::cross(helper, r));
    b = glm::cross(r, t);
  }
  // The float direction at angle a from r (given by its cosine and sine) and
  // azimuth phi about it.
  vec3 at(double cos_a, double sin_a, double phi) const {
    return vec3(sin_a * (std::cos(phi) * t + std::sin(phi) * b) + cos_a * r);
  }
  double azimuth(const vec3& dir) const {
    const glm::dvec3 d(dir);
    const double phi = std::atan2(glm::dot(d, b), glm::dot(d, t));
    return phi < 0.0 ? phi + 2.0 * kPiD : phi;
  }
};

// sin^2 and cos of the angle between a float direction and r, in double.
void angle_of(const vec3& dir, const vec3& reflected, double& sin2, double& cos_a) {
  const glm::dvec3 d(dir), r(reflected);
  const glm::dvec3 x = glm::cross(d - r, r);
  sin2 = glm::dot(x, x) / (glm::dot(d, d) * glm::dot(r, r));
  cos_a = glm::dot(d, r) / std::sqrt(glm::dot(d, d) * glm::dot(r, r));
}

// The radial coordinate the integrals run over, in which density x Jacobian is
// smooth. fuzz < 1: q = sqrt(fuzz^2 - sin^2 a) on [0, fuzz] (q = fuzz at r, 0 on the
// rim), where cos a = sqrt(1 - fuzz^2 + q^2) and d(cos a) = q / cos a dq: the density
// grows like 1 / q at the rim and q / cos a takes that away. fuzz >= 1: cos a itself,
// on [-1, 1] (on [0, 1] at fuzz = 1: nothing reaches c < 0 there).
struct Radial {
  float fuzz;
  bool cone() const { return fuzz < 1.0f; }
  double lo() const { return cone() ? 0.0 : (fuzz == 1.0f ? 0.0 : -1.0); }
  double hi() const { return cone() ? double(fuzz) : 1.0; }
  void angle(double x, double& cos_a, double& sin_a) const {
    if (cone()) {
      const double f = fuzz;
      cos_a = std::sqrt((1.0 - f) * (1.0 + f) + x * x);
      sin_a = std::sqrt((f - x) * (f + x));
    } else {
      cos_a = x;
      sin_a = std::sqrt((1.0 - x) * (1.0 + x));
    }
  }
  // The coordinate of a float direction; false where it lies outside [lo, hi]
  // by more than rounding.
  bool of(const vec3& dir, const vec3& reflected, double& x) const {
    double sin2, cos_a;
    angle_of(dir, reflected, sin2, cos_a);
    const double f = fuzz;
    if (cone()) {
      if (cos_a <= 0.0 || sin2 > f * f * (1.0 + 1e-5)) return false;
      x = std::sqrt(std::max(0.0, f * f - sin2));
    } else {
      if (cos_a < lo() - 1e-6) return false;
      x = cos_a;
    }
    x = std::min(hi(), std::max(lo(), x));
    return true;
  }
  // density(dir) x d(cos a)/dx at the direction at (x, phi). The Jacobian is taken
  // at the float direction actually passed, not at x: near the rim rounding the
  // direction to float moves it by about 1e-7 radians, which changes q a lot there,
  // but density x Jacobian at the direction's own q is smooth.
  double weighted(const Density& density, const Frame& frame, const vec3& reflected, double x, double phi) const {
    double cos_a, sin_a;
    angle(x, cos_a, sin_a);
    const vec3 dir = frame.at(cos_a, sin_a, phi);
    const double p = density(reflected, fuzz, dir);
    if (!cone()) return p;
    double sin2, c;
    angle_of(dir, reflected, sin2, c);
    const double f = fuzz;
    const double q = std::sqrt(std::max(0.0, f * f - sin2));
    return p == 0.0 ? 0.0 : p * q / c;
  }
};

// The integral of the density over x in [x0, x1], phi in [phi0, phi1]: the midpoint
// rule with nx x nphi points.
double integrate(const Density& density, const Radial& radial, const Frame& frame, const vec3& reflected, double x0,
                 double x1, int nx, double phi0, double phi1, int nphi) {
  const double hx = (x1 - x0) / nx, hphi = (phi1 - phi0) / nphi;
  double sum = 0.0;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < nphi; ++j)
      sum += radial.weighted(density, frame, reflected, x0 + (i + 0.5) * hx, phi0 + (j + 0.5) * hphi);
  return sum * hx * hphi;
}

// ---------------------------------------------------------------------------------

// The density integrates to 1 over the sphere: 2000 (fuzz >= 1) or 400 (fuzz < 1,
// in q) radial steps x 16 azimuths, within 1e-3. Measured: at most 1.1e-4 over the
// 21 cases (fuzz 0.5297 about a slanted r), under 1e-7 for fuzz > 1. Finer steps in q do
// not help below 1e-4: within q ~ 3e-4 fuzz of the rim (q^2 ~ 1e-7 fuzz^2, one
// float rounding of sin a) neither a float direction nor the float density can
// tell how close to the rim it is, and a point there weighs its error by 1 / q;
// the first of 400 steps lies at q = fuzz / 800.
TEST(MetalDensity, IntegratesToOne) {
  for (float fuzz : kFuzzes) {
    const Radial radial{fuzz};
    for (const vec3& r : kReflected) {
      const Frame frame(r);
      const double total = integrate(tested_density, radial, frame, r, radial.lo(), radial.hi(),
                                     radial.cone() ? 400 : 2000, 0.0, 2.0 * kPiD, 16);
      EXPECT_NEAR(total, 1.0, 1e-3) << "fuzz " << fuzz << ", r (" << r.x << ", " << r.y << ", " << r.z << ")";
    }
  }
}

// fuzzy_direction is metal_sample's sampling: for the same Rng, every direction
// metal_sample keeps is the one fuzzy_direction gives, bit for bit.
TEST(MetalDensity, FuzzyDirectionIsScatterMetals) {
  SurfacePoint sp{};
  sp.p = vec3(0.0f);
  sp.n = glm::normalize(vec3(0.2f, 1.0f, -0.1f));
  sp.ng = sp.n;
  sp.front = true;
  sp.offset = 1e-3f;
  const Ray in{vec3(-1.0f, 1.0f, 0.3f), glm::normalize(vec3(1.0f, -1.0f, -0.3f))};
  const vec3 r = reflect(in.dir, sp.n);
  for (float fuzz : kFuzzes) {
    Material m{};
    m.kind = MaterialKind::Metal;
    m.texture = -1;
    m.fuzz = fuzz;
    m.albedo = vec3(0.8f);
    int kept = 0;
    for (int i = 0; i < 2000; ++i) {
      const Rng rng = Rng::at(21, uint32_t(i), 0, 0);
      vec3 dir;
      const BsdfSample s = metal_sample(bsdf_at(m, BsdfInputs{}, sp, m.albedo, -in.dir), -in.dir, rng);
      if (s.lobe == 0u) continue;
      ++kept;
      ASSERT_TRUE(fuzzy_direction(r, fuzz, rng, dir));
      EXPECT_EQ(s.wi, dir) << "fuzz " << fuzz << ", key " << i;
    }
    EXPECT_GT(kept, 500) << fuzz;
  }
}

// The sum over the cells of (observed - expected)^2 / expected, with expected =
// n x the density's integral over the cell (not normalised: a density with the
// wrong total must fail too).
double chi_square(const std::vector<long>& counts, const std::vector<double>& expected) {
  double chi2 = 0.0;
  for (size_t i = 0; i < counts.size(); ++i)
    chi2 += (counts[i] - expected[i]) * (counts[i] - expected[i]) / expected[i];
  return chi2;
}

// Pearson's chi-square: 200k directions per fuzz drawn as scatter_metal draws them,
// binned in 20 radial cells (equal steps of the Radial coordinate: q for fuzz < 1,
// cos a otherwise) x 8 azimuths, against the density's integral over each cell (16
// x 4 midpoint points). Every cell expects at least 5 (checked), so df = 159.
// Critical value 258.58, the chi-square(159) upper-tail 1e-6 point (computed with
// mpmath): a correct density fails with probability 1e-6 per fuzz value.
// The same counts are scored against two wrong densities, which must score over
// ten times the critical value: half the density (the right shape, the wrong
// total), and the uniform density over the directions the fuzz can reach (the
// right total, the wrong shape).
TEST(MetalDensity, SampledDirectionsFollowTheDensity) {
  const int n = 200000, nx = 20, nphi = 8;
  const double critical = 258.58;
  const Density half = [](const vec3& r, float fuzz, const vec3& d) { return 0.5 * metal_fuzz_pdf(r, fuzz, d); };
  const Density uniform = [](const vec3& r, float fuzz, const vec3& d) {
    double sin2, c;
    angle_of(d, r, sin2, c);
    if (fuzz < 1.0f) {  // the cone of half-angle asin(fuzz): 1 - cos = fuzz^2 / (1 + sqrt(1 - fuzz^2))
      const double f = fuzz, solid = 2.0 * kPiD * f * f / (1.0 + std::sqrt((1.0 - f) * (1.0 + f)));
      return c > 0.0 && sin2 <= f * f ? 1.0 / solid : 0.0;
    }
    if (fuzz == 1.0f) return c >= 0.0 ? 1.0 / (2.0 * kPiD) : 0.0;
    return 1.0 / (4.0 * kPiD);
  };
  int which = 0;
  for (float fuzz : kFuzzes) {
    const vec3 r = kReflected[1 + which++ % 2];
    const Radial radial{fuzz};
    const Frame frame(r);
    std::vector<long> counts(nx * nphi, 0);
    int outside = 0;
    for (int i = 0; i < n; ++i) {
      vec3 dir;
      double x;
      if (!fuzzy_direction(r, fuzz, Rng::at(17, uint32_t(i), 0, 0), dir) || !radial.of(dir, r, x)) {
        ++outside;
        continue;
      }
      const double u = (x - radial.lo()) / (radial.hi() - radial.lo());
      const int ix = std::min(nx - 1, static_cast<int>(u * nx));
      const int iphi = std::min(nphi - 1, static_cast<int>(frame.azimuth(dir) / (2.0 * kPiD) * nphi));
      ++counts[ix * nphi + iphi];
    }
    EXPECT_EQ(outside, 0) << "fuzz " << fuzz << ": directions outside the reach of the fuzz";
    double scores[3];
    int d = 0;
    for (const Density& density : {Density(tested_density), half, uniform}) {
      std::vector<double> expected(nx * nphi);
      const double hx = (radial.hi() - radial.lo()) / nx, hphi = 2.0 * kPiD / nphi;
      for (int ix = 0; ix < nx; ++ix)
        for (int iphi = 0; iphi < nphi; ++iphi) {
          const double x0 = radial.lo() + ix * hx, phi0 = iphi * hphi;
          expected[ix * nphi + iphi] = n * integrate(density, radial, frame, r, x0, x0 + hx, 16, phi0, phi0 + hphi, 4);
          if (d == 0) {
            ASSERT_GE(expected[ix * nphi + iphi], 5.0) << "fuzz " << fuzz << ", cell " << ix << ", " << iphi;
          }
        }
      scores[d++] = chi_square(counts, expected);
    }
    // Measured with these streams, fuzz 0.05 to 3 in order: 162.6, 134.1, 142.6,
    // 117.0, 152.8, 150.9, 155.2. Half the density: 1.0e5 each (about n / 2);
    // uniform: 2.9e5, 2.6e5, 1.8e5, 3.5e4, 6.6e4, 1.3e5, 3.0e4.
    EXPECT_LT(scores[0], critical) << "fuzz " << fuzz;
    EXPECT_GT(scores[1], 10.0 * critical) << "fuzz " << fuzz << ": half the density passes";
    EXPECT_GT(scores[2], 10.0 * critical) << "fuzz " << fuzz << ": the uniform density passes";
  }
}

// The density from the geometry, in double, written from the definition rather than
// from metal_fuzz_pdf's formulas: the roots t of |t dir - r| = fuzz, i.e.
// t^2 - 2 c t + 1 - fuzz^2 = 0, each with t > 0 adding t^2 / (4 pi fuzz^2 |cos beta|),
// cos beta = (t - c) / fuzz the cosine between dir and the sphere's normal there.
double reference_density(double fuzz, double cos_a) {
  const double disc = cos_a * cos_a - 1.0 + fuzz * fuzz;
  if (disc <= 0.0) return 0.0;
  double p = 0.0;
  for (double t : {cos_a - std::sqrt(disc), cos_a + std::sqrt(disc)})
    if (t > 0.0) p += t * t / (4.0 * kPiD * fuzz * fuzz * std::fabs(t - cos_a) / fuzz);
  return p;
}

// At a fixed angle from r the density is the same at every azimuth (within float
// rounding, 1e-5 relative) and agrees with the double reference (2e-5 relative);
// angles up to 0.95 of the cone's half-angle (fuzz < 1), all over the sphere
// otherwise. At fuzz = 1 it is the cosine lobe c / pi.
TEST(MetalDensity, IsTheSameAllAroundTheMirrorAndMatchesTheGeometry) {
  for (float fuzz : kFuzzes) {
    const double f = fuzz;
    std::vector<double> angles;
    if (fuzz < 1.0f) {
      for (double k : {0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 0.95}) angles.push_back(k * std::asin(f));
    } else {
      for (double a : {0.0, 0.3, 0.8, 1.2, 1.5, 1.7, 2.2, 2.8, 3.1, kPiD}) angles.push_back(a);
    }
    for (const vec3& r : kReflected) {
      const Frame frame(r);
      for (double a : angles) {
        const double reference = reference_density(f, std::cos(a));
        double first = -1.0;
        for (int k = 0; k < 24; ++k) {
          const double phi = 2.0 * kPiD * (k + 0.37) / 24.0;
          const double p = metal_fuzz_pdf(r, fuzz, frame.at(std::cos(a), std::sin(a), phi));
          if (first < 0.0) first = p;
          EXPECT_NEAR(p, first, 1e-5 * first + 1e-30) << "fuzz " << fuzz << ", angle " << a << ", phi " << phi;
          EXPECT_NEAR(p, reference, 2e-5 * reference + 1e-7) << "fuzz " << fuzz << ", angle " << a;
          if (fuzz == 1.0f) {
            EXPECT_NEAR(p, std::max(0.0, std::cos(a)) / kPiD, 2e-5) << "angle " << a;
          }
        }
      }
    }
  }
}

// fuzz < 1: nothing beyond the cone sin a = fuzz, nor behind r, at any azimuth; at
// fuzz = 1 nothing behind the plane across r; above 1 every direction has a
// positive density.
TEST(MetalDensity, IsZeroBeyondTheCone) {
  for (float fuzz : kFuzzes) {
    for (const vec3& r : kReflected) {
      const Frame frame(r);
      std::vector<double> angles;
      if (fuzz < 1.0f) {
        const double rim = std::asin(double(fuzz));
        for (double a : {rim * 1.001, rim + 0.01, 0.5 * (rim + 0.5 * kPiD), 0.5 * kPiD, 2.0, 3.0, kPiD})
          angles.push_back(a);
      } else if (fuzz == 1.0f) {
        for (double a : {0.5 * kPiD + 1e-3, 2.0, 3.0, kPiD}) angles.push_back(a);
      }
      for (double a : angles)
        for (int k = 0; k < 16; ++k) {
          const vec3 dir = frame.at(std::cos(a), std::sin(a), 2.0 * kPiD * k / 16.0);
          EXPECT_EQ(metal_fuzz_pdf(r, fuzz, dir), 0.0f) << "fuzz " << fuzz << ", angle " << a;
        }
      if (fuzz > 1.0f) {
        for (double a = 0.0; a <= kPiD; a += 0.05) {
          EXPECT_GT(metal_fuzz_pdf(r, fuzz, frame.at(std::cos(a), std::sin(a), 1.0)), 0.0f) << fuzz << ", " << a;
        }
      }
    }
  }
}

// No inf or NaN anywhere: a fine scan of angles through every fuzz's cone, the rim
// itself (where the density is large but finite: q is held at 1e-6 fuzz), r and -r,
// and fuzz just below and above 1, where the two formulas meet and agree.
TEST(MetalDensity, IsFiniteEverywhereAndContinuousAcrossFuzzOne) {
  std::vector<float> fuzzes(std::begin(kFuzzes), std::end(kFuzzes));
  fuzzes.push_back(std::nextafter(1.0f, 0.0f));
  fuzzes.push_back(std::nextafter(1.0f, 2.0f));
  fuzzes.push_back(1e-3f);
  for (float fuzz : fuzzes)
    for (const vec3& r : kReflected) {
      const Frame frame(r);
      std::vector<double> angles;
      for (int i = 0; i <= 4000; ++i) angles.push_back(kPiD * i / 4000.0);
      if (fuzz < 1.0f) {
        const double rim = std::asin(double(fuzz));
        for (double k : {1.0 - 1e-6, 1.0 - 1e-7, 1.0, 1.0 + 1e-7}) angles.push_back(k * rim);
      }
      for (double a : angles) {
        const float p = metal_fuzz_pdf(r, fuzz, frame.at(std::cos(a), std::sin(a), 0.7));
        ASSERT_TRUE(std::isfinite(p) && p >= 0.0f) << "fuzz " << fuzz << ", angle " << a << ": " << p;
      }
      EXPECT_TRUE(std::isfinite(metal_fuzz_pdf(r, fuzz, r)));
      if (fuzz > 1.0f) {
        EXPECT_GT(metal_fuzz_pdf(r, fuzz, -r), 0.0f) << fuzz;
      } else {
        EXPECT_EQ(metal_fuzz_pdf(r, fuzz, -r), 0.0f) << fuzz;
      }
    }
  // Across fuzz = 1: the one-root formula at 1 and above, the two-root one below.
  const vec3 r = kReflected[1];
  const Frame frame(r);
  for (double a : {0.1, 0.6, 1.2, 1.5}) {
    const vec3 dir = frame.at(std::cos(a), std::sin(a), 2.0);
    const float at_one = metal_fuzz_pdf(r, 1.0f, dir);
    EXPECT_NEAR(metal_fuzz_pdf(r, std::nextafter(1.0f, 0.0f), dir), at_one, 1e-5f * at_one) << a;
    EXPECT_NEAR(metal_fuzz_pdf(r, std::nextafter(1.0f, 2.0f), dir), at_one, 1e-5f * at_one) << a;
  }
}

}  // namespace
}  // namespace wt

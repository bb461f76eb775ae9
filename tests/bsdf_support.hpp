// What the BSDF tests share (bsdf_test.cpp, principled_layers_test.cpp): a
// material as the scene reader makes it, its BSDF on the plane z = 0, the
// chi-square test of a sampler against a density, and the white furnace.
//
// Statistics. The chi-square statistic (Pearson's, bins of expected count below 5
// pooled, the samples outside the bins a bin of their own, so that a density with
// the wrong total fails too) is turned into a normal deviate by Wilson and
// Hilferty's cube-root transformation, and a test fails above 4.5 (a false alarm
// of 3.4e-6 per test; the seeds are fixed, so results are reproducible). 100,000
// samples a test.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "scene/scene.hpp"
#include "wavetrace/bsdf.hpp"

namespace wt {

constexpr double kPiD = 3.14159265358979323846;
constexpr int kSamples = 100000;
constexpr double kRejectZ = 4.5;

// A material as the scene reader makes it, with its parameters and tables.
struct Case {
  std::string name;
  Material m;
  MaterialParams p;
  std::vector<float> tables;
  std::vector<Texture> textures;  // procedural ones only: no images
};

inline Case material(const std::string& json, const std::string& textures = "") {
  const Scene s = parse_scene(R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
      "textures": [)" + textures + R"(],
      "materials": [)" + json + R"(],
      "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})",
                              "bsdf.json");
  Case c;
  c.name = json;
  c.m = s.materials.at(0);
  c.p = c.m.params >= 0 ? s.material_params.at(c.m.params) : MaterialParams{};
  c.m.params = c.m.params >= 0 ? 0 : -1;
  c.tables = s.bsdf_tables;
  c.tables.push_back(0.0f);  // data() is never null
  c.textures = s.textures;
  return c;
}

// The BSDF of the case on the plane z = 0 (normals +z, tangent +x), seen from wo's
// side; Layers = false: as a kernel without principled's layers makes it.
template <bool Layers = true>
inline BsdfAt at(const Case& c, const vec3& wo) {
  SurfacePoint sp{};
  sp.p = vec3(0.0f);
  sp.n = sp.ng = vec3(0.0f, 0.0f, 1.0f);
  sp.dpdu = vec3(1.0f, 0.0f, 0.0f);
  sp.front = wo.z > 0.0f;
  sp.offset = 1e-4f;
  return bsdf_at<true, Layers>(c.m, BsdfInputs{&c.p, c.tables.data(), c.textures.data(), nullptr}, sp, c.m.albedo, wo);
}

// The incident direction at `deg` from the normal (azimuth 0.3 rad, so that
// anisotropy is not seen along its axis), on the outside or the inside.
inline vec3 incident(double deg, bool outside = true) {
  const double t = deg * kPiD / 180.0;
  const vec3 w(float(std::sin(t) * std::cos(0.3)), float(std::sin(t) * std::sin(0.3)), float(std::cos(t)));
  return outside ? w : vec3(w.x, w.y, -w.z);
}

struct Chi2 {
  double statistic;
  int dof;
  double z;  // Wilson-Hilferty
  double binned;  // the share of the samples in the bins
};

// Bins over directions about `centre` (polar angle edges pi (i / 48)^3, finer near
// the centre where a sharp lobe is, and 32 azimuths), keeping only directions with
// z of sign `side` (0: all). Counts the sampler's non-specular samples against n
// times the density's integral over each bin (10 x 10 midpoints a bin).
// `sample(i)`: the sampler's i-th sample (of kSamples).
inline Chi2 chi2_test(const std::function<BsdfSample(int)>& sample, const std::function<float(const vec3&)>& pdf,
                      const vec3& centre, int side) {
  constexpr int kTheta = 48, kPhi = 32, kSub = 10;
  const Frame f = Frame::about(centre, vec3(0.3f, 0.7f, 0.1f));
  auto theta_edge = [](int i) { return kPiD * std::pow(static_cast<double>(i) / kTheta, 3.0); };
  auto on_side = [side](const vec3& w) { return side == 0 || (side > 0 ? w.z > 0.0f : w.z < 0.0f); };
  std::vector<double> observed(kTheta * kPhi, 0.0), expected(kTheta * kPhi, 0.0);
  for (int i = 0; i < kSamples; ++i) {
    const BsdfSample s = sample(i);
    if (s.lobe == 0u || (s.lobe & kLobeSpecular) || !on_side(s.wi)) continue;
    const vec3 l = f.to_local(s.wi);
    // atan2 keeps small angles exact (acos of a float near 1 steps by 3.5e-4 rad).
    const double theta = std::atan2(std::hypot(static_cast<double>(l.x), static_cast<double>(l.y)), static_cast<double>(l.z));
    double phi = std::atan2(static_cast<double>(l.y), static_cast<double>(l.x));
    if (phi < 0) phi += 2 * kPiD;
    int ti = static_cast<int>(std::cbrt(theta / kPiD) * kTheta);
    ti = std::min(std::max(ti, 0), kTheta - 1);
    // cbrt rounding: step to the bin whose edges hold theta.
    while (ti > 0 && theta < theta_edge(ti)) --ti;
    while (ti < kTheta - 1 && theta >= theta_edge(ti + 1)) ++ti;
    const int pj = std::min(static_cast<int>(phi / (2 * kPiD) * kPhi), kPhi - 1);
    observed[ti * kPhi + pj] += 1;
  }
  for (int ti = 0; ti < kTheta; ++ti) {
    const double t0 = theta_edge(ti), t1 = theta_edge(ti + 1);
    for (int pj = 0; pj < kPhi; ++pj) {
      const double p0 = 2 * kPiD * pj / kPhi, p1 = 2 * kPiD * (pj + 1) / kPhi;
      double integral = 0.0;
      for (int a = 0; a < kSub; ++a) {
        const double t = t0 + (t1 - t0) * (a + 0.5) / kSub;
        for (int c = 0; c < kSub; ++c) {
          const double ph = p0 + (p1 - p0) * (c + 0.5) / kSub;
          const vec3 w = f.to_world(vec3(float(std::sin(t) * std::cos(ph)), float(std::sin(t) * std::sin(ph)),
                                         float(std::cos(t))));
          if (on_side(w)) integral += pdf(glm::normalize(w)) * std::sin(t);
        }
      }
      expected[ti * kPhi + pj] = kSamples * integral * (t1 - t0) * (p1 - p0) / (kSub * kSub);
    }
  }
  double in_bins = 0.0, expected_in_bins = 0.0;
  for (size_t i = 0; i < observed.size(); ++i) {
    in_bins += observed[i];
    expected_in_bins += expected[i];
  }
  // The samples outside the bins (specular, absorbed, on the other side) are a bin.
  observed.push_back(kSamples - in_bins);
  expected.push_back(std::fmax(kSamples - expected_in_bins, 0.0));
  double chi2 = 0.0, pooled_observed = 0.0, pooled_expected = 0.0;
  int bins = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] < 5.0) {
      pooled_observed += observed[i];
      pooled_expected += expected[i];
      continue;
    }
    chi2 += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++bins;
  }
  if (pooled_expected > 0.0 || pooled_observed > 0.0) {
    const double e = std::fmax(pooled_expected, 1.0);
    chi2 += (pooled_observed - e) * (pooled_observed - e) / e;
    ++bins;
  }
  const int dof = std::max(bins - 1, 1);
  const double k = dof;
  const double z = (std::cbrt(chi2 / k) - (1.0 - 2.0 / (9.0 * k))) / std::sqrt(2.0 / (9.0 * k));
  return Chi2{chi2, dof, z, in_bins / kSamples};
}

// sample_bsdf's samples of b at wo (seed, i) against `pdf`.
inline Chi2 chi2_test(const BsdfAt& b, const vec3& wo, const std::function<float(const vec3&)>& pdf, const vec3& centre,
                      int side, uint32_t seed) {
  return chi2_test([&](int i) { return sample_bsdf(b, wo, Rng::at(seed, static_cast<uint32_t>(i), 0, 0)); }, pdf,
                   centre, side);
}

inline std::function<float(const vec3&)> pdf_of(const BsdfAt& b, const vec3& wo) {
  return [b, wo](const vec3& wi) { return pdf_bsdf(b, wo, wi); };
}

inline vec3 mirror(const vec3& wo) { return vec3(-wo.x, -wo.y, wo.z); }

// The direction a smooth interface of index ratio eta (transmitted over incident)
// refracts wo into.
inline vec3 refracted(const vec3& wo, float eta) {
  const float cos_t = refracted_cos(std::fabs(wo.z), eta);
  return glm::normalize(vec3(-wo.x / eta, -wo.y / eta, wo.z > 0 ? -cos_t : cos_t));
}

inline std::string label(const Case& c, double deg) { return c.name + " at " + std::to_string(static_cast<int>(deg)) + " deg"; }

inline void expect_fits(const Case& c, double deg, bool outside = true) {
  const vec3 wo = incident(deg, outside);
  const BsdfAt b = at(c, wo);
  const bool thin = c.m.kind == MaterialKind::Principled && (c.m.flags & kMaterialThin);
  const bool transmits = c.m.kind == MaterialKind::Glass || (c.m.kind == MaterialKind::Principled && c.p.transmission > 0.0f);
  // A thin wall passes light straight on.
  const float eta = thin ? 1.0f : outside ? c.m.ior : 1.0f / c.m.ior;
  struct Lobe {
    vec3 centre;
    int side;
  };
  std::vector<Lobe> lobes;
  if (transmits) {
    lobes.push_back({mirror(wo), outside ? 1 : -1});
    if (refracted_cos(std::fabs(wo.z), eta) > 0.0f) lobes.push_back({refracted(wo, eta), outside ? -1 : 1});
  } else {
    lobes.push_back({mirror(wo), 0});
  }
  for (const Lobe& l : lobes) {
    const Chi2 r = chi2_test(b, wo, pdf_of(b, wo), l.centre, l.side, 17);
    EXPECT_LT(r.z, kRejectZ) << label(c, deg) << (outside ? "" : " (inside)") << ", lobe side " << l.side
                             << ": chi2 " << r.statistic << " on " << r.dof << " dof, " << r.binned
                             << " of the samples binned";
  }
}

inline const std::vector<double> kAngles = {0.0, 30.0, 60.0, 80.0};
inline const std::vector<std::string> kRoughnesses = {"0.05", "0.2", "0.5", "1"};

// The white furnace: the mean weight of the BSDF's samples at wo (the share of the
// light arriving from every direction that it returns), with transmission's
// radiance scaling taken out. Its mean and standard error.
struct Furnace {
  double mean, error;
};

inline Furnace furnace(const Case& c, const vec3& wo) {
  const BsdfAt b = at(c, wo);
  double sum = 0.0, sum2 = 0.0;
  constexpr int n = 160000;
  for (int i = 0; i < n; ++i) {
    const BsdfSample s = sample_bsdf(b, wo, Rng::at(3, static_cast<uint32_t>(i), 0, 0));
    double w = s.lobe == 0u ? 0.0 : (s.weight.x + s.weight.y + s.weight.z) / 3.0;
    const bool volume = c.m.kind == MaterialKind::Glass || (c.m.kind == MaterialKind::Principled && c.p.transmission > 0.0f);
    if ((s.lobe & kLobeTransmission) && volume && !(c.m.flags & kMaterialThin)) {
      const double eta = wo.z > 0 ? c.m.ior : 1.0 / c.m.ior;
      w *= eta * eta;
    }
    sum += w;
    sum2 += w * w;
  }
  const double m = sum / n;
  return Furnace{m, std::sqrt(std::fmax(sum2 / n - m * m, 0.0) / n)};
}

// Every non-specular sample's weight is eval / pdf and its pdf pdf(), to float
// rounding, at kAngles from both sides.
inline void expect_weights_are_eval_over_pdf(const Case& c) {
  for (double deg : kAngles) {
    for (bool outside : {true, false}) {
      const vec3 wo = incident(deg, outside);
      const BsdfAt b = at(c, wo);
      int checked = 0;
      for (int i = 0; i < 2000; ++i) {
        const BsdfSample s = sample_bsdf(b, wo, Rng::at(5, static_cast<uint32_t>(i), 0, 0));
        if (s.lobe == 0u || (s.lobe & kLobeSpecular)) continue;
        float pdf;
        const vec3 f = eval_bsdf(b, wo, s.wi, pdf);
        ASSERT_NEAR(pdf, s.pdf, 1e-3f * s.pdf) << label(c, deg) << " sample " << i;
        for (int k = 0; k < 3; ++k) {
          ASSERT_NEAR(s.weight[k], f[k] / pdf, 2e-3f * s.weight[k] + 1e-6f) << label(c, deg) << " sample " << i;
        }
        ++checked;
      }
      EXPECT_GT(checked, 500) << label(c, deg);
    }
  }
}

// Reciprocity over 4000 pairs of directions drawn uniformly over the sphere, both
// ways round: f(wo, wi) = f(wi, wo), and through an interface f / n^2 of wo's side,
// n being `inside` below the surface and 1 above it (glass's radiance scaling; 1
// where nothing refracts). The pairs where f is not 0, and those of them that cross.
struct ReciprocalPairs {
  int nonzero = 0, crossing = 0;
};
inline ReciprocalPairs reciprocal_pairs(const Case& c, float inside) {
  ReciprocalPairs out;
  for (int i = 0; i < 4000; ++i) {
    const Rng rng = Rng::at(9, static_cast<uint32_t>(i), 0, 0);
    const vec3 a = unit_sphere_point(rng.uniform(0), rng.uniform(1));
    const vec3 d = unit_sphere_point(rng.uniform(2), rng.uniform(3));
    const bool reflection = (a.z > 0) == (d.z > 0);
    if (std::fabs(a.z) < 0.02f || std::fabs(d.z) < 0.02f) continue;
    const vec3 f_ad = eval_bsdf(at(c, a), a, d) / std::fabs(d.z);
    const vec3 f_da = eval_bsdf(at(c, d), d, a) / std::fabs(a.z);
    const float n_a = a.z > 0 ? 1.0f : inside, n_d = d.z > 0 ? 1.0f : inside;
    for (int k = 0; k < 3; ++k) {
      const float x = reflection ? f_ad[k] : f_ad[k] / (n_a * n_a);
      const float y = reflection ? f_da[k] : f_da[k] / (n_d * n_d);
      // (1e-5 absolute: near total internal reflection 1 - F cancels.)
      EXPECT_NEAR(x, y, 2e-3f * std::fmax(x, y) + 1e-5f) << c.name << " pair " << i;
      if (std::fabs(x - y) > 2e-3f * std::fmax(x, y) + 1e-5f) return out;
    }
    if (f_ad.x > 0.0f) ++out.nonzero;
    if (f_ad.x > 0.0f && !reflection) ++out.crossing;
  }
  return out;
}

}  // namespace wt

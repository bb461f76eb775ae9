// The GGX (Trowbridge-Reitz) microfacet distribution, anisotropic, with
// height-correlated Smith masking-shadowing, sampled by its visible normals. All in
// the local frame (z the macro-normal; x the tangent alpha_x runs along).
//
// Distribution: Trowbridge and Reitz 1975, Walter et al. 2007 ("GGX"). Masking:
// Heitz 2014, "Understanding the masking-shadowing function in microfacet-based
// BRDFs". Visible-normal sampling: the spherical caps of Dupuy and Benyoub 2023,
// "Sampling visible GGX normals with spherical caps".
#pragma once

#include "wavetrace/bsdfs/common.hpp"
#include "wavetrace/mutant.hpp"

namespace wt {

// Below this alpha a lobe is a delta (a mirror, a smooth interface).
constexpr float kSmoothAlpha = 1e-4f;

struct Ggx {
  float ax, ay;
  // G2 as the product G1(wo) G1(wi) (uncorrelated heights, as Mitsuba 3's
  // microfacet BSDFs) instead of the height-correlated form, which is the default.
  bool separable = false;

  WT_HD bool smooth() const { return ax < kSmoothAlpha && ay < kSmoothAlpha; }

  // The density of micro-normals h (h.z > 0) per unit projected area.
  WT_HD float d(const vec3& h) const {
    if (h.z <= 0.0f) return 0.0f;
    const float x = h.x / ax, y = h.y / ay;
    const float s = x * x + y * y + h.z * h.z;
    return 1.0f / (kPi * ax * ay * s * s);
  }
  // Smith's Lambda for direction w.
  WT_HD float lambda(const vec3& w) const {
    if (w.z == 0.0f) return 3.0e38f;
    const float a2 = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / (w.z * w.z);
    return 0.5f * (sqrtf(1.0f + a2) - 1.0f);
  }
  WT_HD float g1(const vec3& w) const { return 1.0f / (1.0f + lambda(w)); }
  // Masking-shadowing of the pair: height-correlated, or separable.
  WT_HD float g2(const vec3& wo, const vec3& wi) const {
    const float lo = lambda(wo), li = lambda(wi);
    return separable ? 1.0f / ((1.0f + lo) * (1.0f + li)) : 1.0f / (1.0f + lo + li);
  }

  // The density of the visible normal h seen from wo (wo.z > 0), per solid angle of h.
  WT_HD float visible_d(const vec3& wo, const vec3& h) const {
    const float c = glm::dot(wo, h);
    if (c <= 0.0f || wo.z <= 0.0f) return 0.0f;
    return (WT_MUTANT(VisibleNormalsWithoutG1) ? 1.0f : g1(wo)) * c * d(h) / wo.z;
  }

  // A visible normal seen from wo (wo.z > 0), from two uniforms.
  WT_HD vec3 sample_visible(const vec3& wo, float u1, float u2) const {
    // Stretch to the hemisphere configuration, where visible normals are the sum
    // of the view direction and a point uniform on a spherical cap.
    const vec3 v = glm::normalize(vec3(ax * wo.x, ay * wo.y, wo.z));
    const float phi = 2.0f * kPi * u1;
    const float z = (1.0f - u2) * (1.0f + v.z) - v.z;
    const float sin_theta = sqrtf(fminf(fmaxf(1.0f - z * z, 0.0f), 1.0f));
    const vec3 h = vec3(sin_theta * cosf(phi), sin_theta * sinf(phi), z) + v;
    return glm::normalize(vec3(ax * h.x, ay * h.y, fmaxf(h.z, 0.0f)));
  }
};

// Perceptual roughness (alpha = roughness^2, as glTF and Cycles) and anisotropy in
// [0, 1] to the two alphas, stretched along the tangent by 1 / sqrt(1 - 0.9 a) and
// shrunk across it by the same factor (Burley 2012's mapping).
WT_HD WT_INLINE Ggx ggx_from_roughness(float roughness, float anisotropy) {
  const float alpha = roughness * roughness;
  const float aspect = sqrtf(1.0f - 0.9f * anisotropy);
  return Ggx{alpha / aspect, alpha * aspect};
}

// The roughness the energy tables are read at: that of the isotropic lobe of equal
// alpha_x alpha_y.
WT_HD WT_INLINE float table_roughness(const Ggx& g) { return sqrtf(sqrtf(g.ax * g.ay)); }

WT_HD WT_INLINE vec3 reflect_about(const vec3& wo, const vec3& h) { return 2.0f * glm::dot(wo, h) * h - wo; }

}  // namespace wt

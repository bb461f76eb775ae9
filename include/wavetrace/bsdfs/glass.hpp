// `glass`: a dielectric interface of index `ior` inside, 1 outside, with the exact
// Fresnel reflectance, smooth or rough (GGX, after Walter et al. 2007, "Microfacet
// models for refraction through rough surfaces", sampled by visible normals), and a
// transmission tint. Transmitted radiance is scaled by 1 / eta^2 (eta the ratio of
// the indices, transmitted over incident), as radiance is in crossing an interface.
// With kMaterialCompensated a rough interface's f is divided by its single-
// scattering albedo E(mu_o) on wo's side (reflection plus transmission, a table per
// material: energy.hpp), so that it loses nothing to multiple scattering (Turquin
// 2019's normalisation). kMaterialThin: a thin smooth sheet, whose two faces'
// reflections sum to R' = R + (1 - R)^2 R / (1 - R^2) and which passes light straight
// through otherwise.
#pragma once

#include "wavetrace/bsdfs/common.hpp"
#include "wavetrace/bsdfs/energy.hpp"
#include "wavetrace/bsdfs/microfacet.hpp"

namespace wt {

WT_HD WT_INLINE Ggx glass_ggx(const BsdfAt& b) { return Ggx{b.p.ax, b.p.ay, (b.flags & kMaterialSeparable) != 0}; }

// A glass interface as its functions read it (principled's volume makes one without
// copying the whole BsdfAt).
struct GlassLobe {
  uint32_t flags;  // kMaterialThin, kMaterialCompensated
  float ior;
  vec3 tint;
  int32_t table, rows;  // its energy tables (-1: none), 1 or kEnergySize rows by roughness
  const float* tables;
};

WT_HD WT_INLINE GlassLobe glass_lobe(const BsdfAt& b) {
  return GlassLobe{b.flags, b.ior, b.albedo, b.p.table, b.p.table_rows, b.tables};
}

// 1 / E(mu_o) on wo's side where the glass is compensated, else 1.
WT_HD WT_INLINE float glass_compensation(const GlassLobe& c, const Ggx& g, const vec3& wo) {
  if (!(c.flags & kMaterialCompensated) || c.table < 0) return 1.0f;
  const float* t = c.tables + c.table + (wo.z > 0.0f ? 0 : c.rows * kEnergySize);
  return 1.0f / fmaxf(rows_table(t, c.rows, table_roughness(g), fabsf(wo.z)), 1e-3f);
}

// f cos and the density, local frame about the outward normal (wo on either side).
// Single scattering (no compensation) when `single`.
WT_HD WT_INLINE vec3 glass_eval_local(const GlassLobe& c, const Ggx& g, const vec3& wo, const vec3& wi, float& pdf,
                                      bool single = false) {
  pdf = 0.0f;
  if (wo.z == 0.0f || wi.z == 0.0f) return vec3(0.0f);
  const bool outside = wo.z > 0.0f;
  const float eta = outside ? c.ior : 1.0f / c.ior;  // transmitted over incident, for wo's side
  const bool reflection = (wo.z > 0.0f) == (wi.z > 0.0f);
  const float etap = reflection ? 1.0f : eta;
  vec3 h = wo + wi * etap;
  const float len2 = glm::dot(h, h);
  if (!(len2 > 0.0f)) return vec3(0.0f);
  h *= 1.0f / sqrtf(len2);
  if (h.z < 0.0f) h = -h;
  const float ho = glm::dot(h, wo), hi = glm::dot(h, wi);
  // Micro-normals that face away from either direction carry nothing.
  if (ho * wo.z <= 0.0f || hi * wi.z <= 0.0f) return vec3(0.0f);
  const vec3 wu = outside ? wo : -wo;  // wo on the side of h's hemisphere
  const float f_r = fresnel_dielectric(fabsf(ho), eta);
  const float visible = g.visible_d(wu, h);
  const float dg = g.d(h) * g.g2(wo, wi);
  const float scale = single ? 1.0f : glass_compensation(c, g, wo);
  if (reflection) {
    pdf = visible * f_r / (4.0f * fabsf(ho));
    return vec3(f_r * dg * scale / (4.0f * fabsf(wo.z)));
  }
  const float denom = hi + ho / eta;
  const float jacobian = fabsf(hi) / (denom * denom);
  pdf = visible * (1.0f - f_r) * jacobian;
  return c.tint * ((1.0f - f_r) * dg * fabsf(ho) * jacobian * scale /
                   (WT_MUTANT(GlassUnscaledRadiance) ? fabsf(wo.z) : fabsf(wo.z) * eta * eta));
}

WT_HD WT_INLINE BsdfSample glass_sample_local(const GlassLobe& c, const Ggx& g, const vec3& wo, const Rng& rng,
                                              bool single = false) {
  if (wo.z == 0.0f) return no_sample();
  const bool outside = wo.z > 0.0f;
  const float s = outside ? 1.0f : -1.0f;
  const vec3 wu = s * wo;
  if (c.flags & kMaterialThin) {
    const float r = fresnel_dielectric(wu.z, c.ior);
    const float rt = r < 1.0f ? r + (1.0f - r) * (1.0f - r) * r / (1.0f - r * r) : 1.0f;
    if (rng.uniform(kDimLayer) < rt) return BsdfSample{vec3(-wo.x, -wo.y, wo.z), vec3(1.0f), 0.0f, kLobeSpecular | kLobeReflection};
    return BsdfSample{-wo, c.tint, 0.0f, kLobeSpecular | kLobeTransmission};
  }
  const float eta = outside ? c.ior : 1.0f / c.ior;
  if (g.smooth()) {
    const float f_r = fresnel_dielectric(wu.z, eta);
    if (rng.uniform(kDimLayer) < f_r) return BsdfSample{vec3(-wo.x, -wo.y, wo.z), vec3(1.0f), 0.0f, kLobeSpecular | kLobeReflection};
    const float cos_t = refracted_cos(wu.z, eta);
    const vec3 wi = vec3(-wo.x / eta, -wo.y / eta, -s * cos_t);
    return BsdfSample{wi, c.tint * (1.0f / (eta * eta)), 0.0f, kLobeSpecular | kLobeTransmission};
  }
  const vec3 h = g.sample_visible(wu, rng.uniform(kDimScatterA), rng.uniform(kDimScatterB));
  const float cs = glm::dot(wu, h);
  vec3 wi;
  if (rng.uniform(kDimLayer) < fresnel_dielectric(cs, eta)) {
    wi = reflect_about(wu, h);
    if (wi.z <= 0.0f) return no_sample();
  } else {
    const float cos_t = refracted_cos(cs, eta);
    wi = -wu * (1.0f / eta) + (cs / eta - cos_t) * h;
    if (wi.z >= 0.0f) return no_sample();
  }
  wi = s * glm::normalize(wi);
  float pdf;
  const vec3 f = glass_eval_local(c, g, wo, wi, pdf, single);
  if (!(pdf > 0.0f)) return no_sample();
  const uint32_t side = (wi.z > 0.0f) == outside ? kLobeReflection : kLobeTransmission;
  return BsdfSample{wi, f * (1.0f / pdf), pdf, kLobeGlossy | side};
}

WT_HD WT_INLINE BsdfSample glass_sample(const BsdfAt& b, const vec3& wo_world, const Rng& rng) {
  const Frame fr = b.outward_frame();
  BsdfSample s = glass_sample_local(glass_lobe(b), glass_ggx(b), fr.to_local(wo_world), rng);
  if (s.lobe == 0u) return s;
  s.wi = fr.to_world(s.wi);
  // A reflection must stay on wo's side of the geometric surface, a transmission cross it.
  if (b.same_side(s.wi) != ((s.lobe & kLobeReflection) != 0)) return no_sample();
  return s;
}

WT_HD WT_INLINE vec3 glass_eval(const BsdfAt& b, const vec3& wo, const vec3& wi, float& pdf) {
  pdf = 0.0f;
  const Ggx g = glass_ggx(b);
  if ((b.flags & kMaterialThin) || g.smooth()) return vec3(0.0f);
  const Frame fr = b.outward_frame();
  const vec3 lo = fr.to_local(wo), li = fr.to_local(wi);
  if (b.same_side(wi) != ((lo.z > 0.0f) == (li.z > 0.0f))) return vec3(0.0f);
  return glass_eval_local(glass_lobe(b), g, lo, li, pdf);
}

}  // namespace wt

// `plastic`: a diffuse base under a dielectric coat of index `ior`, smooth or rough
// (GGX). The coat reflects F D G / (4 mu_o) (a mirror with F when smooth); what it
// lets through reaches the base, bounces between base and coat, and leaves:
//   f_d cos = albedo / (1 - albedo R_int) / ior^2 t(mu_o) t(mu_i) mu_i / pi,
// with t(mu) the coat's transmittance from outside (1 - F(mu) when smooth; when
// rough, what its single-scattering BTDF carries through, the masking's losses
// lost: a table per material) and R_int the coat's diffuse reflectance from inside,
// summing the internal bounces as a geometric series. This is the model of Mitsuba
// 3's plastic and roughplastic with `nonlinear` set. Two-sided.
//
// A metallic plastic (MaterialParams::metallic m > 0, glTF's metallic) mixes it
// with a conductor of f0 = albedo (Schlick) at the coat's roughness, energy-
// compensated as conductors are: f = (1 - m) f_plastic + m f_metal, sampled by
// picking the metal with probability m, with the mixture's density.
#pragma once

#include "wavetrace/bsdfs/common.hpp"
#include "wavetrace/bsdfs/conductor.hpp"
#include "wavetrace/bsdfs/energy.hpp"
#include "wavetrace/bsdfs/microfacet.hpp"

namespace wt {

WT_HD WT_INLINE Ggx plastic_ggx(const BsdfAt& b) { return Ggx{b.p.ax, b.p.ay, (b.flags & kMaterialSeparable) != 0}; }

// The coat's transmittance at mu from outside.
WT_HD WT_INLINE float plastic_transmittance(const BsdfAt& b, const Ggx& g, float mu) {
  if (g.smooth() || b.p.table < 0) return 1.0f - fresnel_dielectric(mu, b.ior);
  return rows_table(b.tables + b.p.table, b.p.table_rows, table_roughness(g), mu);
}

// The probability of sampling the coat rather than the base, from their expected
// shares at mu_o (the base's albedo counted at its mean).
WT_HD WT_INLINE float plastic_coat_share(const BsdfAt& b, float t_o) {
  const float base = (b.albedo.x + b.albedo.y + b.albedo.z) * (1.0f / 3.0f);
  const float ws = 1.0f / (1.0f + base);
  const float coat = (1.0f - t_o) * ws, diffuse = t_o * (1.0f - ws);
  return coat + diffuse > 0.0f ? coat / (coat + diffuse) : 1.0f;
}

WT_HD WT_INLINE vec3 plastic_diffuse(const BsdfAt& b, float t_o, float t_i, float mu_i) {
  const vec3 base = b.albedo / (vec3(1.0f) - b.albedo * b.p.internal);
  return base * (t_o * t_i * mu_i / (kPi * b.ior * b.ior));
}

// Local frame (z = the facing shading normal): f cos without the smooth coat's mirror.
WT_HD WT_INLINE vec3 plastic_eval_local(const BsdfAt& b, const Ggx& g, const vec3& wo, const vec3& wi, float& pdf) {
  pdf = 0.0f;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return vec3(0.0f);
  const float t_o = plastic_transmittance(b, g, wo.z), t_i = plastic_transmittance(b, g, wi.z);
  const float coat = plastic_coat_share(b, t_o);
  vec3 f = plastic_diffuse(b, t_o, t_i, wi.z);
  pdf = (1.0f - coat) * wi.z / kPi;
  if (!g.smooth()) {
    const vec3 h = glm::normalize(wo + wi);
    const float ho = glm::dot(wo, h);
    f += vec3(fresnel_dielectric(ho, b.ior) * g.d(h) * g.g2(wo, wi) / (4.0f * wo.z));
    pdf += coat * g.visible_d(wo, h) / (4.0f * ho);
  }
  return f;
}

WT_HD WT_INLINE BsdfSample plastic_base_sample(const BsdfAt& b, const vec3& wo_world, const Rng& rng) {
  const Frame fr = b.facing_frame();
  const vec3 wo = fr.to_local(wo_world);
  if (wo.z <= 0.0f) return no_sample();
  const Ggx g = plastic_ggx(b);
  const float t_o = plastic_transmittance(b, g, wo.z);
  const float coat = plastic_coat_share(b, t_o);
  vec3 wi;
  const bool on_coat = rng.uniform(kDimLayer) < coat;
  if (on_coat && g.smooth()) {
    wi = fr.to_world(vec3(-wo.x, -wo.y, wo.z));
    if (!b.same_side(wi)) return no_sample();
    return BsdfSample{wi, vec3(fresnel_dielectric(wo.z, b.ior) / coat), 0.0f, kLobeSpecular | kLobeReflection};
  }
  if (on_coat) {
    wi = reflect_about(wo, g.sample_visible(wo, rng.uniform(kDimScatterA), rng.uniform(kDimScatterB)));
  } else {
    wi = cosine_direction(vec3(0.0f, 0.0f, 1.0f), rng.uniform(kDimScatterA), rng.uniform(kDimScatterB));
  }
  float pdf;
  const vec3 f = plastic_eval_local(b, g, wo, wi, pdf);
  if (!(pdf > 0.0f)) return no_sample();
  const vec3 wi_world = fr.to_world(wi);
  if (!b.same_side(wi_world)) return no_sample();
  return BsdfSample{wi_world, f * (1.0f / pdf), pdf, (on_coat ? kLobeGlossy : kLobeDiffuse) | kLobeReflection};
}

WT_HD WT_INLINE vec3 plastic_base_eval(const BsdfAt& b, const vec3& wo, const vec3& wi, float& pdf) {
  const Frame fr = b.facing_frame();
  return plastic_eval_local(b, plastic_ggx(b), fr.to_local(wo), fr.to_local(wi), pdf);
}

// A metallic plastic's metal: a Schlick conductor of f0 = albedo (F_avg = f0 +
// (1 - f0) / 21, Schlick's cosine-weighted mean) on the coat's lobe.
WT_HD WT_INLINE ConductorLobe plastic_metal(const BsdfAt& b) {
  return schlick_lobe(b.p.metal_table >= 0 ? static_cast<uint32_t>(kMaterialCompensated) : 0u, b.albedo, b.p.metal_table,
                      b.tables);
}

WT_HD WT_INLINE vec3 plastic_eval(const BsdfAt& b, const vec3& wo, const vec3& wi, float& pdf) {
  const float m = b.p.metallic;
  vec3 f = plastic_base_eval(b, wo, wi, pdf);
  if (!(m > 0.0f)) return f;
  const ConductorLobe metal = plastic_metal(b);
  const float metal_pdf = conductor_pdf(b, metal, wo, wi);
  pdf = (1.0f - m) * pdf + m * metal_pdf;
  return (1.0f - m) * f + m * conductor_eval(b, metal, wo, wi);
}

WT_HD WT_INLINE BsdfSample plastic_sample(const BsdfAt& b, const vec3& wo_world, const Rng& rng) {
  const float m = b.p.metallic;
  if (!(m > 0.0f)) return plastic_base_sample(b, wo_world, rng);
  BsdfSample s = rng.uniform(kDimLobe) < m ? conductor_sample(b, plastic_metal(b), wo_world, rng)
                                           : plastic_base_sample(b, wo_world, rng);
  // A delta lobe's weight is its component's (the pick's probability cancels the
  // mixture's factor); any other direction is weighed by the whole mixture.
  if (s.lobe == 0u || (s.lobe & kLobeSpecular)) return s;
  float pdf;
  const vec3 f = plastic_eval(b, wo_world, s.wi, pdf);
  if (!(pdf > 0.0f)) return no_sample();
  s.weight = f * (1.0f / pdf);
  s.pdf = pdf;
  return s;
}

}  // namespace wt

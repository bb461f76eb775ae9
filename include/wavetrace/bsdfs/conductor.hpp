// `conductor`: a GGX microfacet metal (anisotropic, height-correlated Smith masking,
// visible-normal sampling), with Fresnel from a complex index per channel or from
// Schlick's f0, and (kMaterialCompensated) the energy that single scattering loses
// put back by a diffuse-like multiple-scattering lobe (Kulla and Conty 2017,
// "Revisiting physically based shading at Imageworks"):
//   f_ms cos = multiple (1 - E(mu_o)) (1 - E(mu_i)) mu_i / pi,
// with E the GGX directional albedo at F = 1 (energy.hpp) and `multiple` =
// F_avg^2 E_avg / ((1 - E_avg)(1 - F_avg (1 - E_avg))) per channel (E_avg at the
// hit's roughness, which a texture may set), so that a white conductor (F = 1)
// reflects all that reaches it. Two-sided.
#pragma once

#include "wavetrace/bsdfs/common.hpp"
#include "wavetrace/bsdfs/energy.hpp"
#include "wavetrace/bsdfs/microfacet.hpp"

namespace wt {

// A conductor lobe as its functions read it: a copy of the few fields they need
// (the mixtures that hold several lobes at one hit, plastic's metal and
// principled's three, make theirs without copying the whole BsdfAt).
struct ConductorLobe {
  uint32_t flags;        // kMaterialSchlick, kMaterialCompensated
  vec3 eta, k;           // the complex index, or f0 with kMaterialSchlick
  vec3 fresnel_average;  // Kulla-Conty's F_avg
  int32_t table;         // the conductors' table (-1: none)
  const float* tables;
};

WT_HD WT_INLINE ConductorLobe conductor_lobe(const BsdfAt& b) {
  return ConductorLobe{b.flags, b.p.eta, b.p.k, b.p.fresnel_average, b.p.table, b.tables};
}

// A Schlick conductor of reflectance f0 (a metal of f0 = albedo, a dielectric
// layer's specular), compensated with `table` where the flags say.
WT_HD WT_INLINE ConductorLobe schlick_lobe(uint32_t flags, const vec3& f0, int32_t table, const float* tables) {
  return ConductorLobe{(flags & kMaterialCompensated) | kMaterialSchlick, f0, vec3(0.0f),
                       f0 + (vec3(1.0f) - f0) * (1.0f / 21.0f), table, tables};
}

WT_HD WT_INLINE vec3 conductor_fresnel(const ConductorLobe& c, float cos_i) {
  return (c.flags & kMaterialSchlick) ? schlick_f0(cos_i, c.eta) : fresnel_conductor(cos_i, c.eta, c.k);
}

// Kulla-Conty's scale of the multiple-scattering lobe, per channel, for the average
// Fresnel f_avg at the average albedo e_avg (0 where single scattering loses nothing).
WT_HD WT_INLINE vec3 conductor_multiple_scale(const vec3& f_avg, float e_avg) {
  const float lost = 1.0f - e_avg;
  if (!(lost > 1e-5f)) return vec3(0.0f);
  return f_avg * f_avg * e_avg / (lost * (vec3(1.0f) - f_avg * lost));
}

WT_HD WT_INLINE bool conductor_compensated(const ConductorLobe& c) {
  return (c.flags & kMaterialCompensated) != 0 && c.table >= 0;
}

// The probability of sampling the multiple-scattering lobe: the share single
// scattering misses at mu_o.
WT_HD WT_INLINE float conductor_multiple_share(const ConductorLobe& c, const Ggx& g, float mu_o) {
  if (!conductor_compensated(c)) return 0.0f;
  return 1.0f - conductor_energy(c.tables + c.table, table_roughness(g), mu_o);
}

// Local frame (z = the facing shading normal); wo.z > 0.
WT_HD WT_INLINE vec3 conductor_eval_local(const ConductorLobe& c, const Ggx& g, const vec3& wo, const vec3& wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return vec3(0.0f);
  const vec3 h = glm::normalize(wo + wi);
  vec3 f = conductor_fresnel(c, glm::dot(wo, h)) * (g.d(h) * g.g2(wo, wi) / (4.0f * wo.z));
  if (conductor_compensated(c) && !WT_MUTANT(CompensationDropped)) {
    const float* t = c.tables + c.table;
    const float r = table_roughness(g);
    f += conductor_multiple_scale(c.fresnel_average, conductor_average_energy(t, r)) *
         ((1.0f - conductor_energy(t, r, wo.z)) * (1.0f - conductor_energy(t, r, wi.z)) * wi.z / kPi);
  }
  return f;
}

WT_HD WT_INLINE float conductor_pdf_local(const ConductorLobe& c, const Ggx& g, const vec3& wo, const vec3& wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  const vec3 h = glm::normalize(wo + wi);
  const float q = conductor_multiple_share(c, g, wo.z);
  const float single = g.visible_d(wo, h) / (4.0f * glm::dot(wo, h));
  if (!(q > 0.0f)) return single;
  const float multiple = conductor_multiple_density(c.tables + c.table, table_roughness(g), wi.z) * (0.5f / kPi);
  return (1.0f - q) * single + q * multiple;
}

WT_HD WT_INLINE Ggx conductor_ggx(const BsdfAt& b) { return Ggx{b.p.ax, b.p.ay, (b.flags & kMaterialSeparable) != 0}; }

// A direction drawn from the rough lobe's density (conductor_pdf_local), local
// frame, wo.z > 0: the multiple-scattering lobe by its share (its shape in mu_i,
// energy.hpp, uniform in azimuth), else a visible normal's reflection.
WT_HD WT_INLINE vec3 conductor_direction_local(const ConductorLobe& c, const Ggx& g, const vec3& wo, const Rng& rng) {
  if (rng.uniform(kDimLayer) < conductor_multiple_share(c, g, wo.z)) {
    float density;
    const float mu = conductor_multiple_cosine(c.tables + c.table, table_roughness(g), rng.uniform(kDimScatterA), density);
    const float sin_t = sqrtf(fmaxf(0.0f, 1.0f - mu * mu)), phi = 2.0f * kPi * rng.uniform(kDimScatterB);
    return vec3(sin_t * cosf(phi), sin_t * sinf(phi), mu);
  }
  return reflect_about(wo, g.sample_visible(wo, rng.uniform(kDimScatterA), rng.uniform(kDimScatterB)));
}

// The lobe c at the hit b (its frame, roughness and geometric side).
WT_HD WT_INLINE BsdfSample conductor_sample(const BsdfAt& b, const ConductorLobe& c, const vec3& wo_world, const Rng& rng) {
  const Frame fr = b.facing_frame();
  const vec3 wo = fr.to_local(wo_world);
  if (wo.z <= 0.0f) return no_sample();
  const Ggx g = conductor_ggx(b);
  if (g.smooth()) {
    const vec3 wi = fr.to_world(vec3(-wo.x, -wo.y, wo.z));
    if (!b.same_side(wi)) return no_sample();
    return BsdfSample{wi, conductor_fresnel(c, wo.z), 0.0f, kLobeSpecular | kLobeReflection};
  }
  const vec3 wi = conductor_direction_local(c, g, wo, rng);
  const float pdf = conductor_pdf_local(c, g, wo, wi);
  if (!(pdf > 0.0f)) return no_sample();
  const vec3 wi_world = fr.to_world(wi);
  if (!b.same_side(wi_world)) return no_sample();
  return BsdfSample{wi_world, conductor_eval_local(c, g, wo, wi) * (1.0f / pdf), pdf, kLobeGlossy | kLobeReflection};
}

WT_HD WT_INLINE vec3 conductor_eval(const BsdfAt& b, const ConductorLobe& c, const vec3& wo, const vec3& wi) {
  const Ggx g = conductor_ggx(b);
  if (g.smooth()) return vec3(0.0f);
  const Frame fr = b.facing_frame();
  return conductor_eval_local(c, g, fr.to_local(wo), fr.to_local(wi));
}

WT_HD WT_INLINE float conductor_pdf(const BsdfAt& b, const ConductorLobe& c, const vec3& wo, const vec3& wi) {
  const Ggx g = conductor_ggx(b);
  if (g.smooth()) return 0.0f;
  const Frame fr = b.facing_frame();
  return conductor_pdf_local(c, g, fr.to_local(wo), fr.to_local(wi));
}

}  // namespace wt

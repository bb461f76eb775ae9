// `principled`: glTF 2.0's metallic-roughness material (its specification's
// Appendix B), a dielectric base and a metal mixed by `metallic` m:
//   f = (1 - m) f_dielectric + m F_m(h.o) spec,
// with spec = D G2 / (4 mu_o mu_i) the GGX lobe (height-correlated Smith masking,
// visible-normal sampling) at alpha = roughness^2 and F_m Schlick's Fresnel of f0 =
// albedo (the specification's conductor_fresnel). The dielectric is the
// specification's fresnel_mix of a Lambertian base under a specular layer of
// Schlick's Fresnel F_d of f0 = ((ior - 1) / (ior + 1))^2 (0.04 at glTF's ior 1.5),
//   f_dielectric = F_d(h.o) spec + albedo / pi (1 - E_s(mu_o)) (1 - E_s(mu_i)) / (1 - E_s,avg),
// the base weighed by what the layer does not reflect, E_s being the layer's
// directional albedo (a table per index: bsdf_tables.hpp), rather than by
// 1 - F_d(h.o) at the pair's half vector: that form, the specification's sketch,
// returns up to 35% more light than it receives at grazing angles (a white smooth
// base at 80 degrees), while this one (albedo scaling, as KHR_materials_sheen and
// KHR_materials_clearcoat layer theirs) returns exactly what the layer lets
// through, and is reciprocal. With kMaterialCompensated a rough lobe gets the
// energy single scattering loses back as conductors do (Kulla and Conty 2017,
// conductor.hpp) for each Fresnel's F_avg = f0 + (1 - f0) / 21: the layer's and
// the metal's, so that a white metal returns all that reaches it. Two-sided unless
// kMaterialOneSided (glTF's doubleSided false), whose back face reflects nothing.
//
// Sampled by picking the glossy lobe (the conductors' sampler, multiple-scattering
// lobe included) with its expected share at mu_o, else the cosine-weighted base,
// and weighed by the whole mixture's density. A smooth lobe (alpha below
// kSmoothAlpha) is a mirror of weight (1 - m) s F_d(mu_o) + m F_m(mu_o).
//
// The specular layer's strength s (MaterialParams::specular, glTF's
// KHR_materials_specular specularFactor) scales the layer's lobe and its albedo
// E_s alike, so that the base takes what the weaker layer lets through; s = 0 with
// m = 0 is a Lambertian.
#pragma once

#include "wavetrace/bsdfs/common.hpp"
#include "wavetrace/bsdfs/conductor.hpp"
#include "wavetrace/bsdfs/energy.hpp"
#include "wavetrace/bsdfs/microfacet.hpp"

namespace wt {

WT_HD WT_INLINE Ggx principled_ggx(const BsdfAt& b) { return Ggx{b.p.ax, b.p.ay, (b.flags & kMaterialSeparable) != 0}; }

// The dielectric base's f0 from its index (glTF's KHR_materials_ior relation).
WT_HD WT_INLINE float principled_f0(const BsdfAt& b) {
  const float r = (b.ior - 1.0f) / (b.ior + 1.0f);
  return r * r;
}

// The glossy lobe as a Schlick conductor of reflectance f0 (compensated where the
// material is): the dielectric's specular at f0 = F_d's, the metal's at the albedo.
WT_HD WT_INLINE BsdfAt principled_lobe(const BsdfAt& b, const vec3& f0) {
  BsdfAt c = b;
  c.kind = MaterialKind::Conductor;
  c.flags = (b.flags & (kMaterialSeparable | kMaterialCompensated)) | kMaterialSchlick;
  c.p.eta = f0;
  c.p.table = b.p.metal_table;
  c.p.fresnel_average = f0 + (vec3(1.0f) - f0) * (1.0f / 21.0f);
  return c;
}

// The specular layer's directional albedo E_s(mu), and its cosine-weighted average,
// times the layer's strength (MaterialParams::specular).
WT_HD WT_INLINE float principled_layer_albedo(const BsdfAt& b, const Ggx& g, float mu) {
  if (g.smooth() || b.p.table < 0) return b.p.specular * schlick_f0(mu, vec3(principled_f0(b))).x;
  return b.p.specular * rows_table(b.tables + b.p.table, kEnergySize, table_roughness(g), mu);
}
WT_HD WT_INLINE float principled_layer_average(const BsdfAt& b, const Ggx& g) {
  const float f0 = principled_f0(b);
  if (g.smooth() || b.p.table < 0) return b.p.specular * (f0 + (1.0f - f0) * (1.0f / 21.0f));
  return b.p.specular * cosine_table(b.tables + b.p.table + kEnergySize * kEnergySize, table_roughness(g));
}

// The probability of sampling the glossy lobe at mu_o: its expected share, the
// base counted at the albedo's mean.
WT_HD WT_INLINE float principled_glossy_share(const BsdfAt& b, const Ggx& g, float mu_o) {
  const float m = b.p.metallic;
  const float fd = principled_layer_albedo(b, g, mu_o);
  const vec3 fm = schlick_f0(mu_o, b.albedo);
  const float mean = (b.albedo.x + b.albedo.y + b.albedo.z) * (1.0f / 3.0f);
  const float glossy = (1.0f - m) * fd + m * (fm.x + fm.y + fm.z) * (1.0f / 3.0f);  // fd: the layer's, scaled
  const float diffuse = (1.0f - m) * (1.0f - fd) * mean;
  return glossy + diffuse > 0.0f ? glossy / (glossy + diffuse) : 1.0f;
}

// f cos and the density, local frame (z = the facing shading normal), without a
// smooth lobe's mirror.
WT_HD WT_INLINE vec3 principled_eval_local(const BsdfAt& b, const Ggx& g, const vec3& wo, const vec3& wi, float& pdf) {
  pdf = 0.0f;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return vec3(0.0f);
  const float m = b.p.metallic;
  const float f0 = principled_f0(b);
  const float q = principled_glossy_share(b, g, wo.z);
  const float through = (1.0f - principled_layer_albedo(b, g, wo.z)) * (1.0f - principled_layer_albedo(b, g, wi.z)) /
                        fmaxf(1.0f - principled_layer_average(b, g), 1e-6f);
  vec3 f = b.albedo * ((1.0f - m) * through * wi.z / kPi);
  pdf = (1.0f - q) * wi.z / kPi;
  if (!g.smooth()) {
    const BsdfAt dielectric = principled_lobe(b, vec3(f0)), metal = principled_lobe(b, b.albedo);
    if (m < 1.0f) f += ((1.0f - m) * b.p.specular) * conductor_eval_local(dielectric, g, wo, wi);
    if (m > 0.0f) f += m * conductor_eval_local(metal, g, wo, wi);
    // The two lobes' samplers differ only in the multiple-scattering lobe's share,
    // which depends on the roughness alone: one density serves both.
    pdf += q * conductor_pdf_local(metal, g, wo, wi);
  }
  return f;
}

WT_HD WT_INLINE BsdfSample principled_sample(const BsdfAt& b, const vec3& wo_world, const Rng& rng) {
  const Frame fr = b.facing_frame();
  const vec3 wo = fr.to_local(wo_world);
  if (wo.z <= 0.0f) return no_sample();
  const Ggx g = principled_ggx(b);
  const float q = principled_glossy_share(b, g, wo.z);
  const bool glossy = rng.uniform(kDimLobe) < q;
  vec3 wi;
  if (glossy && g.smooth()) {
    wi = fr.to_world(vec3(-wo.x, -wo.y, wo.z));
    if (!b.same_side(wi)) return no_sample();
    const float m = b.p.metallic;
    const vec3 mirror =
        ((1.0f - m) * b.p.specular) * schlick_f0(wo.z, vec3(principled_f0(b))) + m * schlick_f0(wo.z, b.albedo);
    return BsdfSample{wi, mirror * (1.0f / q), 0.0f, kLobeSpecular | kLobeReflection};
  }
  if (glossy) {
    wi = conductor_direction_local(principled_lobe(b, b.albedo), g, wo, rng);
  } else {
    wi = cosine_direction(vec3(0.0f, 0.0f, 1.0f), rng.uniform(kDimScatterA), rng.uniform(kDimScatterB));
  }
  float pdf;
  const vec3 f = principled_eval_local(b, g, wo, wi, pdf);
  if (!(pdf > 0.0f)) return no_sample();
  const vec3 wi_world = fr.to_world(wi);
  if (!b.same_side(wi_world)) return no_sample();
  return BsdfSample{wi_world, f * (1.0f / pdf), pdf, (glossy ? kLobeGlossy : kLobeDiffuse) | kLobeReflection};
}

WT_HD WT_INLINE vec3 principled_eval(const BsdfAt& b, const vec3& wo, const vec3& wi, float& pdf) {
  const Frame fr = b.facing_frame();
  return principled_eval_local(b, principled_ggx(b), fr.to_local(wo), fr.to_local(wi), pdf);
}

}  // namespace wt

// `principled`: glTF 2.0's metallic-roughness material (its specification's
// Appendix B) with the extensions that layer it: a dielectric base and a metal
// mixed by `metallic` m, under an optional clear coat:
//   f = f_coat + a (f_base),  f_base = (1 - m) f_dielectric + m F_m(h.o) spec,
// with spec = D G2 / (4 mu_o mu_i) the GGX lobe (height-correlated Smith masking,
// visible-normal sampling) at alpha = roughness^2 and F_m Schlick's Fresnel of f0 =
// albedo (the specification's conductor_fresnel). The dielectric is the
// specification's fresnel_mix of a base under a specular layer of Schlick's Fresnel
// F_d of f0 = ((ior - 1) / (ior + 1))^2 (0.04 at glTF's ior 1.5):
//   f_dielectric = s F_d(h.o) spec + (1 - t) albedo / pi (1 - E_s(mu_o)) (1 - E_s(mu_i)) / (1 - E_s,avg)
//                  + t f_transmission,
// the diffuse base weighed by what the layer does not reflect, E_s being the
// layer's directional albedo (a table per index: bsdf_tables.hpp), rather than by
// 1 - F_d(h.o) at the pair's half vector: that form, the specification's sketch,
// returns up to 35% more light than it receives at grazing angles (a white smooth
// base at 80 degrees), while this one (albedo scaling, as KHR_materials_sheen and
// KHR_materials_clearcoat layer theirs) returns exactly what the layer lets
// through, and is reciprocal. With kMaterialCompensated a rough lobe gets the
// energy single scattering loses back as conductors do (Kulla and Conty 2017,
// conductor.hpp) for each Fresnel's F_avg = f0 + (1 - f0) / 21: the layer's and
// the metal's, so that a white metal returns all that reaches it. Two-sided unless
// kMaterialOneSided (glTF's doubleSided false), whose back face reflects nothing
// (unless it transmits: a transmitting surface is seen from inside too).
//
// The specular layer's strength s (MaterialParams::specular, glTF's
// KHR_materials_specular specularFactor) scales the layer's lobe and its albedo
// E_s alike, so that the base takes what the weaker layer lets through; s = 0 with
// m = 0 is a Lambertian.
//
// Transmission t (KHR_materials_transmission) takes that share of the diffuse base
// and sends it through the surface, tinted by the base colour:
// - thin-walled (kMaterialThin): the layer's own lobe mirrored to the far side,
//   weighed by what the layer does not reflect, 1 - s F_d(h.o), plus the share of
//   the multiple-scattering energy the layer's compensation does not reflect, so
//   that layer and wall together return and pass all that reaches them (a white
//   wall: E_s(mu_o) reflected, 1 - E_s(mu_o) passed). Reciprocal.
// - a volume (KHR_materials_volume): the share t is `glass` (glass.hpp: exact
//   Fresnel at the index, refraction, Turquin's compensation), its transmission
//   tinted by the base colour; the layer and the diffuse base keep 1 - t. The
//   volume's absorption is applied along the path (path.hpp).
//
// The clear coat (KHR_materials_clearcoat) of weight c is a second GGX layer of
// index 1.5 (f0 = 0.04) with a roughness and a normal of its own; what it lets
// through to the rest is a = min(1 - c E_c(mu_o), 1 - c E_c(mu_i)), E_c its own
// directional albedo: reciprocal, and never more than the coat leaves at either
// direction, so that coat and base never return more than arrives (a white diffuse
// base under a full smooth coat returns 95% at normal incidence, the loss the
// min costs; the specification's non-reciprocal 1 - c F(mu_o) returns 100%).
//
// Sampled by picking a lobe (coat, glossy, diffuse, transmission) with its expected
// share at mu_o, the glossy and transmitted lobes through the conductors' sampler
// (the transmitted one mirrored to the far side), and weighed by the whole
// mixture's density. A smooth lobe (alpha below kSmoothAlpha) is a delta of its own
// weight over its share.
#pragma once

#include "wavetrace/bsdfs/common.hpp"
#include "wavetrace/bsdfs/conductor.hpp"
#include "wavetrace/bsdfs/energy.hpp"
#include "wavetrace/bsdfs/glass.hpp"
#include "wavetrace/bsdfs/microfacet.hpp"

namespace wt {

WT_HD WT_INLINE Ggx principled_ggx(const BsdfAt& b) { return Ggx{b.p.ax, b.p.ay, (b.flags & kMaterialSeparable) != 0}; }
WT_HD WT_INLINE Ggx principled_coat_ggx(const BsdfAt& b) {
  return Ggx{b.p.coat_alpha, b.p.coat_alpha, (b.flags & kMaterialSeparable) != 0};
}

// The clear coat's f0: glTF's fixed index of 1.5.
constexpr float kCoatF0 = 0.04f;

// The dielectric base's f0 from its index (glTF's KHR_materials_ior relation).
WT_HD WT_INLINE float principled_f0(const BsdfAt& b) {
  const float r = (b.ior - 1.0f) / (b.ior + 1.0f);
  return r * r;
}

// A glossy lobe as a Schlick conductor of reflectance f0 (compensated where the
// material is): the dielectric's specular at f0 = F_d's, the metal's at the albedo,
// the coat's at kCoatF0.
WT_HD WT_INLINE ConductorLobe principled_lobe(const BsdfAt& b, const vec3& f0) {
  return schlick_lobe(b.flags, f0, b.p.metal_table, b.tables);
}

// The volume's share as `glass` sees it: the index, the roughness's energy tables
// (rows by roughness) and the tint.
WT_HD WT_INLINE GlassLobe principled_glass(const BsdfAt& b) {
  return GlassLobe{b.flags & kMaterialCompensated, b.ior, b.albedo, b.p.glass_table, kEnergySize, b.tables};
}

// A Schlick layer's directional albedo E(mu) (from `table`, principled_table at its
// index), and its cosine-weighted average, times the layer's strength.
WT_HD WT_INLINE float layer_albedo(const BsdfAt& b, int32_t table, float f0, float strength, const Ggx& g, float mu) {
  if (g.smooth() || table < 0) return strength * schlick_f0(mu, vec3(f0)).x;
  return strength * rows_table(b.tables + table, kEnergySize, table_roughness(g), mu);
}
WT_HD WT_INLINE float layer_average(const BsdfAt& b, int32_t table, float f0, float strength, const Ggx& g) {
  if (g.smooth() || table < 0) return strength * (f0 + (1.0f - f0) * (1.0f / 21.0f));
  return strength * cosine_table(b.tables + table + kEnergySize * kEnergySize, table_roughness(g));
}

// The dielectric's f0 per channel: the index's, tinted by the specular colour
// (KHR_materials_specular's specularColorFactor), at most 1.
WT_HD WT_INLINE vec3 principled_f0_rgb(const BsdfAt& b) {
  return glm::min(vec3(principled_f0(b)) * b.p.specular_color, vec3(1.0f));
}

// A rough layer's albedo e (directional, or its average) at the index's f0, made
// the tinted f0's per channel: its single scattering is linear in f0 and is the
// conductors' e1 at f0 = 1, so it is moved along that line; the compensation's
// lobe, which is not (its F_avg^2), is taken off at f0 and put back at f0'. `lost`:
// (1 - e1) (1 - e1_avg), what the multiple-scattering lobe of scale 1 returns.
WT_HD WT_INLINE vec3 principled_tinted(const BsdfAt& b, float e, float e1, float e1_avg, float lost) {
  const float f0 = principled_f0(b);
  const vec3 f0t = principled_f0_rgb(b);
  auto multiple = [&](const vec3& f) {
    if (!(b.flags & kMaterialCompensated)) return vec3(0.0f);
    return conductor_multiple_scale(f + (vec3(1.0f) - f) * (1.0f / 21.0f), e1_avg) * lost;
  };
  const float single = e - multiple(vec3(f0)).x;
  return vec3(single) + (f0t - vec3(f0)) * ((e1 - single) / fmaxf(1.0f - f0, 1e-6f)) + multiple(f0t);
}

// The specular layer's E_s(mu) and average per channel, times its strength: Schlick's
// Fresnel of the tinted f0 where smooth, else the index's table, tinted where the
// layer is.
WT_HD WT_INLINE bool principled_untinted(const BsdfAt& b) {
  return b.p.specular_color.x == 1.0f && b.p.specular_color.y == 1.0f && b.p.specular_color.z == 1.0f;
}
WT_HD WT_INLINE vec3 principled_layer_albedo(const BsdfAt& b, const Ggx& g, float mu) {
  if (g.smooth() || b.p.table < 0) return b.p.specular * schlick_f0(mu, principled_f0_rgb(b));
  const float e = layer_albedo(b, b.p.table, principled_f0(b), 1.0f, g, mu);
  if (principled_untinted(b) || b.p.metal_table < 0) return vec3(b.p.specular * e);
  const float* t = b.tables + b.p.metal_table;
  const float r = table_roughness(g);
  const float e1 = conductor_energy(t, r, mu), e1_avg = conductor_average_energy(t, r);
  return b.p.specular * principled_tinted(b, e, e1, e1_avg, (1.0f - e1) * (1.0f - e1_avg));
}
WT_HD WT_INLINE vec3 principled_layer_average(const BsdfAt& b, const Ggx& g) {
  const vec3 f0 = principled_f0_rgb(b);
  if (g.smooth() || b.p.table < 0) return b.p.specular * (f0 + (vec3(1.0f) - f0) * (1.0f / 21.0f));
  const float e = layer_average(b, b.p.table, principled_f0(b), 1.0f, g);
  if (principled_untinted(b) || b.p.metal_table < 0) return vec3(b.p.specular * e);
  const float e1_avg = conductor_average_energy(b.tables + b.p.metal_table, table_roughness(g));
  return b.p.specular * principled_tinted(b, e, e1_avg, e1_avg, (1.0f - e1_avg) * (1.0f - e1_avg));
}

// The coat's c E_c(mu).
WT_HD WT_INLINE float principled_coat_albedo(const BsdfAt& b, const Ggx& gc, float mu) {
  return layer_albedo(b, b.p.coat_table, kCoatF0, b.p.clearcoat, gc, mu);
}

// The coat's weight and the transmission, as a kernel compiled with principled's
// layers (Layers, the kLayersAndAlpha bit) or without them (0: their code is left
// out; such a kernel serves scenes without them) reads them.
template <bool Layers>
WT_HD WT_INLINE float principled_clearcoat(const BsdfAt& b) {
  return Layers ? b.p.clearcoat : 0.0f;
}
template <bool Layers>
WT_HD WT_INLINE float principled_transmission(const BsdfAt& b) {
  return Layers ? b.p.transmission : 0.0f;
}

template <bool Layers = true>
WT_HD WT_INLINE bool principled_thick(const BsdfAt& b) {
  return principled_transmission<Layers>(b) > 0.0f && !(b.flags & kMaterialThin);
}

// The coat's shading frame on wo's side.
WT_HD WT_INLINE Frame principled_coat_frame(const BsdfAt& b) {
  return Frame::about(b.front ? b.coat_n : -b.coat_n, b.dpdu);
}

// The probabilities of sampling each lobe at mu_o (mu_oc: the coat's cosine):
// their expected shares, the diffuse and transmitted ones counted at the albedo's
// mean. They sum to 1.
struct PrincipledLobes {
  float coat, glossy, diffuse, transmit;
};

template <bool Layers = true>
WT_HD WT_INLINE PrincipledLobes principled_lobes(const BsdfAt& b, const Ggx& g, const Ggx& gc, float mu_o, float mu_oc) {
  const float m = b.p.metallic, t = principled_transmission<Layers>(b);
  const vec3 layer = principled_layer_albedo(b, g, mu_o);
  const float fd = (layer.x + layer.y + layer.z) * (1.0f / 3.0f);
  const vec3 fm = schlick_f0(mu_o, b.albedo);
  const float mean = (b.albedo.x + b.albedo.y + b.albedo.z) * (1.0f / 3.0f);
  const float coat = principled_clearcoat<Layers>(b) > 0.0f ? principled_coat_albedo(b, gc, mu_oc) : 0.0f;
  const float through = 1.0f - coat;
  const bool thick = principled_thick<Layers>(b);
  PrincipledLobes l;
  l.coat = coat;
  l.glossy = through * ((1.0f - m) * (thick ? 1.0f - t : 1.0f) * fd + m * (fm.x + fm.y + fm.z) * (1.0f / 3.0f));
  l.diffuse = through * (1.0f - m) * (1.0f - t) * (1.0f - fd) * mean;
  l.transmit = t > 0.0f ? through * (1.0f - m) * t * (thick ? fd + (1.0f - fd) * mean : (1.0f - fd) * mean) : 0.0f;
  const float sum = l.coat + l.glossy + l.diffuse + l.transmit;
  if (!(sum > 0.0f)) return PrincipledLobes{0.0f, 1.0f, 0.0f, 0.0f};
  const float inv = 1.0f / sum;
  return PrincipledLobes{l.coat * inv, l.glossy * inv, l.diffuse * inv, l.transmit * inv};
}

// The thin wall's transmitted lobe (before the tint) for wo and the mirror image wm
// of wi in the surface (both local, above): the layer's lobe weighed by 1 - s F_d,
// and the multiple-scattering energy the layer's compensation leaves.
WT_HD WT_INLINE vec3 principled_thin_local(const BsdfAt& b, const Ggx& g, const vec3& wo, const vec3& wm) {
  const vec3 h = glm::normalize(wo + wm);
  const vec3 f0 = principled_f0_rgb(b);
  const vec3 reflected = b.p.specular * schlick_f0(glm::dot(wo, h), f0);
  vec3 f = (vec3(1.0f) - reflected) * (g.d(h) * g.g2(wo, wm) / (4.0f * wo.z));
  if ((b.flags & kMaterialCompensated) && b.p.metal_table >= 0) {
    const float* t = b.tables + b.p.metal_table;
    const float r = table_roughness(g);
    const float e = conductor_average_energy(t, r);
    if (1.0f - e > 1e-5f) {
      // All the multiple scattering of a white lobe, 1 / (1 - E_avg), less the layer's.
      const vec3 scale = vec3(1.0f / (1.0f - e)) -
                         b.p.specular * conductor_multiple_scale(f0 + (vec3(1.0f) - f0) * (1.0f / 21.0f), e);
      f += glm::max(scale, vec3(0.0f)) *
           ((1.0f - conductor_energy(t, r, wo.z)) * (1.0f - conductor_energy(t, r, wm.z)) * wm.z / kPi);
    }
  }
  return f;
}

// f cos and the density of every lobe that is not a delta, for world directions.
template <bool Layers = true>
WT_HD WT_INLINE vec3 principled_eval_all(const BsdfAt& b, const vec3& wo_world, const vec3& wi_world, float& pdf) {
  pdf = 0.0f;
  const Frame fr = b.facing_frame();
  const vec3 wo = fr.to_local(wo_world), wi = fr.to_local(wi_world);
  if (wo.z <= 0.0f || wi.z == 0.0f) return vec3(0.0f);
  const Ggx g = principled_ggx(b), gc = principled_coat_ggx(b);
  const float m = b.p.metallic, t = principled_transmission<Layers>(b);
  vec3 f(0.0f);
  // The coat: its lobe, and what it lets through.
  float through = 1.0f;
  float mu_oc = wo.z;
  PrincipledLobes l;
  if (principled_clearcoat<Layers>(b) > 0.0f) {
    const Frame fc = principled_coat_frame(b);
    const vec3 co = fc.to_local(wo_world), ci = fc.to_local(wi_world);
    mu_oc = fmaxf(co.z, 0.0f);
    l = principled_lobes<Layers>(b, g, gc, wo.z, mu_oc);
    through = fminf(1.0f - principled_coat_albedo(b, gc, mu_oc), 1.0f - principled_coat_albedo(b, gc, fabsf(ci.z)));
    if (!gc.smooth() && co.z > 0.0f && ci.z > 0.0f) {
      const ConductorLobe coat = principled_lobe(b, vec3(kCoatF0));
      f += b.p.clearcoat * conductor_eval_local(coat, gc, co, ci);
      pdf += l.coat * conductor_pdf_local(coat, gc, co, ci);
    }
  } else {
    l = principled_lobes<Layers>(b, g, gc, wo.z, mu_oc);
  }
  const bool thick = principled_thick<Layers>(b);
  const ConductorLobe metal = principled_lobe(b, b.albedo);
  if (wi.z > 0.0f) {
    const vec3 layer = (vec3(1.0f) - principled_layer_albedo(b, g, wo.z)) *
                       (vec3(1.0f) - principled_layer_albedo(b, g, wi.z)) /
                       glm::max(vec3(1.0f) - principled_layer_average(b, g), vec3(1e-6f));
    f += b.albedo * layer * (through * (1.0f - m) * (1.0f - t) * wi.z / kPi);
    pdf += l.diffuse * wi.z / kPi;
    if (!g.smooth()) {
      const float dielectric_share = (1.0f - m) * b.p.specular * (thick ? 1.0f - t : 1.0f);
      if (dielectric_share > 0.0f) {
        f += (through * dielectric_share) * conductor_eval_local(principled_lobe(b, principled_f0_rgb(b)), g, wo, wi);
      }
      if (m > 0.0f) f += (through * m) * conductor_eval_local(metal, g, wo, wi);
      // The lobes' samplers differ only in the multiple-scattering lobe's share,
      // which depends on the roughness alone: one density serves them all.
      pdf += l.glossy * conductor_pdf_local(metal, g, wo, wi);
    }
  } else if (t > 0.0f && !thick && !g.smooth()) {
    const vec3 wm(wi.x, wi.y, -wi.z);
    f += b.albedo * (through * (1.0f - m) * t * principled_thin_local(b, g, wo, wm));
    pdf += l.transmit * conductor_pdf_local(metal, g, wo, wm);
  }
  if (thick && !g.smooth()) {
    const Frame fo = b.outward_frame();
    float glass_pdf;
    const vec3 fg = glass_eval_local(principled_glass(b), g, fo.to_local(wo_world), fo.to_local(wi_world), glass_pdf);
    f += fg * (through * (1.0f - m) * t);
    pdf += l.transmit * glass_pdf;
  }
  return f;
}

// Whether a one-sided face is seen from behind (then it neither reflects nor passes light).
WT_HD WT_INLINE bool principled_culled(const BsdfAt& b) {
  return (b.flags & kMaterialOneSided) && !b.front && !(b.p.transmission > 0.0f);
}

template <bool Layers = true>
WT_HD WT_INLINE BsdfSample principled_sample(const BsdfAt& b, const vec3& wo_world, const Rng& rng) {
  if (principled_culled(b)) return no_sample();
  const Frame fr = b.facing_frame();
  const vec3 wo = fr.to_local(wo_world);
  if (wo.z <= 0.0f) return no_sample();
  const Ggx g = principled_ggx(b), gc = principled_coat_ggx(b);
  const bool coated = principled_clearcoat<Layers>(b) > 0.0f;
  const Frame fc = coated ? principled_coat_frame(b) : fr;
  const vec3 co = coated ? fc.to_local(wo_world) : wo;
  const PrincipledLobes l = principled_lobes<Layers>(b, g, gc, wo.z, fmaxf(co.z, 0.0f));
  const float m = b.p.metallic, t = principled_transmission<Layers>(b);
  const bool thick = principled_thick<Layers>(b);
  // What the coat lets through for wi (a delta's weight needs it).
  auto through = [&](const vec3& wi_world) {
    if (!coated) return 1.0f;
    return fminf(1.0f - principled_coat_albedo(b, gc, fmaxf(co.z, 0.0f)),
                 1.0f - principled_coat_albedo(b, gc, fabsf(glm::dot(wi_world, fc.n))));
  };
  const float u = rng.uniform(kDimLobe);
  vec3 wi_world;
  uint32_t lobe;
  if (u < l.coat) {
    if (gc.smooth()) {
      wi_world = fc.to_world(vec3(-co.x, -co.y, co.z));
      if (!(co.z > 0.0f) || !b.same_side(wi_world)) return no_sample();
      const float weight = b.p.clearcoat * schlick_f0(co.z, vec3(kCoatF0)).x / l.coat;
      return BsdfSample{wi_world, vec3(weight), 0.0f, kLobeSpecular | kLobeReflection};
    }
    if (!(co.z > 0.0f)) return no_sample();
    wi_world = fc.to_world(conductor_direction_local(principled_lobe(b, vec3(kCoatF0)), gc, co, rng));
    lobe = kLobeGlossy | kLobeReflection;
  } else if (u < l.coat + l.glossy) {
    if (g.smooth()) {
      wi_world = fr.to_world(vec3(-wo.x, -wo.y, wo.z));
      if (!b.same_side(wi_world)) return no_sample();
      const vec3 mirror = ((1.0f - m) * b.p.specular * (thick ? 1.0f - t : 1.0f)) *
                              schlick_f0(wo.z, principled_f0_rgb(b)) +
                          m * schlick_f0(wo.z, b.albedo);
      return BsdfSample{wi_world, mirror * (through(wi_world) / l.glossy), 0.0f, kLobeSpecular | kLobeReflection};
    }
    wi_world = fr.to_world(conductor_direction_local(principled_lobe(b, b.albedo), g, wo, rng));
    lobe = kLobeGlossy | kLobeReflection;
  } else if (u < l.coat + l.glossy + l.diffuse || !(l.transmit > 0.0f)) {
    wi_world = fr.to_world(cosine_direction(vec3(0.0f, 0.0f, 1.0f), rng.uniform(kDimScatterA), rng.uniform(kDimScatterB)));
    lobe = kLobeDiffuse | kLobeReflection;
  } else if (!thick) {
    if (g.smooth()) {
      // Straight through the thin wall, less what the layer reflects.
      wi_world = -wo_world;
      const vec3 passed = vec3(1.0f) - b.p.specular * schlick_f0(wo.z, principled_f0_rgb(b));
      const vec3 weight = b.albedo * ((1.0f - m) * t * passed * through(wi_world) / l.transmit);
      return BsdfSample{wi_world, weight, 0.0f, kLobeSpecular | kLobeTransmission};
    }
    const vec3 wm = conductor_direction_local(principled_lobe(b, b.albedo), g, wo, rng);
    wi_world = fr.to_world(vec3(wm.x, wm.y, -wm.z));
    lobe = kLobeGlossy | kLobeTransmission;
  } else {
    const Frame fo = b.outward_frame();
    BsdfSample s = glass_sample_local(principled_glass(b), g, fo.to_local(wo_world), rng);
    if (s.lobe == 0u) return s;
    s.wi = fo.to_world(s.wi);
    if (b.same_side(s.wi) != ((s.lobe & kLobeReflection) != 0)) return no_sample();
    if (s.lobe & kLobeSpecular) {
      s.weight *= (1.0f - m) * t * through(s.wi) / l.transmit;
      return s;
    }
    wi_world = s.wi;
    lobe = s.lobe;
  }
  if (b.same_side(wi_world) != ((lobe & kLobeReflection) != 0)) return no_sample();
  float pdf;
  const vec3 f = principled_eval_all<Layers>(b, wo_world, wi_world, pdf);
  if (!(pdf > 0.0f)) return no_sample();
  return BsdfSample{wi_world, f * (1.0f / pdf), pdf, lobe};
}

template <bool Layers = true>
WT_HD WT_INLINE vec3 principled_eval(const BsdfAt& b, const vec3& wo, const vec3& wi, float& pdf) {
  pdf = 0.0f;
  if (principled_culled(b)) return vec3(0.0f);
  // A transmitting surface: reflection stays on wo's side of the geometric surface,
  // transmission crosses it (as the sampler keeps them).
  if (principled_transmission<Layers>(b) > 0.0f && b.same_side(wi) != (glm::dot(wi, b.facing_n()) > 0.0f)) return vec3(0.0f);
  return principled_eval_all(b, wo, wi, pdf);
}

}  // namespace wt

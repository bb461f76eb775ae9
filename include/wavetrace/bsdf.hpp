// The BSDF contract: the one place that switches on a material's kind. Every kind
// is a header of its own under bsdfs/, giving
//   sample(wo, rng) -> wi, weight = f cos / pdf, pdf and the lobe (BsdfSample),
//   eval(wo, wi)    -> f |cos theta_i|,
//   pdf(wo, wi)     -> the density with which sample draws wi,
// with eval and pdf zero for specular (delta) lobes, which light sampling skips.
// The light transport (path.hpp) uses only these functions. Adding a kind touches
// its header, the switches here, the scene reader's table of kinds and the docs.
#pragma once

#include "wavetrace/bsdfs/coated.hpp"
#include "wavetrace/bsdfs/conductor.hpp"
#include "wavetrace/bsdfs/dielectric.hpp"
#include "wavetrace/bsdfs/glass.hpp"
#include "wavetrace/bsdfs/lambertian.hpp"
#include "wavetrace/bsdfs/metal.hpp"
#include "wavetrace/bsdfs/plastic.hpp"
#include "wavetrace/bsdfs/principled.hpp"
#include "wavetrace/geometry/alpha.hpp"
#include "wavetrace/mutant.hpp"

namespace wt {

// What bsdf_at reads of the scene: its material_params, bsdf_tables, textures and
// images.
struct BsdfInputs {
  const MaterialParams* params;
  const float* tables;
  const Texture* textures;
  const ImageView* images;
};

// The shading normal a bump (height) map gives about normal n: the surface displaced
// along n by d = scale h, its normal n - grad d, d's gradient along the surface to
// first order (Blinn 1978). The map's texel holds h's derivatives in the texture's
// coordinates (dh/du', dh/dv'); the UV transform's Jacobian J (texture_uv) carries
// them to the surface's u and v (J^T), and the UV rates, UV units per unit length
// along u and v, to world units: a triangle's uv_density on both (exact where its UV
// map neither shears nor stretches one axis against the other), a sphere's
// 1 / (2 pi r sin theta) along u and 1 / (pi r) along v. Without UVs (density 0) the
// surface is not bumped.
WT_HD WT_INLINE vec3 bumped_normal(const vec3& n, const SurfacePoint& sp, const Texture& t, const vec3& texel,
                                   float scale) {
  const vec2 g(t.uv_cos * texel.x - t.uv_sin * texel.y, t.uv_sin * texel.x + t.uv_cos * texel.y);
  const vec2 rate = sp.has_uv ? vec2(sp.uv_density) : sphere_uv_rates(sp);
  const vec2 slope = scale * g * t.uv_scale * rate;  // d's derivatives along u and v, per unit length
  // B times tangent_sign points towards decreasing v.
  const Frame f = Frame::about(n, sp.dpdu);
  const vec3 m = n - slope.x * f.t + (slope.y * sp.tangent_sign) * f.b;
  const float len2 = glm::dot(m, m);
  return len2 > 1e-12f && len2 < 1e30f ? m * (1.0f / sqrtf(len2)) : n;
}

// Principled's textured coat (weight: red; roughness: green; its normal map) and
// transmission (red), looked up where the material has them. Layers = false: a
// kernel without principled's layers (kLayersAndAlpha), for scenes whose
// materials have no coat and no transmission; they stay 0 there.
template <bool Layers = true>
WT_HD WT_INLINE void principled_textures(BsdfAt& b, const BsdfInputs& in, const SurfacePoint& sp, const vec3& wo) {
  auto channel = [&](int32_t texture, int c) {
    return fminf(fmaxf(eval_texture(in.textures[texture], in.images, sp)[c], 0.0f), 1.0f);
  };
  if (b.p.specular_texture >= 0) {
    b.p.specular *= fminf(fmaxf(texture_alpha(in.textures[b.p.specular_texture], in.images,
                                              sp.has_uv ? sp.uv : sphere_uv(sp.n)),
                                0.0f),
                          1.0f);
  }
  if (b.p.specular_color_texture >= 0) {
    b.p.specular_color *= eval_texture(in.textures[b.p.specular_color_texture], in.images, sp);
  }
  if constexpr (!Layers) {
    b.p.transmission = 0.0f;
    b.p.clearcoat = 0.0f;
    return;
  }
  if (b.p.transmission_texture >= 0) b.p.transmission *= channel(b.p.transmission_texture, 0);
  if (!(b.p.clearcoat > 0.0f)) return;
  if (b.p.clearcoat_texture >= 0) b.p.clearcoat *= channel(b.p.clearcoat_texture, 0);
  if (b.p.coat_roughness_texture >= 0) {
    const float r = channel(b.p.coat_roughness_texture, 1);
    b.p.coat_alpha *= r * r;
  }
  if (b.p.coat_normal_texture >= 0) {
    b.coat_n = mapped_normal(sp.n, sp.dpdu, sp.tangent_sign,
                             eval_texture(in.textures[b.p.coat_normal_texture], in.images, sp), b.p.coat_normal_strength);
  }
  b.coat_n = facing_viewer(b.coat_n, wo, b.front);
}

// The BSDF of material m at sp seen from wo, its albedo there being `albedo`
// (material_albedo). Where the material has parameters beyond the study's
// (Microfacet kernels only): its textured roughness and normal map are looked up,
// and the shading normal is turned to face wo (facing_viewer).
template <bool Microfacet = true, bool Layers = Microfacet>
WT_HD WT_INLINE BsdfAt bsdf_at(const Material& m, const BsdfInputs& in, const SurfacePoint& sp, const vec3& albedo,
                               const vec3& wo) {
  BsdfAt b;
  b.kind = m.kind;
  b.flags = m.flags;
  b.fuzz = m.fuzz;
  b.ior = m.ior;
  b.albedo = albedo;
  b.n = sp.n;
  b.ng = sp.ng;
  b.dpdu = sp.dpdu;
  b.front = sp.front;
  b.tables = in.tables;
  b.coat_n = sp.n;
  b.p = MaterialParams{};
  if constexpr (Microfacet) {
    if (m.params >= 0) {
      b.p = in.params[m.params];
      // glTF's metallicRoughnessTexture is one texture for both: looked up once.
      vec3 texel(1.0f);
      if (b.p.roughness_texture >= 0) {
        // Roughness scales by the texture's green channel, alpha by its square.
        texel = eval_texture(in.textures[b.p.roughness_texture], in.images, sp);
        const float r = fminf(fmaxf(texel.y, 0.0f), 1.0f);
        b.p.ax *= r * r;
        b.p.ay *= r * r;
        if (b.kind == MaterialKind::Plastic && b.p.table >= 0 && b.p.table_rows > 1) {
          b.p.internal = cosine_table(in.tables + b.p.table + b.p.table_rows * kEnergySize,
                                      table_roughness(Ggx{b.p.ax, b.p.ay}));
        }
      }
      if (b.p.metallic_texture >= 0) {
        // Metallic scales by the texture's blue channel (glTF's metallicRoughnessTexture).
        if (b.p.metallic_texture != b.p.roughness_texture) {
          texel = eval_texture(in.textures[b.p.metallic_texture], in.images, sp);
        }
        b.p.metallic *= fminf(fmaxf(texel.z, 0.0f), 1.0f);
      }
      if (b.p.normal_texture >= 0) {
        b.n = mapped_normal(sp.n, sp.dpdu, sp.tangent_sign,
                            eval_texture(in.textures[b.p.normal_texture], in.images, sp), b.p.normal_strength);
      }
      if (b.p.bump_texture >= 0) {
        const Texture& t = in.textures[b.p.bump_texture];
        b.n = bumped_normal(b.n, sp, t, eval_texture(t, in.images, sp), b.p.bump_scale);
      }
      b.n = facing_viewer(b.n, wo, b.front);
      if (b.kind == MaterialKind::Principled) principled_textures<Layers>(b, in, sp, wo);
    }
  }
  return b;
}

// Microfacet = false: compiled for scenes without the microfacet kinds (a kernel's
// kMicrofacet bit), whose code it leaves out; Layers = false, for scenes without
// principled's coat and transmission (kLayersAndAlpha).
template <bool Microfacet = true, bool Layers = Microfacet>
WT_HD WT_INLINE BsdfSample sample_bsdf(const BsdfAt& b, const vec3& wo, const Rng& rng) {
  switch (b.kind) {
    case MaterialKind::Lambertian: return lambertian_sample(b, wo, rng);
    case MaterialKind::Metal: return metal_sample(b, wo, rng);
    case MaterialKind::Dielectric: return dielectric_sample(b, wo, rng);
    case MaterialKind::Coated: return coated_sample(b, wo, rng);
    case MaterialKind::Conductor:
      if constexpr (Microfacet) return conductor_sample(b, conductor_lobe(b), wo, rng);
      break;
    case MaterialKind::Glass:
      if constexpr (Microfacet) return glass_sample(b, wo, rng);
      break;
    case MaterialKind::Plastic:
      if constexpr (Microfacet) return plastic_sample(b, wo, rng);
      break;
    case MaterialKind::Principled:
      if constexpr (Microfacet) return principled_sample<Layers>(b, wo, rng);
      break;
    case MaterialKind::Emissive:
    case MaterialKind::Blend: break;  // a blend shades as the material it picks (blend.hpp)
  }
  return no_sample();
}

// f cos for wi, and (in `pdf`) the density sample_bsdf draws it with.
template <bool Microfacet = true, bool Layers = Microfacet>
WT_HD WT_INLINE vec3 eval_bsdf(const BsdfAt& b, const vec3& wo, const vec3& wi, float& pdf) {
  pdf = 0.0f;
  vec3 f(0.0f);
  switch (b.kind) {
    case MaterialKind::Lambertian:
      pdf = lambertian_pdf(b, wo, wi);
      f = lambertian_eval(b, wo, wi);
      break;
    case MaterialKind::Metal:
      pdf = metal_pdf(b, wo, wi);
      f = metal_eval(b, wo, wi);
      break;
    case MaterialKind::Coated:
      pdf = coated_pdf(b, wo, wi);
      f = coated_eval(b, wo, wi);
      break;
    case MaterialKind::Conductor:
      if constexpr (Microfacet) {
        pdf = conductor_pdf(b, conductor_lobe(b), wo, wi);
        f = conductor_eval(b, conductor_lobe(b), wo, wi);
      }
      break;
    case MaterialKind::Glass:
      if constexpr (Microfacet) f = glass_eval(b, wo, wi, pdf);
      break;
    case MaterialKind::Plastic:
      if constexpr (Microfacet) f = plastic_eval(b, wo, wi, pdf);
      break;
    case MaterialKind::Principled:
      if constexpr (Microfacet) f = principled_eval<Layers>(b, wo, wi, pdf);
      break;
    case MaterialKind::Dielectric:
    case MaterialKind::Emissive:
    case MaterialKind::Blend: break;
  }
  if (WT_MUTANT(BsdfPdfScaled)) pdf *= 1.05f;
  return f;
}

WT_HD WT_INLINE vec3 eval_bsdf(const BsdfAt& b, const vec3& wo, const vec3& wi) {
  float pdf;
  return eval_bsdf(b, wo, wi, pdf);
}

WT_HD WT_INLINE float pdf_bsdf(const BsdfAt& b, const vec3& wo, const vec3& wi) {
  float pdf;
  eval_bsdf(b, wo, wi, pdf);
  return pdf;
}

// Whether the BSDF has a lobe that is not a delta, which light sampling can reach.
template <bool Microfacet = true>
WT_HD WT_INLINE bool bsdf_samples_lights(const BsdfAt& b) {
  switch (b.kind) {
    case MaterialKind::Lambertian:
    case MaterialKind::Coated: return true;
    case MaterialKind::Plastic: return Microfacet;
    case MaterialKind::Principled: return Microfacet && !principled_culled(b);
    case MaterialKind::Metal: return b.fuzz > 0.0f;
    case MaterialKind::Conductor: return Microfacet && !conductor_ggx(b).smooth();
    case MaterialKind::Glass: return Microfacet && !(b.flags & kMaterialThin) && !glass_ggx(b).smooth();
    case MaterialKind::Dielectric:
    case MaterialKind::Emissive:
    case MaterialKind::Blend: break;
  }
  return false;
}

// Whether the BSDF can send light through the surface (light sampling then looks
// on both sides of it).
WT_HD WT_INLINE bool bsdf_transmits(const BsdfAt& b) {
  return b.kind == MaterialKind::Glass || (b.kind == MaterialKind::Principled && b.p.transmission > 0.0f);
}

}  // namespace wt

// The materials: how a hit scatters the path and what it emits.
#pragma once

#include "wavetrace/geometry/surface.hpp"
#include "wavetrace/optics.hpp"
#include "wavetrace/sampling.hpp"
#include "wavetrace/texture.hpp"

namespace wt {

enum class MaterialKind : uint32_t { Lambertian = 0, Metal = 1, Dielectric = 2, Coated = 3, Emissive = 4 };
constexpr uint32_t kMaterialKindCount = 5;

struct Material {
  MaterialKind kind;
  int32_t texture;  // < 0: the constant albedo
  float fuzz;       // Metal
  float ior;        // Dielectric, Coated (the coat)
  vec3 albedo;      // Lambertian, Metal, Coated (the base); Dielectric: transmission tint
  vec3 emission;    // Emissive
  // Shading work differs by material kind and by texture kind; this key groups hits
  // that run the same code, so that sorting by it gives warps one code path.
  uint32_t sort_key;
};

// Sort keys: kind * 4 + texture slot (0 untextured, 1 + TextureKind).
WT_HD WT_INLINE uint32_t material_sort_key(MaterialKind kind, int texture_kind /* -1: none */) {
  return static_cast<uint32_t>(kind) * 4u + static_cast<uint32_t>(texture_kind + 1);
}
constexpr uint32_t kSortKeyCount = kMaterialKindCount * 4;
constexpr uint32_t kSortKeyMiss = kSortKeyCount;  // paths that left the scene sort last
static_assert(kSortKeyCount <= 32, "a bounce's sort keys are gathered as the bits of one word");

WT_HD WT_INLINE vec3 material_albedo(const Material& m, const Texture* textures, const ImageView* images,
                                     const SurfacePoint& sp) {
  return m.texture < 0 ? m.albedo : m.albedo * eval_texture(textures[m.texture], images, sp);
}

WT_HD WT_INLINE void scatter_lambertian(const vec3& albedo, const SurfacePoint& sp, const vec3& facing_n,
                                        const Rng& rng, vec3& attenuation, Ray& next) {
  vec3 d = cosine_direction(facing_n, rng.uniform(kDimScatterA), rng.uniform(kDimScatterB));
  attenuation = albedo;
  next = spawn_ray(sp, d);
}

// Mirror reflection perturbed by fuzz; absorbed when the perturbation sends it
// below the surface.
WT_HD WT_INLINE bool scatter_metal(const Material& m, const vec3& albedo, const Ray& in, const SurfacePoint& sp,
                                   const vec3& facing_n, const Rng& rng, vec3& attenuation, Ray& next) {
  vec3 d = reflect(in.dir, facing_n);
  if (m.fuzz > 0.0f) {
    d = d + m.fuzz * unit_sphere_point(rng.uniform(kDimFuzzA), rng.uniform(kDimFuzzB));
    float len2 = glm::dot(d, d);
    if (len2 < 1e-12f || glm::dot(d, facing_n) <= 0.0f) return false;
    d *= 1.0f / sqrtf(len2);
  }
  attenuation = albedo;
  next = spawn_ray(sp, d);
  return true;
}

// The density per unit solid angle with which scatter_metal's normalize(r + fuzz s),
// s uniform on the unit sphere, points along `dir` (unit), for the mirror direction
// `reflected` = r (unit) and fuzz > 0: over the whole sphere of directions, before
// the absorption below the surface, which only takes directions away. The point
// r + fuzz s is uniform by area on the sphere of radius fuzz about r. With
// c = cos a = dot(dir, r) and q = sqrt(fuzz^2 - sin^2 a), the ray t dir meets that
// sphere at t = c -+ q, where the cosine between dir and the sphere's normal is
// q / fuzz; each meeting with t > 0 adds (1 / (4 pi fuzz^2)) t^2 / (q / fuzz)
// = t^2 / (4 pi fuzz q).
//   fuzz < 1: the origin lies outside the sphere. Directions with c <= 0 or
//     sin a > fuzz miss it; the others meet it twice, and the two t^2 sum to
//     2 (c^2 + q^2), which has no cancellation in c - q.
//   fuzz >= 1: the origin is inside the sphere (on it at fuzz = 1), and only
//     t = c + q counts; where c < 0 it is written (fuzz^2 - 1) / (q - c) against
//     cancellation. At fuzz = 1 that is 0, and for c > 0 the density is c / pi
//     (cosine_direction).
// sin^2 a is |(dir - r) x r|^2: the same vector as dir x r, but dir - r is exact
// near r, so small angles keep their relative precision (1 - c^2 loses it there,
// and the products in dir x r round to 1e-7 absolute). At the rim of the cone
// (sin a = fuzz < 1) the density grows without bound like 1 / q; q is kept at
// least 1e-6 fuzz (q^2 >= 1e-12 fuzz^2), so the rim gets a large finite value and
// no finite input gives inf or NaN (unless fuzz is so small that 1 / fuzz^2
// overflows a float).
WT_HD WT_INLINE float metal_fuzz_pdf(const vec3& reflected, float fuzz, const vec3& dir) {
  const vec3 x = glm::cross(dir - reflected, reflected);
  const float sin_a = sqrtf(glm::dot(x, x));
  const float c = glm::dot(dir, reflected);
  if (fuzz < 1.0f && (c <= 0.0f || sin_a > fuzz)) return 0.0f;
  const float q = fmaxf(sqrtf(fmaxf(0.0f, (fuzz - sin_a) * (fuzz + sin_a))), 1e-6f * fuzz);
  if (fuzz < 1.0f) return (c * c + q * q) / (2.0f * kPi * fuzz * q);
  const float t = c >= 0.0f ? c + q : (fuzz - 1.0f) * (fuzz + 1.0f) / (q - c);
  return t * t / (4.0f * kPi * fuzz * q);
}

// Reflect with Schlick's probability (always under total internal reflection), else refract.
WT_HD WT_INLINE void scatter_dielectric(const Material& m, const vec3& albedo, const Ray& in,
                                        const SurfacePoint& sp, const vec3& facing_n, const Rng& rng,
                                        vec3& attenuation, Ray& next) {
  float eta = sp.front ? 1.0f / m.ior : m.ior;
  float cos_i = fminf(-glm::dot(in.dir, facing_n), 1.0f);
  vec3 d;
  if (!refract(in.dir, facing_n, eta, d) || rng.uniform(kDimLayer) < schlick(cos_i, eta)) {
    d = reflect(in.dir, facing_n);
  }
  attenuation = albedo;
  next = spawn_ray(sp, glm::normalize(d));
}

// A clear dielectric coat over a Lambertian base: the coat reflects with Schlick's
// probability; otherwise light reaches the base and leaves diffusely.
WT_HD WT_INLINE void scatter_coated(const Material& m, const vec3& albedo, const Ray& in, const SurfacePoint& sp,
                                    const vec3& facing_n, const Rng& rng, vec3& attenuation, Ray& next) {
  float cos_i = fminf(-glm::dot(in.dir, facing_n), 1.0f);
  if (sp.front && rng.uniform(kDimLayer) < schlick(cos_i, 1.0f / m.ior)) {
    attenuation = vec3(1.0f);
    next = spawn_ray(sp, reflect(in.dir, facing_n));
    return;
  }
  scatter_lambertian(albedo, sp, facing_n, rng, attenuation, next);
}

// A reflection about a shading normal can point below the geometric surface,
// where it would pass through the surface it leaves: the path ends there instead.
WT_HD WT_INLINE bool above_surface(const SurfacePoint& sp, const Ray& next) {
  return glm::dot(next.dir, sp.front ? sp.ng : -sp.ng) >= 0.0f;
}

// Scatters the path at a hit, given the surface's albedo there (material_albedo:
// the caller may need it twice, and a texture is worth evaluating once). Returns
// false when the path ends there (absorbed or emitter).
WT_HD WT_INLINE bool scatter_with_albedo(const Material& m, const vec3& albedo, const Ray& in,
                                         const SurfacePoint& sp, const Rng& rng, vec3& attenuation, Ray& next) {
  vec3 facing_n = sp.front ? sp.n : -sp.n;
  switch (m.kind) {
    case MaterialKind::Lambertian:
      scatter_lambertian(albedo, sp, facing_n, rng, attenuation, next);
      return above_surface(sp, next);
    case MaterialKind::Metal:
      return scatter_metal(m, albedo, in, sp, facing_n, rng, attenuation, next) && above_surface(sp, next);
    case MaterialKind::Dielectric:
      scatter_dielectric(m, albedo, in, sp, facing_n, rng, attenuation, next);
      return true;
    case MaterialKind::Coated:
      scatter_coated(m, albedo, in, sp, facing_n, rng, attenuation, next);
      return above_surface(sp, next);
    case MaterialKind::Emissive:
      return false;
  }
  return false;
}

WT_HD WT_INLINE bool scatter(const Material& m, const Texture* textures, const ImageView* images, const Ray& in,
                             const SurfacePoint& sp, const Rng& rng, vec3& attenuation, Ray& next) {
  if (m.kind == MaterialKind::Emissive) return false;
  return scatter_with_albedo(m, material_albedo(m, textures, images, sp), in, sp, rng, attenuation, next);
}

}  // namespace wt

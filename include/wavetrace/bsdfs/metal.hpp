// The study's metal: the mirror direction perturbed by "fuzz" (a point uniform in a
// ball of radius fuzz added to it), tinted by the albedo; directions it sends
// below the surface are absorbed. f cos is the albedo times the density of the
// perturbed direction (metal_fuzz_pdf), so the sample's weight is the albedo.
#pragma once

#include "wavetrace/bsdfs/common.hpp"

namespace wt {

// The density per unit solid angle with which normalize(r + fuzz s), s uniform on
// the unit sphere, points along `dir` (unit), for the mirror direction
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

WT_HD WT_INLINE BsdfSample metal_sample(const BsdfAt& b, const vec3& wo, const Rng& rng) {
  const vec3 facing_n = b.facing_n();
  const vec3 r = reflect(-wo, facing_n);
  vec3 d = r;
  if (b.fuzz > 0.0f) {
    d = d + b.fuzz * unit_sphere_point(rng.uniform(kDimFuzzA), rng.uniform(kDimFuzzB));
    const float len2 = glm::dot(d, d);
    if (len2 < 1e-12f || glm::dot(d, facing_n) <= 0.0f) return no_sample();
    d *= 1.0f / sqrtf(len2);
  }
  if (!b.same_side(d)) return no_sample();
  if (b.fuzz > 0.0f) return BsdfSample{d, b.albedo, metal_fuzz_pdf(r, b.fuzz, d), kLobeGlossy | kLobeReflection};
  return BsdfSample{d, b.albedo, 0.0f, kLobeSpecular | kLobeReflection};
}

WT_HD WT_INLINE float metal_pdf(const BsdfAt& b, const vec3& wo, const vec3& wi) {
  const vec3 facing_n = b.facing_n();
  if (!(b.fuzz > 0.0f) || glm::dot(wi, facing_n) <= 0.0f) return 0.0f;
  return metal_fuzz_pdf(reflect(-wo, facing_n), b.fuzz, wi);
}

WT_HD WT_INLINE vec3 metal_eval(const BsdfAt& b, const vec3& wo, const vec3& wi) {
  return b.albedo * metal_pdf(b, wo, wi);
}

}  // namespace wt

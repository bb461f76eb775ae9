// The study's Lambertian: albedo / pi, two-sided, sampled by the cosine.
#pragma once

#include "wavetrace/bsdfs/common.hpp"

namespace wt {

WT_HD WT_INLINE BsdfSample lambertian_sample(const BsdfAt& b, const vec3& /*wo*/, const Rng& rng) {
  const vec3 facing_n = b.facing_n();
  const vec3 wi = cosine_direction(facing_n, rng.uniform(kDimScatterA), rng.uniform(kDimScatterB));
  if (!b.same_side(wi)) return no_sample();
  return BsdfSample{wi, b.albedo, fmaxf(glm::dot(wi, facing_n), 0.0f) * (1.0f / kPi), kLobeDiffuse | kLobeReflection};
}

WT_HD WT_INLINE float lambertian_pdf(const BsdfAt& b, const vec3& /*wo*/, const vec3& wi) {
  return fmaxf(glm::dot(wi, b.facing_n()), 0.0f) * (1.0f / kPi);
}

WT_HD WT_INLINE vec3 lambertian_eval(const BsdfAt& b, const vec3& wo, const vec3& wi) {
  return b.albedo * lambertian_pdf(b, wo, wi);
}

}  // namespace wt

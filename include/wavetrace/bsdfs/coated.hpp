// The study's coat: a clear smooth coat over a Lambertian base. From the front the
// coat reflects with Schlick's probability F and the base takes the rest, so f cos
// is the base's albedo (1 - F) cos / pi besides the coat's mirror; from the back
// there is no coat.
#pragma once

#include "wavetrace/bsdfs/common.hpp"

namespace wt {

// Schlick's reflectance of the coat for wo (0 from the back).
WT_HD WT_INLINE float coat_reflectance(const BsdfAt& b, const vec3& wo) {
  return b.front ? schlick(fminf(glm::dot(wo, b.facing_n()), 1.0f), 1.0f / b.ior) : 0.0f;
}

WT_HD WT_INLINE BsdfSample coated_sample(const BsdfAt& b, const vec3& wo, const Rng& rng) {
  const vec3 facing_n = b.facing_n();
  const float coat = coat_reflectance(b, wo);
  vec3 wi;
  if (b.front && rng.uniform(kDimLayer) < coat) {
    wi = reflect(-wo, facing_n);
    if (!b.same_side(wi)) return no_sample();
    return BsdfSample{wi, vec3(1.0f), 0.0f, kLobeSpecular | kLobeReflection};
  }
  wi = cosine_direction(facing_n, rng.uniform(kDimScatterA), rng.uniform(kDimScatterB));
  if (!b.same_side(wi)) return no_sample();
  return BsdfSample{wi, b.albedo, (1.0f - coat) * fmaxf(glm::dot(wi, facing_n), 0.0f) * (1.0f / kPi),
                    kLobeDiffuse | kLobeReflection};
}

WT_HD WT_INLINE float coated_pdf(const BsdfAt& b, const vec3& wo, const vec3& wi) {
  return (1.0f - coat_reflectance(b, wo)) * fmaxf(glm::dot(wi, b.facing_n()), 0.0f) * (1.0f / kPi);
}

WT_HD WT_INLINE vec3 coated_eval(const BsdfAt& b, const vec3& wo, const vec3& wi) {
  return b.albedo * coated_pdf(b, wo, wi);
}

}  // namespace wt

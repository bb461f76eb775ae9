// The study's dielectric: a smooth interface that reflects with Schlick's
// probability (always under total internal reflection) and refracts otherwise,
// tinted by the albedo either way. Specular only: nothing to evaluate.
#pragma once

#include "wavetrace/bsdfs/common.hpp"

namespace wt {

WT_HD WT_INLINE BsdfSample dielectric_sample(const BsdfAt& b, const vec3& wo, const Rng& rng) {
  const vec3 facing_n = b.facing_n();
  const vec3 in = -wo;
  const float eta = b.front ? 1.0f / b.ior : b.ior;
  const float cos_i = fminf(-glm::dot(in, facing_n), 1.0f);
  vec3 d;
  uint32_t lobe = kLobeSpecular | kLobeTransmission;
  if (!refract(in, facing_n, eta, d) || rng.uniform(kDimLayer) < schlick(cos_i, eta)) {
    d = reflect(in, facing_n);
    lobe = kLobeSpecular | kLobeReflection;
  }
  return BsdfSample{glm::normalize(d), b.albedo, 0.0f, lobe};
}

}  // namespace wt

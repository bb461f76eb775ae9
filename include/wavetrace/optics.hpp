// Reflection, refraction and Fresnel: the analytic pieces the materials build on.
#pragma once

#include "wavetrace/config.hpp"

namespace wt {

WT_HD WT_INLINE vec3 reflect(const vec3& d, const vec3& n) { return d - 2.0f * glm::dot(d, n) * n; }

// Snell refraction of unit d through unit n (n against d); eta = n_incident / n_transmitted.
// Returns false on total internal reflection.
WT_HD WT_INLINE bool refract(const vec3& d, const vec3& n, float eta, vec3& out) {
  float cos_i = fminf(-glm::dot(d, n), 1.0f);
  float sin2_t = eta * eta * fmaxf(0.0f, 1.0f - cos_i * cos_i);
  if (sin2_t > 1.0f) return false;
  float cos_t = sqrtf(1.0f - sin2_t);
  out = eta * d + (eta * cos_i - cos_t) * n;
  return true;
}

// Schlick's approximation of the Fresnel reflectance for a ray meeting an interface
// at cos_i, with eta = n_incident / n_transmitted.
WT_HD WT_INLINE float schlick(float cos_i, float eta) {
  float r0 = (1.0f - eta) / (1.0f + eta);
  r0 = r0 * r0;
  float m = 1.0f - cos_i;
  float m2 = m * m;
  return r0 + (1.0f - r0) * m2 * m2 * m;
}

}  // namespace wt

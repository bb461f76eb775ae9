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

// The exact Fresnel reflectance of unpolarised light meeting a dielectric interface
// at cos_i (>= 0, on the incident side), with eta = n_transmitted / n_incident: the
// mean of the s and p reflectances. 1 under total internal reflection.
WT_HD WT_INLINE float fresnel_dielectric(float cos_i, float eta) {
  cos_i = fminf(fmaxf(cos_i, 0.0f), 1.0f);
  const float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return 1.0f;
  const float cos_t = sqrtf(1.0f - sin2_t);
  const float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5f * (rs * rs + rp * rp);
}

// The cosine of the refracted direction for fresnel_dielectric's arguments (0 under
// total internal reflection).
WT_HD WT_INLINE float refracted_cos(float cos_i, float eta) {
  const float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
  return sin2_t >= 1.0f ? 0.0f : sqrtf(1.0f - sin2_t);
}

// The Fresnel reflectance of a conductor of complex index eta + i k (relative to
// the outside) for unpolarised light at cos_i, one channel: the s and p amplitudes
// written with a^2 + b^2 = |n^2 - sin^2|, a = Re sqrt(n^2 - sin^2).
WT_HD WT_INLINE float fresnel_conductor(float cos_i, float eta, float k) {
  cos_i = fminf(fmaxf(cos_i, 0.0f), 1.0f);
  const float c2 = cos_i * cos_i, s2 = 1.0f - c2;
  const float t0 = eta * eta - k * k - s2;
  const float ab2 = sqrtf(fmaxf(t0 * t0 + 4.0f * eta * eta * k * k, 0.0f));
  const float a = sqrtf(fmaxf(0.5f * (ab2 + t0), 0.0f));
  const float t1 = ab2 + c2, t2 = 2.0f * cos_i * a;
  const float rs = (t1 - t2) / fmaxf(t1 + t2, 1e-30f);
  const float t3 = c2 * ab2 + s2 * s2, t4 = t2 * s2;
  const float rp = rs * (t3 - t4) / fmaxf(t3 + t4, 1e-30f);
  return 0.5f * (rs + rp);
}

WT_HD WT_INLINE vec3 fresnel_conductor(float cos_i, const vec3& eta, const vec3& k) {
  return vec3(fresnel_conductor(cos_i, eta.x, k.x), fresnel_conductor(cos_i, eta.y, k.y),
              fresnel_conductor(cos_i, eta.z, k.z));
}

// Schlick's approximation with the reflectance f0 at normal incidence.
WT_HD WT_INLINE vec3 schlick_f0(float cos_i, const vec3& f0) {
  const float m = 1.0f - fminf(fmaxf(cos_i, 0.0f), 1.0f);
  const float m2 = m * m;
  return f0 + (vec3(1.0f) - f0) * (m2 * m2 * m);
}

}  // namespace wt

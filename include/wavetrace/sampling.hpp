// Direction sampling shared by the materials.
#pragma once

#include "wavetrace/config.hpp"

namespace wt {

// Uniform point on the unit sphere from two uniforms (an area-preserving map).
WT_HD WT_INLINE vec3 unit_sphere_point(float u1, float u2) {
  float z = 1.0f - 2.0f * u1;
  float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
  float phi = 2.0f * kPi * u2;
  return vec3(r * cosf(phi), r * sinf(phi), z);
}

// Uniform point in the unit disk (polar map; area-preserving).
WT_HD WT_INLINE vec2 unit_disk_point(float u1, float u2) {
  float r = sqrtf(u1);
  float phi = 2.0f * kPi * u2;
  return vec2(r * cosf(phi), r * sinf(phi));
}

// normal + a uniform unit vector is distributed as cos(theta) / pi about the normal.
// The sum vanishes only on a set of measure zero; then the normal itself is used.
WT_HD WT_INLINE vec3 cosine_direction(const vec3& normal, float u1, float u2) {
  vec3 d = normal + unit_sphere_point(u1, u2);
  float len2 = glm::dot(d, d);
  if (len2 < 1e-12f) return normal;
  return d * (1.0f / sqrtf(len2));
}

}  // namespace wt

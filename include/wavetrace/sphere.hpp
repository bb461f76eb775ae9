// Ray-sphere intersection, robust for rays that start inside a sphere, for grazing
// rays and for spheres far larger than the distances between them (the ground).
#pragma once

#include "wavetrace/ray.hpp"

namespace wt {

// The nearest root of |o + t d - c|^2 = r^2 in (tmin, tmax), for unit d.
// The discriminant is formed from the perpendicular distance of the centre to the
// ray rather than from b^2 - c, which cancels catastrophically when the ray starts
// far from a small sphere; the roots use the form that avoids subtracting nearly
// equal numbers.
WT_HD WT_INLINE bool intersect_sphere(const Ray& ray, const vec3& center, float radius, float tmin,
                                      float tmax, float& t_out) {
  vec3 f = ray.origin - center;
  float b = -glm::dot(f, ray.dir);  // the ray parameter of the point closest to the centre
  vec3 closest = f + b * ray.dir;
  float r2 = radius * radius;
  float disc = r2 - glm::dot(closest, closest);
  if (disc < 0.0f) return false;
  float c = glm::dot(f, f) - r2;
  float q = b + copysignf(sqrtf(disc), b);
  float t0, t1;
  if (q == 0.0f) {  // the ray's origin is at the centre's closest point and on the sphere
    t0 = t1 = 0.0f;
  } else {
    t0 = c / q;
    t1 = q;
  }
  if (t0 > t1) {
    float tmp = t0;
    t0 = t1;
    t1 = tmp;
  }
  if (t0 > tmin && t0 < tmax) {
    t_out = t0;
    return true;
  }
  if (t1 > tmin && t1 < tmax) {
    t_out = t1;
    return true;
  }
  return false;
}

}  // namespace wt

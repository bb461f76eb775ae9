// The sphere primitive: its record, its intersection (robust for rays that start
// inside a sphere, for grazing rays and for spheres far larger than the distances
// between them: the ground) and its surface.
#pragma once

#include "wavetrace/geometry/surface.hpp"

namespace wt {

struct alignas(16) SphereGeom {
  float x, y, z, w;  // centre and radius
};

// A sphere hit closer than this along the ray is the surface the ray just left.
constexpr float kSphereTMin = 1e-4f;
// Secondary rays leave a sphere this far along the normal. Spheres keep the fixed
// offset the reference images were rendered with; triangles derive theirs from
// the hit point's error bound (triangle.hpp).
constexpr float kSphereSurfaceOffset = 1e-3f;

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

// The surface at t along `ray` (whose direction is unit: spheres are placed only
// untransformed).
WT_HD WT_INLINE SurfacePoint sphere_surface(const SphereGeom& s, const Ray& ray, float t) {
  SurfacePoint sp;
  sp.p = ray.at(t);
  sp.local = sp.p - vec3(s.x, s.y, s.z);
  sp.n = sp.local * (1.0f / s.w);
  sp.ng = sp.n;
  sp.uv = vec2(0.0f);
  sp.dpdu = vec3(-sp.local.z, 0.0f, sp.local.x);
  sp.tangent_sign = -1.0f;  // u runs clockwise seen from outside; v = 0 is the north pole
  sp.has_uv = false;
  sp.front = glm::dot(ray.dir, sp.n) < 0.0f;
  sp.offset = kSphereSurfaceOffset;
  return sp;
}

}  // namespace wt

// What shading needs to know about a hit, whatever the primitive, and how a
// secondary ray leaves the surface without hitting it again.
#pragma once

#include "wavetrace/ray.hpp"

namespace wt {

struct SurfacePoint {
  vec3 p;       // world position
  vec3 n;       // unit shading normal, on the outward side
  vec3 ng;      // unit geometric normal, outward
  vec3 local;   // object-space position (procedural textures): relative to a sphere's centre
  vec2 uv;      // texture coordinates (triangles); spheres map theirs from n (texture.hpp)
  vec3 dpdu;    // the direction of increasing u (not unit; anisotropy's tangent): a
                // sphere's azimuth, a triangle's from its UVs (its first edge without them)
  float tangent_sign;  // +-1: the bitangent cross(n, dpdu) times this points up the image
                       // (towards decreasing v), as a tangent-space normal map's +y
  // Texture filtering (texture.hpp's mip-mapped lookups): UV units per unit length
  // on the surface (isotropic: the square root of UV area over world area; triangles
  // with UVs, 0 elsewhere: a sphere's follows from its normal), and the width of the
  // pixel's footprint on the surface in world units (0: none, the finest level).
  float uv_density = 0.0f;
  float footprint = 0.0f;
  bool has_uv;  // false: spheres
  bool front;   // the ray arrived from the outward side
  float offset;  // how far a secondary ray starts from p along ng: covers p's rounding error
};

// Floating-point rounding bound gamma(n) = n u / (1 - n u), u = 2^-24: the relative
// error of n rounded operations.
WT_HD WT_INLINE constexpr float rounding_gamma(int n) {
  return (n * 5.9604645e-8f) / (1.0f - n * 5.9604645e-8f);
}

// A ray from the hit along `dir`, started `offset` along the geometric normal on the
// side `dir` goes to, so that it cannot hit the surface it leaves.
WT_HD WT_INLINE Ray spawn_ray(const SurfacePoint& sp, const vec3& dir) {
  float side = glm::dot(dir, sp.ng) >= 0.0f ? 1.0f : -1.0f;
  return Ray{sp.p + (side * sp.offset) * sp.ng, dir};
}

}  // namespace wt

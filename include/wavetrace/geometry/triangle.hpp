// The triangle primitive: its records, a watertight intersection and its surface
// with the error bound that places secondary rays.
//
// The intersection transforms the triangle into a space where the ray runs along
// +z from the origin (a translation, a permutation of the axes that makes z the
// ray's dominant one, and a shear), then decides coverage from the signs of three
// edge functions. Edges shared by two triangles get the same edge function with
// opposite sign, so a ray through a shared edge or vertex hits at least one of
// them: no cracks. An edge function that rounds to exactly zero is recomputed in
// double, so a ray through an edge is not counted as on it by rounding alone.
#pragma once

#include "wavetrace/geometry/surface.hpp"

namespace wt {

// Corners, padded to 16 bytes each for aligned loads; the first pad says whether
// the triangle is alpha-tested (geometry/alpha.hpp), so that the traversal learns it
// from the record it loads anyway and opaque triangles cost one compare.
struct alignas(16) TriangleGeom {
  float p0[3];
  uint32_t alpha;  // 0: opaque; else 1 + its AlphaTest's index in the scene's alpha_tests
  float p1[3], pad1;
  float p2[3], pad2;

  WT_HD vec3 corner(int i) const {
    const float* c = i == 0 ? p0 : (i == 1 ? p1 : p2);
    return vec3(c[0], c[1], c[2]);
  }
};

// Where a triangle's shading data lives: its corners' indices into the scene's
// vertex normal and UV arrays, and which of the two it has.
struct TriangleShading {
  uint32_t vertex[3];
  uint32_t flags;
};
constexpr uint32_t kTriangleHasNormals = 1u;
constexpr uint32_t kTriangleHasUvs = 2u;
// Per-vertex tangents (scene_view.hpp's `tangents`, where the scene has normal maps):
// a vertex v has two, 2v for the faces of positive handedness and 2v + 1 for those
// of negative (kTriangleTangentFlipped), so that a UV mirror seam keeps both.
constexpr uint32_t kTriangleHasTangents = 4u;
constexpr uint32_t kTriangleTangentFlipped = 8u;

// dp/du and dp/dv over a triangle of edges e1, e2 whose UVs change by d1, d2 along
// them (det = d1.x d2.y - d1.y d2.x, non-zero): p(u, v) solved for its derivatives.
WT_HD WT_INLINE void uv_derivatives(const vec3& e1, const vec3& e2, const vec2& d1, const vec2& d2, float det,
                                    vec3& dpdu, vec3& dpdv) {
  const float inv = 1.0f / det;
  dpdu = (d2.y * e1 - d1.y * e2) * inv;
  dpdv = (d1.x * e2 - d2.x * e1) * inv;
}

// The UV map's handedness about normal n (SurfacePoint::tangent_sign): -1 where
// cross(n, dp/du) points along dp/dv (v grows down the image), else +1.
WT_HD WT_INLINE float uv_handedness(const vec3& n, const vec3& dpdu, const vec3& dpdv) {
  return glm::dot(glm::cross(n, dpdu), dpdv) > 0.0f ? -1.0f : 1.0f;
}

WT_HD WT_INLINE float component(const vec3& v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

// The per-ray part of the transformation: computed once per ray (per instance).
struct TriangleRay {
  int kx, ky, kz;  // the permutation: kz is the direction's largest component
  float sx, sy, sz;  // the shear
};

WT_HD WT_INLINE TriangleRay triangle_ray(const vec3& d) {
  TriangleRay r;
  float ax = fabsf(d.x), ay = fabsf(d.y), az = fabsf(d.z);
  r.kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
  r.kx = r.kz == 2 ? 0 : r.kz + 1;
  r.ky = r.kx == 2 ? 0 : r.kx + 1;
  float dz = component(d, r.kz);
  r.sx = -component(d, r.kx) / dz;
  r.sy = -component(d, r.ky) / dz;
  r.sz = 1.0f / dz;
  return r;
}

// a * b rounded on its own: never fused into a neighbouring add, so that an edge
// function and its negation (the same edge seen from the neighbouring triangle)
// round alike.
WT_HD WT_INLINE float product_rn(float a, float b) {
#if defined(__CUDA_ARCH__)
  return __fmul_rn(a, b);
#else
  return a * b;
#endif
}

// a.x b.y - a.y b.x of two sheared corners; exactly zero in float is rechecked in
// double, where the products are exact.
WT_HD WT_INLINE float edge_function(float ax, float ay, float bx, float by) {
  float e = product_rn(ax, by) - product_rn(ay, bx);
  if (e == 0.0f) e = static_cast<float>(static_cast<double>(ax) * by - static_cast<double>(ay) * bx);
  return e;
}

// The hit of `ray` (origin o, any non-zero direction; tr = triangle_ray(direction))
// with the triangle in (0, tmax): t, and the barycentric weights b1, b2 of corners
// 1 and 2. The lower bound is the distance the computed t may be off by, so that a
// ray leaving the triangle never hits it again.
WT_HD WT_INLINE bool intersect_triangle(const TriangleGeom& tri, const vec3& o, const TriangleRay& tr, float tmax,
                                        float& t_out, float& b1_out, float& b2_out) {
  vec3 a = tri.corner(0) - o, b = tri.corner(1) - o, c = tri.corner(2) - o;
  float az = component(a, tr.kz), bz = component(b, tr.kz), cz = component(c, tr.kz);
  // The largest unscaled z: the shear's error is in the same units as x and y.
  const float max_z_space = fmaxf(fabsf(az), fmaxf(fabsf(bz), fabsf(cz)));
  float ax = component(a, tr.kx) + tr.sx * az, ay = component(a, tr.ky) + tr.sy * az;
  float bx = component(b, tr.kx) + tr.sx * bz, by = component(b, tr.ky) + tr.sy * bz;
  float cx = component(c, tr.kx) + tr.sx * cz, cy = component(c, tr.ky) + tr.sy * cz;
  float e0 = edge_function(bx, by, cx, cy);
  float e1 = edge_function(cx, cy, ax, ay);
  float e2 = edge_function(ax, ay, bx, by);
  if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f)) return false;
  float det = e0 + e1 + e2;
  if (det == 0.0f) return false;
  az *= tr.sz;
  bz *= tr.sz;
  cz *= tr.sz;
  float t_scaled = e0 * az + e1 * bz + e2 * cz;
  if (det < 0.0f ? (t_scaled >= 0.0f || t_scaled < tmax * det) : (t_scaled <= 0.0f || t_scaled > tmax * det)) {
    return false;
  }
  float inv_det = 1.0f / det;
  float t = t_scaled * inv_det;
  // A conservative bound on t's error: the hit must lie beyond it. The sheared x and
  // y carry the error of x + s z with |s| <= 1 (z is the dominant axis), in space
  // units; the scaled z is in units of t. Mixing the two would make the bound
  // depend on the direction's length, which instances change.
  float max_z = fmaxf(fabsf(az), fmaxf(fabsf(bz), fabsf(cz)));
  float max_x = fmaxf(fabsf(ax), fmaxf(fabsf(bx), fabsf(cx)));
  float max_y = fmaxf(fabsf(ay), fmaxf(fabsf(by), fabsf(cy)));
  float delta_z = rounding_gamma(3) * max_z;
  float delta_x = rounding_gamma(5) * (max_x + max_z_space);
  float delta_y = rounding_gamma(5) * (max_y + max_z_space);
  float delta_e = 2.0f * (rounding_gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
  float max_e = fmaxf(fabsf(e0), fmaxf(fabsf(e1), fabsf(e2)));
  float delta_t =
      3.0f * (rounding_gamma(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) * fabsf(inv_det);
  if (t <= delta_t) return false;
  t_out = t;
  b1_out = e1 * inv_det;
  b2_out = e2 * inv_det;
  return true;
}

// The object-space point at barycentrics (b1, b2) and the bound on its rounding
// error, per axis.
WT_HD WT_INLINE vec3 triangle_point(const TriangleGeom& tri, float b1, float b2, vec3& error) {
  float b0 = 1.0f - b1 - b2;
  vec3 w0 = b0 * tri.corner(0), w1 = b1 * tri.corner(1), w2 = b2 * tri.corner(2);
  error = rounding_gamma(7) * (glm::abs(w0) + glm::abs(w1) + glm::abs(w2));
  return w0 + w1 + w2;
}

}  // namespace wt

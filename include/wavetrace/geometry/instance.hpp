// Instances: a group of primitives (a bottom-level BVH) placed in the world by an
// affine transform. A mesh placed many times is stored once.
#pragma once

#include "wavetrace/ray.hpp"

namespace wt {

// The rows of a 3x4 matrix: y = M (x, 1).
struct Affine {
  float m[12];

  WT_HD vec3 point(const vec3& p) const {
    return vec3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
  }
  WT_HD vec3 vector(const vec3& v) const {
    return vec3(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
                m[8] * v.x + m[9] * v.y + m[10] * v.z);
  }
  // The transpose of the linear part times v: with the inverse transform's matrix,
  // this carries normals.
  WT_HD vec3 transposed_vector(const vec3& v) const {
    return vec3(m[0] * v.x + m[4] * v.y + m[8] * v.z, m[1] * v.x + m[5] * v.y + m[9] * v.z,
                m[2] * v.x + m[6] * v.y + m[10] * v.z);
  }
  // |linear part| times v (v >= 0), and the translation's magnitude: for error bounds.
  WT_HD vec3 abs_vector(const vec3& v) const {
    return vec3(fabsf(m[0]) * v.x + fabsf(m[1]) * v.y + fabsf(m[2]) * v.z,
                fabsf(m[4]) * v.x + fabsf(m[5]) * v.y + fabsf(m[6]) * v.z,
                fabsf(m[8]) * v.x + fabsf(m[9]) * v.y + fabsf(m[10]) * v.z);
  }
  WT_HD vec3 abs_translation() const { return vec3(fabsf(m[3]), fabsf(m[7]), fabsf(m[11])); }
};

// The determinant of a transform's linear part (< 0: it mirrors).
WT_HD WT_INLINE float affine_determinant(const Affine& a) {
  const float* m = a.m;
  return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) + m[2] * (m[4] * m[9] - m[5] * m[8]);
}

constexpr Affine kIdentityTransform{{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}};

enum class PrimitiveKind : uint32_t { Sphere = 0, Triangle = 1 };

struct alignas(16) Instance {
  Affine object_from_world;
  Affine world_from_object;
  int32_t root;        // its bottom-level BVH's root in the scene's node array
  PrimitiveKind kind;  // of every primitive under root
  int32_t material;    // overrides the primitives' own materials; < 0: none
  uint32_t identity;   // non-zero: the transforms are the identity, and rays are not transformed
};

}  // namespace wt

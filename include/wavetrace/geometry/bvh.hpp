// The bounding volume hierarchy's node layout and the slab test. One node array
// holds the top level (over instances) and every bottom level (over one group of
// primitives); traverse.hpp walks both.
#pragma once

#include "wavetrace/ray.hpp"

namespace wt {

// Two 16-byte rows: the bounds, and either the first of two adjacent children
// (inner node, count == 0) or the first primitive and the primitive count (leaf).
struct alignas(16) BvhNode {
  float lo[3];
  int32_t left_or_first;
  float hi[3];
  int32_t count;
};

// The deepest the builder makes a tree. Traversal defers at most one node per
// level, and the deferred nodes' depths strictly increase down the stack, so a
// tree of depth D needs at most D stack entries; two levels and the entry that
// marks the return from an instance need twice that and one more.
constexpr int kMaxBvhDepth = 24;
constexpr int kBvhStackSize = 2 * kMaxBvhDepth + 1;

// The slab test's far distances are rounded up by this factor (1 + 2 gamma(3) of
// the three rounded operations behind each): a ray through an edge or corner that
// lies on a box's face is never culled by the box's rounding, which the watertight
// triangle test relies on.
constexpr float kSlabRoundUp = 1.0000004f;

// The reciprocal of a direction for the slab test. A zero component gives an
// infinite reciprocal; a ray with it that starts exactly in the plane of a box's
// face would make 0 * inf = NaN there and cull the box. The builder therefore
// widens every triangle's box by an ulp on each side (scene_bvh.cpp): geometry
// never lies in the plane of a face, and a ray in that plane cannot touch it.
WT_HD WT_INLINE vec3 slab_inverse(const vec3& d) { return vec3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z); }

// Slab test; returns the entry distance or a value > tmax when the box is missed.
// RoundUp: widen the far side for rounding (needed for triangles; the spheres'
// boxes are padded instead).
template <bool RoundUp = true>
WT_HD WT_INLINE float box_entry(const BvhNode& n, const vec3& o, const vec3& inv, float tmax) {
  constexpr float up = RoundUp ? kSlabRoundUp : 1.0f;
  float tx0 = (n.lo[0] - o.x) * inv.x, tx1 = (n.hi[0] - o.x) * inv.x;
  float ty0 = (n.lo[1] - o.y) * inv.y, ty1 = (n.hi[1] - o.y) * inv.y;
  float tz0 = (n.lo[2] - o.z) * inv.z, tz1 = (n.hi[2] - o.z) * inv.z;
  float tnear = fmaxf(fmaxf(fminf(tx0, tx1), fminf(ty0, ty1)), fmaxf(fminf(tz0, tz1), 0.0f));
  float tfar = fminf(fminf(fmaxf(tx0, tx1), fmaxf(ty0, ty1)) * up, fminf(fmaxf(tz0, tz1) * up, tmax));
  return tnear <= tfar ? tnear : tmax * 2.0f + 1.0f;
}

}  // namespace wt

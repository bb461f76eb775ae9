// The bounding volume hierarchy's node layout and the slab test. One node array
// holds the top level (over instances) and every bottom level (over one group of
// primitives); geometry.hpp walks both.
//
// Nodes are 8-wide with compressed child boxes (WideBvhNode): a ray visits about a
// third as many nodes as in a binary tree of the same leaves, and a node is three
// 32-byte memory sectors. The host builds a binary SAH tree and collapses it into
// this layout (src/scene/bvh_build.hpp).
#pragma once

#include "wavetrace/ray.hpp"

namespace wt {

constexpr int kBvhWidth = 8;

// A child reference: >= 0 is an inner node's index in the node array; < 0 is a leaf,
// `count` primitives (1 to kMaxLeafCount) from `first` (below kMaxLeafFirst).
constexpr int kLeafCountBits = 4;
constexpr int kLeafFirstBits = 31 - kLeafCountBits;
constexpr int kMaxLeafCount = 1 << kLeafCountBits;
constexpr int32_t kMaxLeafFirst = int32_t(1) << kLeafFirstBits;

WT_HD WT_INLINE constexpr int32_t leaf_ref(int32_t first, int count) {
  return static_cast<int32_t>(0x80000000u | (static_cast<uint32_t>(count - 1) << kLeafFirstBits) |
                              static_cast<uint32_t>(first));
}
WT_HD WT_INLINE constexpr bool is_leaf(int32_t ref) { return ref < 0; }
WT_HD WT_INLINE constexpr int32_t leaf_first(int32_t ref) { return ref & (kMaxLeafFirst - 1); }
WT_HD WT_INLINE constexpr int leaf_count(int32_t ref) {
  return static_cast<int>((static_cast<uint32_t>(ref) >> kLeafFirstBits) & (kMaxLeafCount - 1)) + 1;
}

// Up to eight children. Their boxes are stored on a grid of the node's own: on axis
// k, child s spans origin[k] + lo * 2^e[k] to origin[k] + hi * 2^e[k], where lo and
// hi are 8-bit grid values (grid_lo, grid_hi). The builder rounds the grid outward,
// so a decoded box contains the child's exact box, and checks it with the same
// arithmetic as child_box: the product is exact (an 8-bit integer times a power of
// two), and the one rounding of the sum is the same on every backend.
//
// Every field is a 32-bit word, so that a node loaded into registers stays there:
// the grid values are packed four to a word, slots 0-3 and 4-7 of axis k in words
// 2k and 2k + 1.
struct alignas(32) WideBvhNode {
  float origin[3];
  uint32_t meta;  // bytes 0-2: each axis's grid exponent, biased by 127; byte 3: the child count
  uint32_t lo[6];
  uint32_t hi[6];
  int32_t child[kBvhWidth];  // slots 0 .. child_count - 1 in use

  WT_HD int child_count() const { return static_cast<int>(meta >> 24); }
  WT_HD uint32_t exponent(int axis) const { return (meta >> (8 * axis)) & 255u; }
  WT_HD uint32_t grid_lo(int axis, int slot) const { return (lo[2 * axis + (slot >> 2)] >> (8 * (slot & 3))) & 255u; }
  WT_HD uint32_t grid_hi(int axis, int slot) const { return (hi[2 * axis + (slot >> 2)] >> (8 * (slot & 3))) & 255u; }
};
static_assert(sizeof(WideBvhNode) == 96, "a node is three 32-byte sectors");

// 2^(e - 127) for a biased exponent e in 1 .. 254.
WT_HD WT_INLINE float grid_step(uint32_t e) {
#ifdef __CUDA_ARCH__
  return __int_as_float(static_cast<int>(e << 23));
#else
  const uint32_t bits = e << 23;
  float f;
  __builtin_memcpy(&f, &bits, sizeof f);
  return f;
#endif
}

// A child's decoded box.
WT_HD WT_INLINE void child_box(const WideBvhNode& n, int slot, vec3& lo, vec3& hi) {
  const vec3 step(grid_step(n.exponent(0)), grid_step(n.exponent(1)), grid_step(n.exponent(2)));
  lo = vec3(n.origin[0] + static_cast<float>(n.grid_lo(0, slot)) * step.x,
            n.origin[1] + static_cast<float>(n.grid_lo(1, slot)) * step.y,
            n.origin[2] + static_cast<float>(n.grid_lo(2, slot)) * step.z);
  hi = vec3(n.origin[0] + static_cast<float>(n.grid_hi(0, slot)) * step.x,
            n.origin[1] + static_cast<float>(n.grid_hi(1, slot)) * step.y,
            n.origin[2] + static_cast<float>(n.grid_hi(2, slot)) * step.z);
}

// The child in `slot` when slot is only known at run time: a choice among registers
// rather than an index into them (which would put the node in local memory).
WT_HD WT_INLINE int32_t child_in_slot(const WideBvhNode& n, int slot) {
  int32_t ref = n.child[0];
  WT_UNROLL
  for (int s = 1; s < kBvhWidth; ++s) ref = slot == s ? n.child[s] : ref;
  return ref;
}

// The deepest the builder makes a tree. Traversal defers at most one entry per
// level (a node and the order of its children still to visit), so a tree of depth D
// needs at most D stack entries; two levels and the entry that marks the return
// from an instance need twice that and one more.
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
WT_HD WT_INLINE float box_entry(const vec3& lo, const vec3& hi, const vec3& o, const vec3& inv, float tmax) {
  constexpr float up = RoundUp ? kSlabRoundUp : 1.0f;
  float tx0 = (lo.x - o.x) * inv.x, tx1 = (hi.x - o.x) * inv.x;
  float ty0 = (lo.y - o.y) * inv.y, ty1 = (hi.y - o.y) * inv.y;
  float tz0 = (lo.z - o.z) * inv.z, tz1 = (hi.z - o.z) * inv.z;
  float tnear = fmaxf(fmaxf(fminf(tx0, tx1), fminf(ty0, ty1)), fmaxf(fminf(tz0, tz1), 0.0f));
  float tfar = fminf(fminf(fmaxf(tx0, tx1), fmaxf(ty0, ty1)) * up, fminf(fmaxf(tz0, tz1) * up, tmax));
  return tnear <= tfar ? tnear : tmax * 2.0f + 1.0f;
}

}  // namespace wt

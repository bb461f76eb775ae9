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

// The node width: 8, or 4 where WAVETRACE_BVH_WIDTH says so (a build option, for
// measuring the two against each other).
#ifndef WAVETRACE_BVH_WIDTH
#define WAVETRACE_BVH_WIDTH 8
#endif
constexpr int kBvhWidth = WAVETRACE_BVH_WIDTH;
static_assert(kBvhWidth == 4 || kBvhWidth == 8, "the node width is 4 or 8");
constexpr int kGridWords = kBvhWidth / 4;  // packed grid values per axis and side

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
// k, child s spans origin[k] + lo * 2^e[k] to origin[k] + hi * 2^e[k] (exactly,
// in real numbers), where lo and hi are 8-bit grid values (grid_lo, grid_hi). The
// builder rounds the grid outward, so that box contains the child's exact box.
//
// Every field is a 32-bit word, so that a node loaded into registers stays there:
// the grid values are packed four to a word, slots 0-3 and 4-7 of axis k in words
// 2k and 2k + 1.
struct alignas(32) WideBvhNode {
  float origin[3];
  uint32_t meta;  // bytes 0-2: each axis's grid exponent, biased by 127; byte 3: the child count
  uint32_t lo[3 * kGridWords];
  uint32_t hi[3 * kGridWords];
  int32_t child[kBvhWidth];  // slots 0 .. child_count - 1 in use

  WT_HD int child_count() const { return static_cast<int>(meta >> 24); }
  WT_HD uint32_t exponent(int axis) const { return (meta >> (8 * axis)) & 255u; }
  WT_HD uint32_t grid_lo(int axis, int slot) const { return (lo[kGridWords * axis + (slot >> 2)] >> (8 * (slot & 3))) & 255u; }
  WT_HD uint32_t grid_hi(int axis, int slot) const { return (hi[kGridWords * axis + (slot >> 2)] >> (8 * (slot & 3))) & 255u; }
};
static_assert(sizeof(WideBvhNode) == (kBvhWidth == 8 ? 96 : 64), "a node is three (two) 32-byte sectors");

WT_HD WT_INLINE float bits_float(uint32_t bits) {
#ifdef __CUDA_ARCH__
  return __uint_as_float(bits);
#else
  float f;
  __builtin_memcpy(&f, &bits, sizeof f);
  return f;
#endif
}

WT_HD WT_INLINE uint32_t float_bits(float f) {
#ifdef __CUDA_ARCH__
  return __float_as_uint(f);
#else
  uint32_t bits;
  __builtin_memcpy(&bits, &f, sizeof bits);
  return bits;
#endif
}

// 2^(e - 127) for a biased exponent e in 1 .. 254.
WT_HD WT_INLINE float grid_step(uint32_t e) { return bits_float(e << 23); }

// Grid value `byte` (0-3) of a packed word, as a float: on the GPU one byte
// permute into the bits of 2^23 + value and one exact subtraction, both full-rate
// (an integer-to-float conversion is not).
WT_HD WT_INLINE float grid_value(uint32_t word, int byte) {
#ifdef __CUDA_ARCH__
  return __uint_as_float(__byte_perm(word, 0x4B000000u, 0x7440u | static_cast<uint32_t>(byte))) - 8388608.0f;
#else
  return static_cast<float>((word >> (8 * byte)) & 255u);
#endif
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

// The relative widening of every slab, which makes the slab test conservative:
// a child's entry and exit distances on an axis are computed as q * a + b from
// per-node terms (a = step / d, b = (origin - o) / d, each rounded), which differ
// from the exact distances to the exact grid box by at most about 6 roundings of
// M = (255 step + |origin - o|) / |d|, the largest term. Every slab is widened by
// 16 such roundings of M on each side (1e-6 M), so no box is culled that the ray
// touches in exact arithmetic: a ray through a triangle's edge or corner on a box
// face reaches the triangle test, which the watertight test relies on.
constexpr float kSlabWidening = 1.0e-6f;

// The reciprocal of a direction for the slab test. A zero component gives an
// infinite reciprocal, and 0 * inf = NaN where the ray starts in the plane of a
// grid line; the min and max below drop a NaN, which leaves that axis unbounded:
// the box is kept, never culled by it.
WT_HD WT_INLINE vec3 slab_inverse(const vec3& d) { return vec3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z); }

}  // namespace wt

// A blend of two materials (MaterialKind::Blend): the mixture (1 - w) f_a + w f_b
// of their BSDFs, rendered by picking one of the two at each hit, the second with
// probability w, and shading the hit with it alone. The pick is made before the hit
// is shaded, so a hit is sorted and shaded as its picked material's (its sort key,
// its code), and the picked material's light sampling, BSDF sampling and MIS
// weights all belong to one BSDF. The estimate is unbiased: averaged over the pick,
// each path vertex's contribution is the mixture's, because a path's contribution
// is linear in the BSDF of each vertex.
//
// The pick needs a uniform number that intersect (for the sort key) and shade (for
// the material) draw alike without sharing state: it is hashed from the ray and the
// hit, as alpha testing's is (geometry/alpha.hpp), with a salt of its own so that
// the two decisions on one ray are independent, and the blend's level, so that a
// blend within a blend picks independently too.
#pragma once

#include "wavetrace/geometry/alpha.hpp"
#include "wavetrace/ray.hpp"

namespace wt {

// A blend may hold blends, this many deep (the scene reader refuses deeper ones).
constexpr int kMaxBlendDepth = 4;

// A number in [0, 1) for the pick of the blend at `level` (0: the hit's own
// material) at `hit` along `ray`: the same ray and hit always give the same number;
// different rays, independent ones.
WT_HD WT_INLINE float blend_uniform(const Ray& ray, const Hit& hit, int level) {
  uint32_t h = hash_u32(float_bits(ray.origin.x) ^ 0xbb67ae85u);
  h = hash_u32(h ^ float_bits(ray.origin.y));
  h = hash_u32(h ^ float_bits(ray.origin.z));
  h = hash_u32(h ^ float_bits(ray.dir.x));
  h = hash_u32(h ^ float_bits(ray.dir.y));
  h = hash_u32(h ^ float_bits(ray.dir.z));
  h = hash_u32(h ^ float_bits(hit.t));
  h = hash_u32(h ^ static_cast<uint32_t>(hit.prim));
  h = hash_u32(h ^ static_cast<uint32_t>(hit.instance) ^ (static_cast<uint32_t>(level) << 24));
  return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}

// Whether a blend of weight w takes its second material for the number u in [0, 1):
// with probability w (never for w = 0, always for w = 1).
WT_HD WT_INLINE bool blend_takes_second(float weight, float u) {
  if (WT_MUTANT(BlendWeightSwapped)) weight = 1.0f - weight;
  return u < weight;
}

}  // namespace wt

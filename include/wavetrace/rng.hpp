// Counter-based random numbers: every number is a pure function of
// (seed, pixel, sample, bounce, dimension), so any backend and any kernel that
// traces the same path draws the same numbers, whatever order it runs in.
#pragma once

#include "wavetrace/config.hpp"

namespace wt {

// A 32-bit integer hash with low bias (a bijection on uint32).
WT_HD WT_INLINE uint32_t hash_u32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// The dimensions a path consumes at one bounce. Keeping them named keeps two
// decisions from ever sharing a number.
enum RngDim : uint32_t {
  kDimPixelX = 0,
  kDimPixelY = 1,
  kDimLensX = 2,
  kDimLensY = 3,
  kDimScatterA = 4,
  kDimScatterB = 5,
  kDimFuzzA = 6,
  kDimFuzzB = 7,
  kDimLayer = 8,
  kDimRoulette = 9,
  kDimLightPick = 10,
  kDimLightA = 11,
  kDimLightB = 12,
  kDimLobe = 13,  // a mixture's choice of component (a metallic plastic's metal)
};

// Random numbers for one (seed, pixel, sample, bounce): `uniform(dim)` is in [0, 1).
struct Rng {
  uint32_t key;

  WT_HD static Rng at(uint32_t seed, uint32_t pixel, uint32_t sample, uint32_t bounce) {
    uint32_t h = hash_u32(seed ^ 0x9e3779b9u);
    h = hash_u32(h ^ pixel);
    h = hash_u32(h ^ sample);
    h = hash_u32(h ^ bounce);
    return Rng{h};
  }

  WT_HD uint32_t bits(uint32_t dim) const { return hash_u32(key ^ hash_u32(dim + 0x68bc21ebu)); }

  // 24 random bits scaled into [0, 1): exactly representable, never 1.
  WT_HD float uniform(uint32_t dim) const {
    return static_cast<float>(bits(dim) >> 8) * (1.0f / 16777216.0f);
  }
};

}  // namespace wt

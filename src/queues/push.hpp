// Pushing into a queue from many threads, the same call on both backends.
#pragma once

#include <cstdint>

#include "wavetrace/config.hpp"

namespace wt {

// Those callers with `want` get distinct, consecutive slots from *count. On the GPU
// every thread of the warp that reaches this call takes part, and the warp's leader
// reserves the warp's slots with one atomic; on host threads each push is one atomic.
WT_HD WT_INLINE uint32_t push_slot(uint32_t* count, bool want) {
#if defined(__CUDA_ARCH__)
  const unsigned active = __activemask();
  const unsigned wanting = __ballot_sync(active, want);
  if (!wanting) return 0;
  const int lane = threadIdx.x & 31;
  const int leader = __ffs(wanting) - 1;
  uint32_t base = 0;
  if (lane == leader) base = atomicAdd(count, static_cast<uint32_t>(__popc(wanting)));
  base = __shfl_sync(active, base, leader);
  return base + __popc(wanting & ((1u << lane) - 1u));
#else
  return want ? __atomic_fetch_add(count, 1u, __ATOMIC_RELAXED) : 0;
#endif
}

// Sets `bits` in *mask, from many threads. On the GPU the warp's bits are gathered
// first, and its leader writes only those *mask lacks (most warps, once the common
// keys are in, write nothing); on host threads one atomic OR.
WT_HD WT_INLINE void or_bits(uint32_t* mask, uint32_t bits) {
#if defined(__CUDA_ARCH__)
  const unsigned active = __activemask();
  const uint32_t warp_bits = __reduce_or_sync(active, bits);
  if ((threadIdx.x & 31) == static_cast<unsigned>(__ffs(active) - 1) && (warp_bits & ~*mask) != 0) {
    atomicOr(mask, warp_bits);
  }
#else
  if (bits) __atomic_fetch_or(mask, bits, __ATOMIC_RELAXED);
#endif
}

}  // namespace wt

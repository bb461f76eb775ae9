// Pushing into a queue from many threads: one atomic per warp, not per item.
#pragma once

#include <cstdint>

namespace wt::cuda {

// Every thread of the warp that reaches this call takes part; those with `want`
// get consecutive slots from *count, reserved by one atomic of the warp's leader.
__device__ __forceinline__ uint32_t push_slot(uint32_t* count, bool want) {
  const unsigned active = __activemask();
  const unsigned wanting = __ballot_sync(active, want);
  if (!wanting) return 0;
  const int lane = threadIdx.x & 31;
  const int leader = __ffs(wanting) - 1;
  uint32_t base = 0;
  if (lane == leader) base = atomicAdd(count, static_cast<uint32_t>(__popc(wanting)));
  base = __shfl_sync(active, base, leader);
  return base + __popc(wanting & ((1u << lane) - 1u));
}

}  // namespace wt::cuda

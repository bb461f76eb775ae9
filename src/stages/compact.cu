#include <cub/device/device_select.cuh>

#include "stages/stages.hpp"

namespace wt::cuda {

namespace {
struct HitSomething {
  __host__ __device__ bool operator()(uint32_t entry) const { return entry_key(entry) != kSortKeyMiss; }
};
}  // namespace

size_t compact_temp_bytes(size_t capacity) {
  size_t bytes = 0;
  WT_CUDA(cub::DeviceSelect::If(nullptr, bytes, static_cast<const uint32_t*>(nullptr), static_cast<uint32_t*>(nullptr),
                                static_cast<uint32_t*>(nullptr), static_cast<int64_t>(capacity), HitSomething{}),
          "compact");
  return bytes;
}

void compact_entries(const WaveMemory& wave, cudaStream_t stream) {
  size_t bytes = wave.temp_bytes();
  WT_CUDA(cub::DeviceSelect::If(wave.temp(), bytes, wave.entries(), wave.selected(), &wave.counters()->hits,
                                static_cast<int64_t>(wave.capacity()), HitSomething{}, stream),
          "compact");
}

}  // namespace wt::cuda

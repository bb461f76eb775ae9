#include <cub/device/device_radix_sort.cuh>

#include "stages/stages.hpp"

namespace wt::cuda {

size_t sort_temp_bytes(size_t capacity) {
  size_t bytes = 0;
  WT_CUDA(cub::DeviceRadixSort::SortKeys(nullptr, bytes, static_cast<const uint32_t*>(nullptr),
                                         static_cast<uint32_t*>(nullptr), static_cast<int64_t>(capacity), kSlotBits,
                                         32),
          "sort");
  return bytes;
}

void sort_entries(const WaveMemory& wave, uint32_t count, int key_bits, cudaStream_t stream) {
  size_t bytes = wave.temp_bytes();
  // Only the key bits take part: fewer radix passes, and slots keep their order within a key.
  WT_CUDA(cub::DeviceRadixSort::SortKeys(wave.temp(), bytes, wave.selected(), wave.sorted(),
                                         static_cast<int64_t>(count), kSlotBits, kSlotBits + key_bits, stream),
          "sort");
}

}  // namespace wt::cuda

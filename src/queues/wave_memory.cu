#include "queues/wave_memory.hpp"

#include <algorithm>

#include "stages/stages.hpp"

namespace wt::cuda {

namespace {
constexpr const char* kStage = "wave allocation";
constexpr size_t kEntryArrays = 3;  // entries, selected, sorted
}  // namespace

size_t WaveMemory::bytes_for(size_t capacity) {
  return capacity * (2 * PathQueue::kBytesPerSlot + sizeof(float) + sizeof(int32_t) + kEntryArrays * sizeof(uint32_t)) +
         std::max(compact_temp_bytes(capacity), sort_temp_bytes(capacity)) + sizeof(WaveCounters);
}

WaveMemory::WaveMemory(size_t capacity) : capacity_(capacity) {
  for (int q = 0; q < 2; ++q) {
    queue_memory_[q].allocate(capacity * PathQueue::kBytesPerSlot, kStage);
    queues_[q] = PathQueue::over(queue_memory_[q].get(), capacity);
  }
  hit_t_.allocate(capacity, kStage);
  hit_sphere_.allocate(capacity, kStage);
  entries_.allocate(capacity, kStage);
  selected_.allocate(capacity, kStage);
  sorted_.allocate(capacity, kStage);
  counters_.allocate(1, kStage);
  temp_.allocate(std::max(compact_temp_bytes(capacity), sort_temp_bytes(capacity)), kStage);
}

}  // namespace wt::cuda

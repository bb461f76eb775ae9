// The device memory of one wave: two path queues (the bounce being traced and the
// next), the hit records, the sort entries and the counters.
#pragma once

#include <cstddef>

#include "cuda/buffer.hpp"
#include "stages/stage_items.hpp"

namespace wt::cuda {

class WaveMemory {
 public:
  explicit WaveMemory(size_t capacity);

  // Device bytes a wave of `capacity` slots takes, temporary storage included.
  static size_t bytes_for(size_t capacity);

  size_t capacity() const { return capacity_; }
  const PathQueue& queue(int which) const { return queues_[which]; }
  HitQueue hits() const { return HitQueue{hit_t_.get(), hit_sphere_.get()}; }
  uint32_t* entries() const { return entries_.get(); }    // intersect's output
  uint32_t* selected() const { return selected_.get(); }  // compact's output
  uint32_t* sorted() const { return sorted_.get(); }      // sort's output
  WaveCounters* counters() const { return counters_.get(); }
  void* temp() const { return temp_.get(); }
  size_t temp_bytes() const { return temp_.size(); }

 private:
  size_t capacity_;
  DeviceBuffer<unsigned char> queue_memory_[2];
  PathQueue queues_[2];
  DeviceBuffer<float> hit_t_;
  DeviceBuffer<int32_t> hit_sphere_;
  DeviceBuffer<uint32_t> entries_, selected_, sorted_;
  DeviceBuffer<WaveCounters> counters_;
  DeviceBuffer<unsigned char> temp_;
};

}  // namespace wt::cuda

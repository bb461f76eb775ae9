// One wave of the wavefront: its path slots, the queues and arrays over them, and
// the counters that say where the wave stands. The layout is backend-neutral: the
// CPU lays it out in host memory, the GPU in device memory, with the same code.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "queues/path_queue.hpp"

namespace wt {

// Where a wave draws its paths from and what it has handed out so far.
struct WaveCounters {
  uint32_t queued[2];  // paths waiting in each queue (the current one, and the one shade fills)
  uint32_t next_path;  // first path index not yet generated
  uint32_t hits;       // entries compact kept this bounce
  uint64_t rays;       // rays intersected, all bounces
  uint32_t shadows;    // shadow rays shade queued this bounce
  // The sort keys among the hits of the bounce traced from queue[cur] (bit k: key k),
  // which decide whether that bounce is sorted; each bounce's counter update clears
  // the next bounce's.
  uint32_t key_mask[2];
  uint32_t unused;
  uint64_t shadow_rays;  // shadow rays traced, all bounces
};

// Paths live in slots [0, live) once generate has filled the free slots.
WT_HD WT_INLINE uint32_t live_paths(uint32_t queued, uint32_t next_path, uint32_t total_paths, uint32_t capacity) {
  uint64_t want = static_cast<uint64_t>(queued) + (total_paths - next_path);
  return static_cast<uint32_t>(want < capacity ? want : capacity);
}

// The arrays of one wave, laid out in one block by lay_out_wave.
struct WaveView {
  uint32_t capacity = 0;
  PathQueue queue[2];  // the bounce being traced, and the next one shade pushes into
  HitQueue hits;
  ShadowQueue shadows;           // shade's light samples, one a slot at the most
  uint32_t* entries = nullptr;   // intersect's sort entries; the sort's second buffer
  uint32_t* selected = nullptr;  // compact's output: the entries of rays that hit
  WaveCounters* counters = nullptr;
  void* temp = nullptr;          // the backend's temporary storage (CUB's, on the GPU)
  size_t temp_bytes = 0;
};

// Lays a wave of `capacity` slots out over `base`; with a null base it only sizes
// the block. *bytes receives the block's size.
inline WaveView lay_out_wave(unsigned char* base, size_t capacity, size_t temp_bytes, size_t* bytes) {
  Arena arena(base);
  WaveView w;
  w.capacity = static_cast<uint32_t>(capacity);
  for (PathQueue& q : w.queue) q = PathQueue::take(arena, capacity);
  w.hits = HitQueue::take(arena, capacity);
  w.shadows = ShadowQueue::take(arena, capacity);
  w.entries = arena.take<uint32_t>(capacity);
  w.selected = arena.take<uint32_t>(capacity);
  w.counters = arena.take<WaveCounters>(1);
  w.temp = arena.take<unsigned char>(temp_bytes);
  w.temp_bytes = temp_bytes;
  *bytes = arena.size();
  return w;
}

// Bytes of the block a wave of `capacity` slots takes.
inline size_t wave_bytes(size_t capacity, size_t temp_bytes) {
  size_t bytes = 0;
  lay_out_wave(nullptr, capacity, temp_bytes, &bytes);
  return bytes;
}

// How a backend sizes its waves when the user does not.
struct WaveBudget {
  int64_t default_slots;      // the backend's measured default
  size_t memory_bytes;        // what the wave may take at most; 0: no limit
  size_t bytes_per_slot;      // wave_bytes per slot, temporaries included
};

constexpr int64_t kMinWaveSlots = 1024;  // the most: kMaxWaveSize, set by the sort entry's slot bits

// The wave size for a render of `total_paths`: the request if given (checked by the
// caller against kMinWaveSlots..kMaxWaveSize), else the backend's default, capped by
// its memory budget but never below kMinWaveSlots; never more slots than paths.
inline int64_t choose_wave_size(int64_t requested, int64_t total_paths, const WaveBudget& budget) {
  if (requested > 0) return std::min(requested, total_paths);
  int64_t slots = budget.default_slots;
  if (budget.memory_bytes > 0) {
    slots = std::min(slots, static_cast<int64_t>(budget.memory_bytes / budget.bytes_per_slot));
  }
  return std::min(total_paths, std::max(slots, kMinWaveSlots));
}

}  // namespace wt

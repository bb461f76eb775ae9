// The wavefront's stage launches: each a thin loop around a per-item function of
// stage_items.hpp. Every launch is checked and named after its stage.
#pragma once

#include <cuda_runtime.h>

#include "queues/wave_memory.hpp"

namespace wt::cuda {

// generate: fills the free slots of queue `cur` with camera paths.
void launch_generate(const SceneView& scene, const RenderParams& rp, const WaveMemory& wave, int cur,
                     uint32_t total_paths, cudaStream_t stream);

// intersect: closest hits of the live slots, sort entries, sky for misses; then
// advances the counters (rays, next path) and empties the other queue.
void launch_intersect(const SceneView& scene, const RenderParams& rp, const WaveMemory& wave, int cur,
                      uint32_t total_paths, float* film, cudaStream_t stream);

// compact: keeps the entries of paths that hit something (cub::DeviceSelect);
// their number goes to counters->hits.
void compact_entries(const WaveMemory& wave, cudaStream_t stream);

// Bytes of temporary storage compact needs for `capacity` entries.
size_t compact_temp_bytes(size_t capacity);

// sort: orders `count` entries by their material key (cub::DeviceRadixSort over the key bits only).
void sort_entries(const WaveMemory& wave, uint32_t count, int key_bits, cudaStream_t stream);

size_t sort_temp_bytes(size_t capacity);

// shade: scatters the `count` paths listed in `list`, pushing survivors into queue 1 - cur.
void launch_shade(const SceneView& scene, const RenderParams& rp, const WaveMemory& wave, int cur,
                  const uint32_t* list, uint32_t count, float* film, cudaStream_t stream);

}  // namespace wt::cuda

#include "stages/stages.hpp"

namespace wt::cuda {

namespace {
__global__ void intersect_kernel(SceneView scene, RenderParams rp, PathQueue q, HitQueue hits, uint32_t* entries,
                                 const WaveCounters* counters, int cur, uint32_t total_paths, uint32_t capacity,
                                 float* film) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= capacity) return;
  const uint32_t live = live_paths(counters->queued[cur], counters->next_path, total_paths, capacity);
  // Slots past the live ones get a miss entry so that compact, which runs over the
  // whole capacity without the host knowing the count, drops them.
  entries[i] = i < live ? intersect_one(i, scene, rp, q, hits, film) : pack_entry(kSortKeyMiss, i);
}

// Runs after every intersect thread has read the counters.
__global__ void advance_counters(WaveCounters* c, int cur, uint32_t total_paths, uint32_t capacity) {
  const uint32_t queued = c->queued[cur];
  const uint32_t live = live_paths(queued, c->next_path, total_paths, capacity);
  c->rays += live;
  c->next_path += live - queued;
  c->queued[cur] = live;
  c->queued[1 - cur] = 0;
}
}  // namespace

void launch_intersect(const SceneView& scene, const RenderParams& rp, const WaveMemory& wave, int cur,
                      uint32_t total_paths, float* film, cudaStream_t stream) {
  const uint32_t capacity = static_cast<uint32_t>(wave.capacity());
  intersect_kernel<<<(capacity + 127) / 128, 128, 0, stream>>>(scene, rp, wave.queue(cur), wave.hits(),
                                                               wave.entries(), wave.counters(), cur, total_paths,
                                                               capacity, film);
  WT_CUDA_LAUNCHED("intersect_kernel", "intersect");
  advance_counters<<<1, 1, 0, stream>>>(wave.counters(), cur, total_paths, capacity);
  WT_CUDA_LAUNCHED("advance_counters", "intersect");
}

}  // namespace wt::cuda

#include "queues/push.cuh"
#include "stages/stages.hpp"

namespace wt::cuda {

namespace {
__global__ void shade_kernel(SceneView scene, RenderParams rp, PathQueue q, HitQueue hits, PathQueue next_queue,
                             uint32_t* next_count, const uint32_t* list, uint32_t count, float* film) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  PathState next;
  const bool alive = i < count && shade_one(entry_slot(list[i]), scene, rp, q, hits, film, next);
  // Every thread reaches the push, so the warp can reserve its slots with one atomic.
  const uint32_t slot = push_slot(next_count, alive);
  if (alive) next_queue.store(slot, next);
}
}  // namespace

void launch_shade(const SceneView& scene, const RenderParams& rp, const WaveMemory& wave, int cur,
                  const uint32_t* list, uint32_t count, float* film, cudaStream_t stream) {
  if (count == 0) return;
  shade_kernel<<<(count + 127) / 128, 128, 0, stream>>>(scene, rp, wave.queue(cur), wave.hits(), wave.queue(1 - cur),
                                                        &wave.counters()->queued[1 - cur], list, count, film);
  WT_CUDA_LAUNCHED("shade_kernel", "shade");
}

}  // namespace wt::cuda

#include "stages/stages.hpp"

namespace wt::cuda {

namespace {
__global__ void generate_kernel(SceneView scene, RenderParams rp, PathQueue q, const WaveCounters* counters, int cur,
                                uint32_t total_paths, uint32_t capacity) {
  const uint32_t slot = blockIdx.x * blockDim.x + threadIdx.x;
  const uint32_t queued = counters->queued[cur];
  const uint32_t next_path = counters->next_path;
  if (slot < queued || slot >= live_paths(queued, next_path, total_paths, capacity)) return;
  generate_one(slot, queued, next_path, scene, rp, q);
}
}  // namespace

void launch_generate(const SceneView& scene, const RenderParams& rp, const WaveMemory& wave, int cur,
                     uint32_t total_paths, cudaStream_t stream) {
  const uint32_t capacity = static_cast<uint32_t>(wave.capacity());
  generate_kernel<<<(capacity + 255) / 256, 256, 0, stream>>>(scene, rp, wave.queue(cur), wave.counters(), cur,
                                                             total_paths, capacity);
  WT_CUDA_LAUNCHED("generate_kernel", "generate");
}

}  // namespace wt::cuda

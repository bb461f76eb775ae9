#include "cuda/cuda_wavefront.hpp"

#include "cuda/executor.cuh"
#include "stages/wavefront.hpp"

namespace wt::cuda {

namespace {
// Measured on an H100 (seed57, 1920x1080, 300 spp): 1, 2, 4, 8 and 16 Mi slots took
// 0.232, 0.173, 0.156, 0.144 and 0.141 s (bench/RESULTS.md). Bigger waves mean fewer
// bounces, so fewer launches and host round trips; 16 Mi slots take about 1.8 GB.
constexpr int64_t kDefaultWaveSlots = int64_t(1) << 24;
}  // namespace

size_t wavefront_bytes(int64_t wave_size) { return wt::wavefront_bytes<Executor>(static_cast<size_t>(wave_size)); }

int64_t choose_wave_size(int64_t requested, const RenderParams& rp, size_t free_memory) {
  const int64_t total = static_cast<int64_t>(rp.width) * rp.height * rp.spp;
  // A quarter of free memory at most: the film, the scene and the runtime need the rest.
  const size_t per_slot = (wavefront_bytes(1 << 20) >> 20) + 1;
  return wt::choose_wave_size(requested, total, WaveBudget{kDefaultWaveSlots, free_memory / 4, per_slot});
}

RenderResult render_wavefront(const SceneView& scene, int key_bits, const RenderOptions& options, int64_t wave_size) {
  Executor ex;
  return wt::render_wavefront(ex, scene, key_bits, options, wave_size);
}

struct WaveRenderer::Kept {
  Executor ex;
};

WaveRenderer::WaveRenderer() = default;
WaveRenderer::~WaveRenderer() = default;

RenderResult WaveRenderer::render(const SceneView& scene, int key_bits, const RenderOptions& options,
                                  int64_t wave_size) {
  if (!kept_) kept_ = std::make_unique<Kept>();  // at the first render: none for the megakernels
  return wt::render_wavefront(kept_->ex, scene, key_bits, options, wave_size);
}

size_t WaveRenderer::kept_bytes() const { return kept_ ? kept_->ex.wave_bytes() : 0; }

}  // namespace wt::cuda

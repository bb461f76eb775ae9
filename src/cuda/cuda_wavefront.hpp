// The wavefront on the GPU: stages/wavefront.hpp's driver over the CUDA executor.
#pragma once

#include <memory>

#include "render/render_types.hpp"

namespace wt::cuda {

// Device bytes a wave of this many slots needs (queues, hits, entries, CUB's temporaries).
size_t wavefront_bytes(int64_t wave_size);

// The wave size: the request if given, else the measured default capped by free memory.
int64_t choose_wave_size(int64_t requested, const RenderParams& rp, size_t free_memory);

// Renders with a wave of `wave_size` slots; the result holds pixel sums.
RenderResult render_wavefront(const SceneView& scene, int key_bits, const RenderOptions& options, int64_t wave_size);

// The same renders one after another on the current device, keeping what a render
// sets up (its stream's pinned counters, the wave's memory: about 2 GB at the default
// size) for the next: the chunks of a render split over devices.
class WaveRenderer {
 public:
  WaveRenderer();
  ~WaveRenderer();
  WaveRenderer(const WaveRenderer&) = delete;
  WaveRenderer& operator=(const WaveRenderer&) = delete;
  RenderResult render(const SceneView& scene, int key_bits, const RenderOptions& options, int64_t wave_size);
  // The device memory kept for the next render's wave (0 before the first).
  size_t kept_bytes() const;

 private:
  struct Kept;
  std::unique_ptr<Kept> kept_;
};

}  // namespace wt::cuda

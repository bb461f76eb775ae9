// The wavefront renderer on the GPU: the stages of stages.hpp, bounce after bounce,
// with path regeneration keeping the wave full while paths remain.
#pragma once

#include "render/renderer.hpp"

namespace wt::cuda {

// Device bytes a wave of this many slots needs (queues, hits, entries, temporaries).
size_t wavefront_bytes(int64_t wave_size);

// The wave size: the request if given (checked), else chosen from free memory.
int64_t choose_wave_size(int64_t requested, const RenderParams& rp, size_t free_memory);

RenderResult render_wavefront(const SceneView& scene, int key_bits, const RenderOptions& options, int64_t wave_size);

}  // namespace wt::cuda

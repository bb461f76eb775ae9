// The wavefront on host threads: stages/wavefront.hpp's driver over the CPU executor.
#pragma once

#include "render/render_types.hpp"

namespace wt::cpu {

// The wave size: the request if given, else the measured default.
int64_t choose_wave_size(int64_t requested, const RenderParams& rp);

// Renders with a wave of `wave_size` slots; the result holds pixel sums.
RenderResult render_wavefront(const SceneView& scene, int key_bits, const RenderOptions& options, int64_t wave_size);

}  // namespace wt::cpu

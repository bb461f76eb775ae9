#pragma once

#include "render/renderer.hpp"

namespace wt::cuda {

RenderResult render(const Scene& scene, const RenderOptions& options);

// Device bytes a render with these settings needs beyond the scene itself.
size_t render_state_bytes(const RenderParams& rp, Kernel kernel, int64_t wave_size);

}  // namespace wt::cuda

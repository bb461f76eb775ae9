#pragma once

#include "render/render_types.hpp"
#include "scene/scene.hpp"

namespace wt::cuda {

// Renders on the current CUDA device; the result holds pixel sums (render/renderer.hpp divides).
RenderResult render(const Scene& scene, const RenderOptions& options);

// Device bytes a render with these settings needs beyond the scene itself.
size_t render_state_bytes(const RenderParams& rp, Kernel kernel, int64_t wave_size);

// Throws InputError naming the resolution and the device when `need` bytes do not
// fit in `free_bytes` (less headroom for the runtime).
void require_device_memory(const RenderParams& rp, size_t need, size_t free_bytes, const std::string& device);

}  // namespace wt::cuda

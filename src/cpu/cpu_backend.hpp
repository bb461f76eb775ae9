// The CPU backend: the megakernel and the wavefront on host threads.
#pragma once

#include <cstddef>

#include "render/aovs.hpp"
#include "render/device_renderer.hpp"
#include "render/render_types.hpp"
#include "scene/scene.hpp"

namespace wt::cpu {

// Renders on host threads (options.threads, or every core); the result holds pixel
// sums (dispatch/renderer.hpp divides). One "device": the dispatcher splits a render
// over several (options.devices) with device_renderer.
RenderResult render(const Scene& scene, const RenderOptions& options);

// Host "device" i of the render's several (the split's logic without GPUs): a share
// of the threads, rendering each chunk as render does.
DeviceRenderer device_renderer(const Scene& scene, const RenderOptions& options, size_t i);

// The first-surface pass (include/wavetrace/aov.hpp) over every sample of every
// pixel, on host threads: the sums the AOVs are made of.
AovSums render_aov_sums(const Scene& scene, const RenderOptions& options,
                        const std::vector<int32_t>* pixel_samples = nullptr);

}  // namespace wt::cpu

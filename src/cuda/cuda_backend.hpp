#pragma once

#include <cstddef>

#include "render/aovs.hpp"
#include "render/device_renderer.hpp"
#include "render/render_types.hpp"
#include "scene/scene.hpp"

namespace wt::cuda {

// Throws DeviceError where no CUDA device is present, and InputError for a device of
// options.devices that is not one: called by the dispatcher before either below.
void check_devices(const RenderOptions& options);

// Renders on the one device of options.devices (or the current one where it names
// none); the result holds pixel sums (dispatch/renderer.hpp divides). The dispatcher
// splits a render over several devices with device_renderer.
RenderResult render(const Scene& scene, const RenderOptions& options);

// Device i of options.devices, one of several: made current on the calling thread
// (the split's thread for it), the scene uploaded there, and each chunk rendered
// there, its sums kept in the device's memory until collected.
DeviceRenderer device_renderer(const Scene& scene, const RenderOptions& options, size_t i);

// The first-surface pass (include/wavetrace/aov.hpp) on the first of
// options.devices (or the current device), over a scene uploaded for it: the sums
// the AOVs are made of.
AovSums render_aov_sums(const Scene& scene, const RenderOptions& options,
                        const std::vector<int32_t>* pixel_samples = nullptr);

// Device bytes a render with these settings needs beyond the scene itself.
size_t render_state_bytes(const RenderParams& rp, Kernel kernel, int64_t wave_size);

// Throws InputError naming the resolution and the device when `need` bytes do not
// fit in `free_bytes` (less headroom for the runtime).
void require_device_memory(const RenderParams& rp, size_t need, size_t free_bytes, const std::string& device);

}  // namespace wt::cuda

#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "cuda/device_image.hpp"
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

// The same render of a whole film (from sample 0, no adaptive rounds) on that one
// device, its image finished there (device_image.hpp) instead of brought back: the
// result's rgb is empty, and `image` holds each pixel's mean: in the memory its rgba
// names where it names some (ImageFinisher), else in device memory that the scene's
// copy there keeps for images (ImageBlocks: a block let go serves the next image).
RenderResult render_image(const Scene& scene, const RenderOptions& options, DeviceImage& image);

// Device i of options.devices, one of several: made current on the calling thread
// (the split's thread for it), the scene uploaded there, and each chunk rendered
// there, its sums kept in the device's memory until collected.
DeviceRenderer device_renderer(const Scene& scene, const RenderOptions& options, size_t i);

// The first-surface pass (include/wavetrace/aov.hpp) on the first of
// options.devices (or the current device), over a scene uploaded for it: the sums
// the AOVs are made of.
AovSums render_aov_sums(const Scene& scene, const RenderOptions& options,
                        const std::vector<int32_t>* pixel_samples = nullptr);

// Copies of `scene` to keep on the devices from one render to the next, for
// RenderOptions::resident; `scene` must outlive them. And how many uploads they have
// made (each device's first render, and one more where two renders hold one device at
// once).
std::shared_ptr<ResidentScenes> keep_scene(const Scene& scene);
int64_t uploads(const ResidentScenes& resident);

// `n` floats copied into new memory on CUDA device `device` (an image handed to
// another library where it lies: the Python module's DLPack arrays), which
// free_on_device frees.
float* copy_to_device(const float* host, size_t n, int device);
void free_on_device(void* p) noexcept;
// And back: `n` floats of device memory copied to `host`.
void copy_to_host(const float* on_device, size_t n, float* host);

// Device bytes a render with these settings needs beyond the scene itself.
size_t render_state_bytes(const RenderParams& rp, Kernel kernel, int64_t wave_size);

// Throws InputError naming the resolution and the device when `need` bytes do not
// fit in `free_bytes` (less headroom for the runtime).
void require_device_memory(const RenderParams& rp, size_t need, size_t free_bytes, const std::string& device);

}  // namespace wt::cuda

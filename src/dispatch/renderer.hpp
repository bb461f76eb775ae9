// One entry point for every backend and kernel: render a scene, get linear
// radiance, counted rays and timings back.
#pragma once

#include "cuda/device_image.hpp"
#include "render/adaptive.hpp"
#include "render/aovs.hpp"
#include "render/render_types.hpp"
#include "render/settings.hpp"
#include "scene/scene.hpp"

namespace wt {

const char* backend_name(Backend b);

// Fails with InputError for settings the backend cannot honour (naming the setting),
// and DeviceError (cuda::CudaError for CUDA calls, naming the call and the stage)
// when the machine fails. The result holds each pixel's mean radiance. With
// options.noise_threshold, the render is adaptive (render/adaptive.hpp), its rounds'
// pixels split between the options' devices where it has several.
RenderResult render(const Scene& scene, const RenderOptions& options);
// The same, an adaptive render's checkpoints and progress kept by `hooks`.
RenderResult render(const Scene& scene, const RenderOptions& options, const AdaptiveHooks& hooks);
// What renders an adaptive render's rounds on the options' devices (each call the
// pixels and samples its options name, their sums back; render/adaptive.hpp): made
// once, the scene uploaded to each device once; over several devices, each round's
// pixels split between them (PixelSplit, dispatch/split.hpp).
ChunkRenderer adaptive_rounds(const Scene& scene, const RenderOptions& options);
// The adaptive render of `options` with those rounds (or others that wrap them: an
// MPI run's ranks), its settings checked first.
RenderResult render_adaptive_rounds(const ChunkRenderer& rounds, const RenderOptions& options,
                                    const AdaptiveHooks& hooks);
// Whether render_to_device takes these options: the CUDA backend on one device, a
// render of a whole film from sample 0 that is not adaptive.
bool renders_to_device(const RenderOptions& options);
// render() of such options, its image finished on the device it ran on
// (cuda/device_image.hpp) instead of brought back: the result's rgb is empty, and
// `image` holds the means render() would have returned, bit for bit: in memory from
// `memory` where it is given (asked for once the render's settings and devices are
// checked), else in device memory.
RenderResult render_to_device(const Scene& scene, const RenderOptions& options, cuda::DeviceImage& image,
                              const cuda::ImageMemory& memory = {});
// The same render, its result the pixels' sums over the samples it rendered
// (Radiance::SumOfSamples, with the initial film's): for a part of a render whose
// sums are added to others' (the ranks of an MPI run).
RenderResult render_sums(const Scene& scene, const RenderOptions& options);

// The first-surface pass that the AOVs are made of (render/aovs.hpp), over every
// sample of every pixel, on the options' backend (the first of its devices): the same
// for every kernel, since the pass follows the camera's rays and not a kernel's queues.
// With `pixel_samples` (an adaptive render's), pixel p's samples [0, pixel_samples[p]).
AovSums render_aovs(const Scene& scene, const RenderOptions& options,
                    const std::vector<int32_t>* pixel_samples = nullptr);

// Copies of `scene` kept on the devices between renders (RenderOptions::resident):
// the backend's where it uploads a scene (CUDA), null where it renders the scene
// where it lies (the CPU). `scene` must outlive them.
std::shared_ptr<ResidentScenes> keep_scene(const Scene& scene, Backend backend);
// The uploads those copies have made (0 for none).
int64_t scene_uploads(const ResidentScenes* resident);

// Turns a backend's pixel sums over r.samples samples into means (every render's
// last step; also for a film that was complete when it was resumed).
void take_mean(RenderResult& r);

// Checks RenderParams against the sane limits; throws InputError naming the setting.
void validate_params(const RenderParams& p);
// Those and the rest of the options (the samples, the initial film).
void validate_render(const RenderOptions& options);

// Params from the scene's defaults.
RenderParams default_params(const Scene& scene);

}  // namespace wt

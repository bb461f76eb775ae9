// The one-kernel renderers kept for comparison: one thread per pixel traces every
// bounce of every sample in one launch, over a scene in global or constant memory.
#pragma once

#include <cuda_runtime.h>

#include <cstdint>
#include <vector>

#include "scene/scene.hpp"

namespace wt::cuda {

// A launch's pixels and where it puts their samples (megakernel_body.cuh): the
// `count` pixels `active` lists (adaptive sampling's pixels still going), or every
// pixel (active null); their samples added to `film`, one thread a pixel looping
// over them (radiance null), or, for a batch of a small image's samples, one thread
// a pixel and sample, each sample's radiance stored in `radiance` (samples x count x
// 3 floats, by the pixel's place in the list) for launch_megakernel_fold.
struct MegakernelWork {
  float* film;
  float* radiance;
  const uint32_t* active = nullptr;
  uint32_t count = 0;  // with active

  // The pixels the launch covers, and the one at `index` of them.
  WT_HD uint32_t pixels(const RenderParams& rp) const {
    return active ? count : static_cast<uint32_t>(rp.width) * static_cast<uint32_t>(rp.height);
  }
  WT_HD uint32_t pixel(uint32_t index) const { return active ? active[index] : index; }
};

// A small image fills the GPU with too few threads at one a pixel (at 512 x 384 an
// H200 runs 2.3 waves of the megakernel, the last a third full), so its passes run
// in batches of this many samples, one thread a pixel and sample: enough threads for
// about four full waves of the device (sm_count x 2048 x 4), at most the pass's
// samples (and 1024). 1: one thread a pixel (1920 x 1080 on 132 SMs, and larger).
int megakernel_batch(int64_t pixels, int sm_count, int pass_samples);

// Adds samples [first_sample, first_sample + samples) of the work's pixels to its film
// (RGB sums), or stores each in its radiance, and the path rays they intersect to
// rays[0] and the shadow rays to rays[1].
void launch_megakernel(const SceneView& scene, const RenderParams& rp, int first_sample, int samples,
                       MegakernelWork out, unsigned long long* rays, cudaStream_t stream);

// Adds a batch's stored samples (`samples` of them, in sample order) to each pixel's
// running sum (from zero where `first`), and where `last` (the pass's last batch) the
// sum to the film: the additions of the one-thread-a-pixel loop, in its order, so
// that batches change no bit of the image.
void launch_megakernel_fold(const RenderParams& rp, int samples, MegakernelWork work, float* running, bool first,
                            bool last, cudaStream_t stream);

// Loads the kernel launch_megakernel would run for this scene and these settings
// (device.hpp's load_kernel).
void load_megakernel(const SceneView& scene, const RenderParams& rp);

// Loads launch_megakernel_fold's kernel, which either megakernel's batches run (its
// module is the global megakernel's, loaded with it: a tenth of a second on the H100).
void load_megakernel_fold();

// Bytes of __constant__ memory the constant-memory megakernel can hold a scene in.
size_t constant_scene_capacity();

// Copies the scene into __constant__ memory; throws InputError if it does not fit.
// `images` are the device image views (texture objects) of the uploaded scene.
void upload_constant_scene(const Scene& scene, const SceneView& device_view, const std::vector<ImageView>& images);

void launch_megakernel_constant(const RenderParams& rp, int first_sample, int samples, MegakernelWork out,
                                unsigned long long* rays, cudaStream_t stream);

// Loads the kernel launch_megakernel_constant would run for the uploaded scene.
void load_megakernel_constant(const RenderParams& rp);

}  // namespace wt::cuda

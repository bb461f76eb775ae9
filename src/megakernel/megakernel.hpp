// The one-kernel renderers kept for comparison: one thread per pixel traces every
// bounce of every sample in one launch, over a scene in global or constant memory.
#pragma once

#include <cuda_runtime.h>

#include <vector>

#include "scene/scene.hpp"

namespace wt::cuda {

// Adds samples [first_sample, first_sample + samples) of every pixel to film (RGB
// sums), the path rays they intersect to rays[0] and the shadow rays to rays[1].
void launch_megakernel(const SceneView& scene, const RenderParams& rp, int first_sample, int samples, float* film,
                       unsigned long long* rays, cudaStream_t stream);

// Bytes of __constant__ memory the constant-memory megakernel can hold a scene in.
size_t constant_scene_capacity();

// Copies the scene into __constant__ memory; throws InputError if it does not fit.
// `images` are the device image views (texture objects) of the uploaded scene.
void upload_constant_scene(const Scene& scene, const SceneView& device_view, const std::vector<ImageView>& images);

void launch_megakernel_constant(const RenderParams& rp, int first_sample, int samples, float* film,
                                unsigned long long* rays, cudaStream_t stream);

}  // namespace wt::cuda

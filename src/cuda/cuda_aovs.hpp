// The first-surface pass that the AOVs are made of (render/aovs.hpp), on the GPU.
#pragma once

#include <cuda_runtime.h>

#include "wavetrace/scene_view.hpp"

namespace wt::cuda {

// Writes every pixel's kAovFloats sums over samples [0, rp.spp), or [0, counts[p])
// of pixel p where `counts` is given, to `sums`.
void launch_first_surface(const SceneView& scene, const RenderParams& rp, const int32_t* counts, float* sums,
                          cudaStream_t stream);

}  // namespace wt::cuda

// The first-surface pass on the GPU (include/wavetrace/aov.hpp): one thread a pixel,
// every sample of it in turn, as the CPU backend adds them.
#include "cuda/cuda_aovs.hpp"
#include "device/device.hpp"
#include "device/kernel_bodies.hpp"
#include "wavetrace/aov.hpp"

namespace wt::cuda {

namespace {

constexpr int kAovBlockX = 16;
constexpr int kAovBlockY = 8;

__global__ void __launch_bounds__(kAovBlockX * kAovBlockY)
    first_surface_kernel(SceneView scene, RenderParams rp, const int32_t* counts, float* sums) {
#if WT_KERNEL_BODIES
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  const int y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= rp.width || y >= rp.height) return;
  const uint32_t pixel = static_cast<uint32_t>(y) * rp.width + x;
  float local[kAovFloats] = {};
  const int samples = counts ? counts[pixel] : rp.spp;
  for (int s = 0; s < samples; ++s) add_first_surface(local, first_surface(scene, rp, pixel, static_cast<uint32_t>(s)));
  float* out = sums + static_cast<size_t>(pixel) * kAovFloats;
  for (int i = 0; i < kAovFloats; ++i) out[i] = local[i];
#endif
}

}  // namespace

void launch_first_surface(const SceneView& scene, const RenderParams& rp, const int32_t* counts, float* sums,
                          cudaStream_t stream) {
  const dim3 block(kAovBlockX, kAovBlockY);
  const dim3 grid((rp.width + kAovBlockX - 1) / kAovBlockX, (rp.height + kAovBlockY - 1) / kAovBlockY);
  first_surface_kernel<<<grid, block, 0, stream>>>(scene, rp, counts, sums);
  WT_CUDA_LAUNCHED("first_surface_kernel", "aovs");
}

}  // namespace wt::cuda

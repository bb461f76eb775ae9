#include "cuda/device.hpp"
#include "megakernel/megakernel.hpp"
#include "megakernel/megakernel_body.cuh"

namespace wt::cuda {

__global__ void __launch_bounds__(kMegakernelBlockX * kMegakernelBlockY)
    megakernel_global(SceneView scene, RenderParams rp, int first_sample, int samples, float* film,
                      unsigned long long* rays) {
  megakernel_pixel(scene, rp, first_sample, samples, film, rays);
}

void launch_megakernel(const SceneView& scene, const RenderParams& rp, int first_sample, int samples, float* film,
                       unsigned long long* rays, cudaStream_t stream) {
  megakernel_global<<<megakernel_grid(rp), dim3(kMegakernelBlockX, kMegakernelBlockY), 0, stream>>>(
      scene, rp, first_sample, samples, film, rays);
  WT_CUDA_LAUNCHED("megakernel_global", "megakernel");
}

}  // namespace wt::cuda

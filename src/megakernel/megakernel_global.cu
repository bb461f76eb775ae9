#include "device/device.hpp"
#include "megakernel/megakernel.hpp"
#include "megakernel/megakernel_body.cuh"

namespace wt::cuda {

template <uint32_t Kinds>
__global__ void __launch_bounds__(kMegakernelBlockX * kMegakernelBlockY)
    megakernel_global(SceneView scene, RenderParams rp, int first_sample, int samples, float* film,
                      unsigned long long* rays) {
  megakernel_pixel<Kinds>(scene, rp, first_sample, samples, film, rays);
}

void launch_megakernel(const SceneView& scene, const RenderParams& rp, int first_sample, int samples, float* film,
                       unsigned long long* rays, cudaStream_t stream) {
  const dim3 grid = megakernel_grid(rp), block(kMegakernelBlockX, kMegakernelBlockY);
  // Light sampling's code is compiled in only where the scene has emitters to sample.
  const uint32_t kinds_and_lights = scene.kinds | (scene.samples_lights(rp) ? kLightSampling : 0u);
  with_kinds(kinds_and_lights, [&](auto kinds) {
    megakernel_global<decltype(kinds)::value><<<grid, block, 0, stream>>>(scene, rp, first_sample, samples, film, rays);
  });
  WT_CUDA_LAUNCHED("megakernel_global", "megakernel");
}

}  // namespace wt::cuda

#include "cuda/device.hpp"
#include "megakernel/megakernel.hpp"
#include "megakernel/megakernel_body.cuh"

namespace wt::cuda {

template <uint32_t Kinds>
__global__ void __launch_bounds__(kMegakernelThreads, kMegakernelMinBlocksPerSm)
    megakernel_global(SceneView scene, RenderParams rp, int first_sample, int samples, float* film,
                      unsigned long long* rays, unsigned int* next_pixel) {
  megakernel_thread<Kinds>(scene, rp, first_sample, samples, film, rays, next_pixel);
}

void launch_megakernel(const SceneView& scene, const RenderParams& rp, int first_sample, int samples, float* film,
                       unsigned long long* rays, unsigned int* next_pixel, cudaStream_t stream) {
  // Light sampling's code is compiled in only where the scene has emitters to sample.
  const uint32_t kinds_and_lights = scene.kinds | (rp.nee != 0 && scene.light_total > 0 ? kLightSampling : 0u);
  with_kinds(kinds_and_lights, [&](auto kinds) {
    const auto kernel = megakernel_global<decltype(kinds)::value>;
    kernel<<<megakernel_grid(kernel, rp, "megakernel"), kMegakernelThreads, 0, stream>>>(scene, rp, first_sample,
                                                                                         samples, film, rays,
                                                                                         next_pixel);
  });
  WT_CUDA_LAUNCHED("megakernel_global", "megakernel");
}

}  // namespace wt::cuda

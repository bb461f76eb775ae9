#include <algorithm>

#include "device/device.hpp"
#include "device/kernel_bodies.hpp"
#include "megakernel/megakernel.hpp"
#include "megakernel/megakernel_body.cuh"

namespace wt::cuda {

template <uint32_t Kinds>
__global__ void __launch_bounds__(kMegakernelBlockX * kMegakernelBlockY)
    megakernel_global(SceneView scene, RenderParams rp, int first_sample, int samples, MegakernelWork out,
                      unsigned long long* rays) {
#if WT_KERNEL_BODIES
  megakernel_pixel<Kinds>(scene, rp, first_sample, samples, out, rays);
#endif
}

// Thread per pixel: the pixel's sums of the batch's earlier samples (`running`,
// where `first` is false) plus each of this batch's in turn; the pass's last batch
// adds the sum to the film, the others keep it in `running`.
__global__ void megakernel_fold(RenderParams rp, int samples, MegakernelWork work, float* running, bool first,
                                bool last) {
  const size_t pixels = work.pixels(rp);
  const size_t index = static_cast<size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (index >= pixels) return;
  const size_t pixel = work.pixel(static_cast<uint32_t>(index));
  vec3 sum = first ? vec3(0.0f) : vec3(running[3 * index], running[3 * index + 1], running[3 * index + 2]);
  for (int j = 0; j < samples; ++j) {
    const float* r = work.radiance + 3 * (j * pixels + index);
    sum += vec3(r[0], r[1], r[2]);
  }
  float* f = last ? work.film + 3 * pixel : running + 3 * index;
  if (last) {
    f[0] += sum.x;
    f[1] += sum.y;
    f[2] += sum.z;
  } else {
    f[0] = sum.x;
    f[1] = sum.y;
    f[2] = sum.z;
  }
}

int megakernel_batch(int64_t pixels, int sm_count, int pass_samples) {
  const int64_t target = static_cast<int64_t>(sm_count) * 2048 * 4;
  const int64_t batch = (target + pixels - 1) / std::max<int64_t>(pixels, 1);
  return static_cast<int>(std::clamp<int64_t>(batch, 1, std::clamp(pass_samples, 1, 1024)));
}

void launch_megakernel_fold(const RenderParams& rp, int samples, MegakernelWork work, float* running, bool first,
                            bool last, cudaStream_t stream) {
  const size_t pixels = work.pixels(rp);
  constexpr unsigned kBlock = 256;
  megakernel_fold<<<static_cast<unsigned>((pixels + kBlock - 1) / kBlock), kBlock, 0, stream>>>(
      rp, samples, work, running, first, last);
  WT_CUDA_LAUNCHED("megakernel_fold", "megakernel");
}

namespace {

// Hands f the megakernel compiled for the scene's kinds: light sampling's code is
// compiled in only where the scene has emitters to sample.
template <class F>
void with_megakernel(const SceneView& scene, const RenderParams& rp, F&& f) {
  const uint32_t kinds_and_lights = scene.kinds | (scene.samples_lights(rp) ? kLightSampling : 0u);
  with_kinds(kinds_and_lights, [&](auto kinds) { f(megakernel_global<decltype(kinds)::value>); });
}

}  // namespace

void launch_megakernel(const SceneView& scene, const RenderParams& rp, int first_sample, int samples,
                       MegakernelWork out, unsigned long long* rays, cudaStream_t stream) {
  const dim3 grid = megakernel_grid(rp, out.radiance ? samples : 1, out), block(kMegakernelBlockX, kMegakernelBlockY);
  with_megakernel(scene, rp, [&](auto kernel) {
    kernel<<<grid, block, 0, stream>>>(scene, rp, first_sample, samples, out, rays);
  });
  WT_CUDA_LAUNCHED("megakernel_global", "megakernel");
}

void load_megakernel(const SceneView& scene, const RenderParams& rp) {
  with_megakernel(scene, rp, [](auto kernel) { load_kernel(reinterpret_cast<const void*>(kernel), "megakernel"); });
}

void load_megakernel_fold() { load_kernel(reinterpret_cast<const void*>(megakernel_fold), "megakernel"); }

}  // namespace wt::cuda

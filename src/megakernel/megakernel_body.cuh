// The megakernel's per-thread body, shared by the global- and constant-memory
// variants: they differ only in the scene accessor.
#pragma once

#include <algorithm>

#include "wavetrace/path.hpp"

namespace wt::cuda {

constexpr int kMegakernelBlockX = 16;
constexpr int kMegakernelBlockY = 8;

// With out.radiance null, each thread traces samples [first_sample, first_sample +
// samples) of its pixel and adds their sum to out.film. With out.radiance (a small
// image's batch: megakernel_batch), thread (pixel, z) traces sample first_sample + z
// alone and stores it at radiance[3 (z pixels + pixel)], and megakernel_fold adds the
// batch's samples up in the order the loop would have.
template <uint32_t Kinds, class Scene>
__device__ __forceinline__ void megakernel_pixel(const Scene& scene, const RenderParams& rp, int first_sample,
                                                 int samples, MegakernelWork out, unsigned long long* rays) {
  // rays[0]: path rays; rays[1]: shadow rays.
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  const int y = blockIdx.y * blockDim.y + threadIdx.y;
  const int z = static_cast<int>(blockIdx.z);
  // The thread's place in the work's pixels, and its pixel.
  const uint32_t index = static_cast<uint32_t>(y) * rp.width + x;
  const uint32_t pixels = out.pixels(rp);
  uint32_t count = 0, shadow_count = 0;
  if (x < rp.width && index < pixels && (!out.radiance || z < samples)) {
    const uint32_t pixel = out.pixel(index);
    // One call of trace_path in the kernel, whichever way: it is most of its code.
    const int begin = out.radiance ? first_sample + z : first_sample;
    const int end = out.radiance ? begin + 1 : first_sample + samples;
    vec3 sum(0.0f);
    for (int s = begin; s < end; ++s) {
      sum += trace_path<Kinds>(scene, rp, pixel, static_cast<uint32_t>(s), count, shadow_count);
    }
    if (out.radiance) {
      // 0 + L is L: the sample as trace_path returned it.
      float* r = out.radiance + 3 * (static_cast<size_t>(z) * pixels + index);
      r[0] = sum.x;
      r[1] = sum.y;
      r[2] = sum.z;
    } else {
      float* f = out.film + 3 * static_cast<size_t>(pixel);
      f[0] += sum.x;
      f[1] += sum.y;
      f[2] += sum.z;
    }
  }
  // One atomic per warp, not per ray: every lane reaches this point. The warp's sum
  // is taken in 64 bits, since 32 lanes of a long pass can pass 2^32 rays.
  unsigned long long warp_total = count, warp_shadows = shadow_count;
  for (int offset = 16; offset > 0; offset /= 2) {
    warp_total += __shfl_down_sync(0xffffffffu, warp_total, offset);
    warp_shadows += __shfl_down_sync(0xffffffffu, warp_shadows, offset);
  }
  if ((threadIdx.x + threadIdx.y * blockDim.x) % 32 == 0) {
    if (warp_total) atomicAdd(rays, warp_total);
    if (warp_shadows) atomicAdd(rays + 1, warp_shadows);
  }
}

// The launch's grid: the image's blocks (or the rows the work's listed pixels fill,
// read a row of the image's width at a time), `batch` deep where the samples are a
// batch (one thread a pixel and sample), else one deep.
inline dim3 megakernel_grid(const RenderParams& rp, int batch, const MegakernelWork& work) {
  const uint32_t rows = (work.pixels(rp) + rp.width - 1) / rp.width;
  return dim3((rp.width + kMegakernelBlockX - 1) / kMegakernelBlockX,
              std::max<uint32_t>(1, (rows + kMegakernelBlockY - 1) / kMegakernelBlockY), static_cast<unsigned>(batch));
}

}  // namespace wt::cuda

// The megakernel's per-thread body, shared by the global- and constant-memory
// variants: they differ only in the scene accessor.
//
// Persistent threads with path regeneration: the grid holds as many threads as the
// GPU runs at once, and each thread takes pixels from a global counter and traces
// their samples one ray at a time (advance_path). A thread whose path ends starts
// its next path at once instead of waiting, as it would in a loop over whole
// paths, for the longest path of its warp; so a warp's lanes stay busy while paths
// end at different bounces. A pixel's samples are still traced in order by one
// thread and summed into its film value once, so the image is the one a thread per
// pixel gives, bit for bit.
#pragma once

#include "cuda/device.hpp"
#include "wavetrace/path.hpp"

namespace wt::cuda {

// Threads per block, and the blocks of that size an SM must hold at once (the
// register budget: 65536 / (128 x 4) = 128 registers a thread). A build may set
// another budget (-DWAVETRACE_MEGAKERNEL_MIN_BLOCKS=N) to measure it.
constexpr int kMegakernelThreads = 128;
#ifdef WAVETRACE_MEGAKERNEL_MIN_BLOCKS
constexpr int kMegakernelMinBlocksPerSm = WAVETRACE_MEGAKERNEL_MIN_BLOCKS;
#else
constexpr int kMegakernelMinBlocksPerSm = 4;
#endif

// The next value of *counter for each calling lane, with one atomic per warp: the
// lanes that call together take consecutive values.
__device__ __forceinline__ uint32_t take_next(unsigned int* counter) {
  const unsigned int active = __activemask();
  const int leader = __ffs(active) - 1;
  const unsigned int lane = threadIdx.x % 32;
  const unsigned int before = __popc(active & ((1u << lane) - 1u));
  unsigned int base = 0;
  if (lane == static_cast<unsigned int>(leader)) base = atomicAdd(counter, static_cast<unsigned int>(__popc(active)));
  return __shfl_sync(active, base, leader) + before;
}

// rays[0]: path rays; rays[1]: shadow rays. next_pixel: 0 at launch.
template <uint32_t Kinds, class Scene>
__device__ __forceinline__ void megakernel_thread(const Scene& scene, const RenderParams& rp, int first_sample,
                                                  int samples, float* film, unsigned long long* rays,
                                                  unsigned int* next_pixel) {
  const uint32_t pixels = static_cast<uint32_t>(rp.width) * static_cast<uint32_t>(rp.height);
  const uint32_t first = static_cast<uint32_t>(first_sample), end = first + static_cast<uint32_t>(samples);
  uint32_t count = 0, shadow_count = 0;
  uint32_t pixel = take_next(next_pixel);
  if (pixel < pixels && samples > 0) {
    uint32_t sample = first;
    vec3 sum(0.0f);
    PathInFlight path = begin_path(scene, rp, pixel, sample);
    for (;;) {
      if (advance_path<Kinds>(scene, rp, pixel, sample, path, count, shadow_count)) continue;
      sum += path.radiance;
      if (++sample == end) {
        float* f = film + 3 * static_cast<size_t>(pixel);
        f[0] += sum.x;
        f[1] += sum.y;
        f[2] += sum.z;
        pixel = take_next(next_pixel);
        if (pixel >= pixels) break;
        sample = first;
        sum = vec3(0.0f);
      }
      path = begin_path(scene, rp, pixel, sample);
    }
  }
  // One atomic per warp, not per ray: every lane reaches this point. The warp's sum
  // is taken in 64 bits, since 32 lanes of a long pass can pass 2^32 rays.
  unsigned long long warp_total = count, warp_shadows = shadow_count;
  for (int offset = 16; offset > 0; offset /= 2) {
    warp_total += __shfl_down_sync(0xffffffffu, warp_total, offset);
    warp_shadows += __shfl_down_sync(0xffffffffu, warp_shadows, offset);
  }
  if (threadIdx.x % 32 == 0) {
    if (warp_total) atomicAdd(rays, warp_total);
    if (warp_shadows) atomicAdd(rays + 1, warp_shadows);
  }
}

// As many blocks as the GPU holds at once for `kernel`, and no more than the
// pixels need.
template <class Kernel>
inline dim3 megakernel_grid(Kernel kernel, const RenderParams& rp, const char* stage) {
  int device = 0, sms = 0, per_sm = 0;
  WT_CUDA(cudaGetDevice(&device), stage);
  WT_CUDA(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device), stage);
  WT_CUDA(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, kernel, kMegakernelThreads, 0), stage);
  const uint64_t pixels = static_cast<uint64_t>(rp.width) * static_cast<uint64_t>(rp.height);
  const uint64_t needed = (pixels + kMegakernelThreads - 1) / kMegakernelThreads;
  const uint64_t resident = static_cast<uint64_t>(sms) * static_cast<uint64_t>(per_sm > 0 ? per_sm : 1);
  return dim3(static_cast<unsigned int>(needed < resident ? needed : resident));
}

}  // namespace wt::cuda

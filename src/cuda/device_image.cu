#include "cuda/device_image.hpp"

#include <cuda_runtime.h>

#include <cub/block/block_reduce.cuh>
#include <iterator>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

#include "cuda/buffer.hpp"
#include "cuda/event.hpp"
#include "device/device.hpp"
#include "device/kernel_bodies.hpp"

namespace wt::cuda {

namespace {

constexpr const char* kFinish = "image finish";
constexpr const char* kHandOff = "image hand-off";
constexpr unsigned kBlock = 256;

// The mean of pixel i's film sums (times `inv`, take_mean's factor).
__device__ inline float3 pixel_mean(const float* film, size_t i, float inv) {
  return make_float3(film[3 * i] * inv, film[3 * i + 1] * inv, film[3 * i + 2] * inv);
}

// Thread per pixel: the block's count of pixels whose mean is not finite, added to
// `nonfinite`.
__global__ void __launch_bounds__(kBlock)
    count_nonfinite(const float* film, size_t pixels, float inv, unsigned long long* nonfinite) {
#if WT_KERNEL_BODIES
  using Reduce = cub::BlockReduce<unsigned, kBlock>;
  __shared__ typename Reduce::TempStorage temp;
  const size_t i = static_cast<size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  unsigned bad = 0;
  if (i < pixels) {
    const float3 m = pixel_mean(film, i, inv);
    bad = !(isfinite(m.x) && isfinite(m.y) && isfinite(m.z));
  }
  const unsigned block_bad = Reduce(temp).Sum(bad);
  if (threadIdx.x == 0 && block_bad != 0) atomicAdd(nonfinite, static_cast<unsigned long long>(block_bad));
#endif
}

// Thread per pixel: its mean as RGBA.
__global__ void __launch_bounds__(kBlock) write_means(const float* film, size_t pixels, float inv, float4* rgba) {
#if WT_KERNEL_BODIES
  const size_t i = static_cast<size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < pixels) {
    const float3 m = pixel_mean(film, i, inv);
    rgba[i] = make_float4(m.x, m.y, m.z, 1.0f);
  }
#endif
}

}  // namespace

struct ImageWriting {
  Event done;
  // An image let go unread is still written before its memory goes (freed, or back
  // to its pool to be written again); an error here surfaces at the next call.
  ~ImageWriting() { cudaEventSynchronize(done.get()); }
};

struct ImageFinisher::Kept {
  DeviceBuffer<unsigned long long> count{1, kFinish};
  PinnedBuffer<unsigned long long> told{1, kFinish};  // the count, brought back
  Stream beside{kFinish};
  Event film_done;  // the default stream's work on the film
};

ImageFinisher::ImageFinisher() : kept_(std::make_unique<Kept>()) {}
ImageFinisher::~ImageFinisher() = default;

void ImageFinisher::finish(const float* film, size_t pixels, int32_t samples, DeviceImage& image) {
  WT_CUDA(cudaGetDevice(&image.device), kFinish);
  float* rgba = image.rgba.get();
  if (rgba == nullptr && pixels > 0) throw std::logic_error("ImageFinisher: no memory for the image");
  // Page-locked host memory as the device addresses it (the same address where
  // addressing is unified, as on every 64-bit system).
  cudaPointerAttributes at{};
  WT_CUDA(cudaPointerGetAttributes(&at, rgba), kFinish);
  if (at.type == cudaMemoryTypeHost) {
    void* on_device = nullptr;
    WT_CUDA(cudaHostGetDevicePointer(&on_device, rgba, 0), kFinish);
    rgba = static_cast<float*>(on_device);
  }
  const float inv = 1.0f / static_cast<float>(samples);  // take_mean's factor
  const unsigned blocks = static_cast<unsigned>((pixels + kBlock - 1) / kBlock);
  // The count on its own stream, after the film's work, from the film in device
  // memory (a pass that reads it, not the bus); queued first and at a higher
  // priority, its blocks run ahead of the writing's.
  cudaStream_t beside = kept_->beside.get();
  kept_->film_done.record(kFinish);
  kept_->beside.wait_for(kept_->film_done, kFinish);
  WT_CUDA(cudaMemsetAsync(kept_->count.get(), 0, sizeof(unsigned long long), beside), kFinish);
  if (pixels > 0) {
    count_nonfinite<<<blocks, kBlock, 0, beside>>>(film, pixels, inv, kept_->count.get());
    WT_CUDA_LAUNCHED("count_nonfinite", kFinish);
  }
  WT_CUDA(cudaMemcpyAsync(kept_->told.get(), kept_->count.get(), sizeof(unsigned long long), cudaMemcpyDeviceToHost,
                          beside),
          kFinish);
  if (pixels > 0) {
    write_means<<<blocks, kBlock>>>(film, pixels, inv, reinterpret_cast<float4*>(rgba));
    WT_CUDA_LAUNCHED("write_means", kFinish);
    image.writing = std::make_shared<ImageWriting>();
    image.writing->done.record(kFinish);
  }
  // The count is read before the film can be written again: the caller's next work
  // on it is queued after this returns.
  kept_->beside.synchronize(kFinish);
  image.nonfinite_pixels = *kept_->told.get();
}

void DeviceImage::wait() {
  if (!writing) return;
  writing->done.synchronize(kHandOff);
  writing.reset();
}

struct ImageBlocks::Pool {
  std::mutex mutex;
  Memory memory = Memory::PageLocked;
  int device = 0;  // a device block's
  size_t keep = 0;
  int64_t allocations = 0;
  std::vector<std::pair<size_t, float*>> free;  // (floats, block), the last let go last

  void release(float* block) const {
    // As DeviceBuffer's: an error here surfaces at the next call.
    if (memory == Memory::PageLocked) {
      cudaFreeHost(block);
    } else {
      cudaFree(block);
    }
  }
  ~Pool() {
    for (const auto& block : free) release(block.second);
  }
};

ImageBlocks::ImageBlocks(Memory memory, size_t keep) : pool_(std::make_shared<Pool>()) {
  pool_->memory = memory;
  pool_->keep = keep;
  if (memory == Memory::Device) WT_CUDA(cudaGetDevice(&pool_->device), kHandOff);
}

std::shared_ptr<float> ImageBlocks::take(size_t floats) {
  float* block = nullptr;
  {
    std::lock_guard<std::mutex> lock(pool_->mutex);
    for (auto it = pool_->free.rbegin(); it != pool_->free.rend(); ++it) {
      if (it->first == floats) {
        block = it->second;
        pool_->free.erase(std::next(it).base());
        break;
      }
    }
  }
  const bool on_device = pool_->memory == Memory::Device;
  if (on_device) WT_CUDA(cudaSetDevice(pool_->device), kHandOff);
  if (block != nullptr && on_device) {
    // What a consumer queued before letting the block go is done before it is written
    // again (as freeing it would have waited for).
    WT_CUDA(cudaDeviceSynchronize(), kHandOff);
  }
  if (block == nullptr) {
    void* p = nullptr;
    const size_t bytes = floats * sizeof(float);
    if (on_device) {
      check_allocation(static_cast<int>(cudaMalloc(&p, bytes)), bytes, kHandOff);
    } else {
      // Mapped (the device writes it: ImageFinisher) and usable from every device.
      WT_CUDA(cudaHostAlloc(&p, bytes, cudaHostAllocMapped | cudaHostAllocPortable), kHandOff);
    }
    block = static_cast<float*>(p);
    std::lock_guard<std::mutex> lock(pool_->mutex);
    ++pool_->allocations;
  }
  // The pool outlives its blocks: each holds it.
  std::shared_ptr<Pool> pool = pool_;
  return std::shared_ptr<float>(block, [pool, floats](float* p) {
    std::lock_guard<std::mutex> lock(pool->mutex);
    pool->free.emplace_back(floats, p);
    if (pool->free.size() > pool->keep) {
      pool->release(pool->free.front().second);  // the block let go longest ago
      pool->free.erase(pool->free.begin());
    }
  });
}

int64_t ImageBlocks::allocations() const {
  std::lock_guard<std::mutex> lock(pool_->mutex);
  return pool_->allocations;
}

}  // namespace wt::cuda

#include "cuda/device_image.hpp"

#include <cuda_runtime.h>

#include <cub/block/block_reduce.cuh>
#include <mutex>
#include <utility>
#include <vector>

#include "cuda/buffer.hpp"
#include "device/device.hpp"
#include "device/kernel_bodies.hpp"

namespace wt::cuda {

namespace {

constexpr const char* kFinish = "image finish";
constexpr const char* kHandOff = "image hand-off";
constexpr unsigned kBlock = 256;

// Thread per pixel: its mean as RGBA, and the block's count of non-finite pixels
// added to `nonfinite`.
__global__ void __launch_bounds__(kBlock)
    finish_pixels(const float* film, size_t pixels, float inv, float4* rgba, unsigned long long* nonfinite) {
#if WT_KERNEL_BODIES
  using Reduce = cub::BlockReduce<unsigned, kBlock>;
  __shared__ typename Reduce::TempStorage temp;
  const size_t i = static_cast<size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  unsigned bad = 0;
  if (i < pixels) {
    const float r = film[3 * i] * inv, g = film[3 * i + 1] * inv, b = film[3 * i + 2] * inv;
    rgba[i] = make_float4(r, g, b, 1.0f);
    bad = !(isfinite(r) && isfinite(g) && isfinite(b));
  }
  const unsigned block_bad = Reduce(temp).Sum(bad);
  if (threadIdx.x == 0 && block_bad != 0) atomicAdd(nonfinite, static_cast<unsigned long long>(block_bad));
#endif
}

}  // namespace

DeviceImage finish_image(const float* film, size_t pixels, int32_t samples) {
  DeviceImage out;
  WT_CUDA(cudaGetDevice(&out.device), kFinish);
  const size_t bytes = pixels * 4 * sizeof(float);
  void* rgba = nullptr;
  check_allocation(static_cast<int>(cudaMalloc(&rgba, bytes)), bytes, kFinish);
  // Freed where the last owner lets go (a DLPack consumer's, maybe); an error there
  // surfaces at the next call, as DeviceBuffer's does.
  out.rgba = std::shared_ptr<float>(static_cast<float*>(rgba), [](float* p) { cudaFree(p); });
  DeviceBuffer<unsigned long long> count(1, kFinish);
  count.zero(kFinish);
  if (pixels > 0) {
    const float inv = 1.0f / static_cast<float>(samples);  // take_mean's factor
    finish_pixels<<<static_cast<unsigned>((pixels + kBlock - 1) / kBlock), kBlock>>>(
        film, pixels, inv, static_cast<float4*>(rgba), count.get());
    WT_CUDA_LAUNCHED("finish_pixels", kFinish);
  }
  unsigned long long nonfinite = 0;
  WT_CUDA(cudaMemcpy(&nonfinite, count.get(), sizeof(nonfinite), cudaMemcpyDeviceToHost), kFinish);
  out.nonfinite_pixels = nonfinite;
  return out;
}

struct PinnedImages::Pool {
  std::mutex mutex;
  size_t keep = 0;
  int64_t allocations = 0;
  std::vector<std::pair<size_t, float*>> free;  // (floats, block)
  ~Pool() {
    for (const auto& block : free) cudaFreeHost(block.second);
  }
};

PinnedImages::PinnedImages(size_t keep) : pool_(std::make_shared<Pool>()) { pool_->keep = keep; }

std::shared_ptr<float> PinnedImages::take(size_t floats) {
  float* block = nullptr;
  {
    std::lock_guard<std::mutex> lock(pool_->mutex);
    for (auto it = pool_->free.begin(); it != pool_->free.end(); ++it) {
      if (it->first == floats) {
        block = it->second;
        pool_->free.erase(it);
        break;
      }
    }
  }
  if (block == nullptr) {
    void* p = nullptr;
    WT_CUDA(cudaMallocHost(&p, floats * sizeof(float)), kHandOff);
    block = static_cast<float*>(p);
    std::lock_guard<std::mutex> lock(pool_->mutex);
    ++pool_->allocations;
  }
  // The pool outlives its blocks: each holds it.
  std::shared_ptr<Pool> pool = pool_;
  return std::shared_ptr<float>(block, [pool, floats](float* p) {
    std::lock_guard<std::mutex> lock(pool->mutex);
    if (pool->free.size() < pool->keep) {
      pool->free.emplace_back(floats, p);
    } else {
      cudaFreeHost(p);
    }
  });
}

int64_t PinnedImages::allocations() const {
  std::lock_guard<std::mutex> lock(pool_->mutex);
  return pool_->allocations;
}

std::shared_ptr<float> to_host(const DeviceImage& image, size_t floats, PinnedImages& memory) {
  std::shared_ptr<float> host = memory.take(floats);
  WT_CUDA(cudaMemcpy(host.get(), image.rgba.get(), floats * sizeof(float), cudaMemcpyDeviceToHost), kHandOff);
  return host;
}

}  // namespace wt::cuda

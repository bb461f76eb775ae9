// Owning device allocations, every call checked and named by stage.
#pragma once

#include <cuda_runtime.h>

#include <cstddef>
#include <utility>
#include <vector>

#include "device/device.hpp"

namespace wt::cuda {

template <class T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  DeviceBuffer(size_t n, const char* stage) { allocate(n, stage); }
  ~DeviceBuffer() { release(); }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  DeviceBuffer(DeviceBuffer&& o) noexcept : ptr_(std::exchange(o.ptr_, nullptr)), size_(std::exchange(o.size_, 0)) {}
  DeviceBuffer& operator=(DeviceBuffer&& o) noexcept {
    release();
    ptr_ = std::exchange(o.ptr_, nullptr);
    size_ = std::exchange(o.size_, 0);
    return *this;
  }

  void allocate(size_t n, const char* stage) {
    release();
    if (n == 0) return;
    check_allocation(static_cast<int>(cudaMalloc(reinterpret_cast<void**>(&ptr_), n * sizeof(T))), n * sizeof(T),
                     stage);
    size_ = n;
  }

  void upload(const std::vector<T>& host, const char* stage) {
    allocate(host.size(), stage);
    if (!host.empty()) WT_CUDA(cudaMemcpy(ptr_, host.data(), host.size() * sizeof(T), cudaMemcpyHostToDevice), stage);
  }

  std::vector<T> download(const char* stage) const {
    std::vector<T> host(size_);
    if (size_) WT_CUDA(cudaMemcpy(host.data(), ptr_, size_ * sizeof(T), cudaMemcpyDeviceToHost), stage);
    return host;
  }

  void zero(const char* stage, cudaStream_t stream = nullptr) {
    if (size_) WT_CUDA(cudaMemsetAsync(ptr_, 0, size_ * sizeof(T), stream), stage);
  }

  T* get() const { return ptr_; }
  size_t size() const { return size_; }

 private:
  void release() {
    if (ptr_) cudaFree(ptr_);  // freeing cannot be reported from a destructor; errors surface at the next call
    ptr_ = nullptr;
    size_ = 0;
  }
  T* ptr_ = nullptr;
  size_t size_ = 0;
};

// Page-locked host memory, which the GPU copies to at full speed. Made before it is
// needed: allocating it costs milliseconds.
template <class T>
class PinnedBuffer {
 public:
  PinnedBuffer(size_t n, const char* stage) : size_(n) {
    if (n) WT_CUDA(cudaMallocHost(reinterpret_cast<void**>(&ptr_), n * sizeof(T)), stage);
  }
  ~PinnedBuffer() {
    if (ptr_) cudaFreeHost(ptr_);  // as DeviceBuffer: errors surface at the next call
  }
  PinnedBuffer(const PinnedBuffer&) = delete;
  PinnedBuffer& operator=(const PinnedBuffer&) = delete;

  // Copies `device` (size() values) here and waits for it.
  void download(const T* device, const char* stage) {
    if (size_) WT_CUDA(cudaMemcpy(ptr_, device, size_ * sizeof(T), cudaMemcpyDeviceToHost), stage);
  }
  const T* get() const { return ptr_; }
  T* get() { return ptr_; }
  size_t size() const { return size_; }

 private:
  T* ptr_ = nullptr;
  size_t size_ = 0;
};

}  // namespace wt::cuda

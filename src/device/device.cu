#include "device/device.hpp"

#include <cuda_runtime.h>

namespace wt::cuda {

int device_count() {
#if defined(WT_NO_DEVICE_CODE)
  return 0;  // a host-only build (device/kernel_bodies.hpp): its kernels do nothing
#endif
  int n = 0;
  if (cudaGetDeviceCount(&n) != cudaSuccess) {
    cudaGetLastError();  // clear the sticky "no device" error
    return 0;
  }
  return n;
}

void require_cuda_devices(const std::vector<int>& devices, int present) {
  for (int d : devices) {
    if (d < 0 || d >= present) {
      throw InputError("devices: " + std::to_string(d) + " is not a CUDA device (" + std::to_string(present) +
                       " present)");
    }
  }
}

namespace {

std::string error_text(cudaError_t err) {
  return std::string(cudaGetErrorName(err)) + " (" + cudaGetErrorString(err) + ")";
}

std::string mib(size_t bytes) { return std::to_string((bytes + (1 << 20) - 1) >> 20) + " MiB"; }

}  // namespace

void start_context(int device) {
  if (device_count() <= device) return;
  if (cudaSetDevice(device) != cudaSuccess || cudaFree(nullptr) != cudaSuccess) cudaGetLastError();
}

void check(int code, const char* call, const char* stage) {
  if (code == cudaSuccess) return;
  auto err = static_cast<cudaError_t>(code);
  cudaGetLastError();  // reported here: a later launch check must not report it again
  // Device allocations say which (check_allocation); this is any call that ran out, host pinned memory too.
  const char* what = err == cudaErrorMemoryAllocation ? ": out of memory: " : ": ";
  throw CudaError(std::string(stage) + what + call + " failed: " + error_text(err));
}

void load_kernel(const void* kernel, const char* stage) {
  cudaFuncAttributes attributes{};
  WT_CUDA(cudaFuncGetAttributes(&attributes, kernel), stage);
}

void check_allocation(int code, size_t bytes, const char* stage) {
  if (code == cudaErrorMemoryAllocation) {
    cudaGetLastError();
    throw CudaError(std::string(stage) + ": out of device memory: allocating " + mib(bytes) + " failed: " +
                    error_text(cudaErrorMemoryAllocation));
  }
  check(code, "cudaMalloc", stage);
}

Recovery recover_after_error() {
  if (device_count() == 0) return Recovery::Clean;
  cudaGetLastError();  // an error of the failed call that did not poison the context
  // A poisoned context answers every call with its error, and the wait also brings
  // out a fault of work still queued.
  cudaError_t err = cudaDeviceSynchronize();
  if (err == cudaSuccess) err = cudaGetLastError();
  return err == cudaSuccess ? Recovery::Clean : Recovery::Lost;
}

DeviceInfo device_info() {
  DeviceInfo info;
  int dev = 0;
  WT_CUDA(cudaGetDevice(&dev), "device query");
  cudaDeviceProp prop{};
  WT_CUDA(cudaGetDeviceProperties(&prop, dev), "device query");
  info.name = prop.name;
  info.sm_count = prop.multiProcessorCount;
  WT_CUDA(cudaDeviceGetAttribute(&info.sm_clock_khz, cudaDevAttrClockRate, dev), "device query");
  WT_CUDA(cudaDeviceGetAttribute(&info.memory_clock_khz, cudaDevAttrMemoryClockRate, dev), "device query");
  WT_CUDA(cudaDriverGetVersion(&info.driver_version), "device query");
  WT_CUDA(cudaRuntimeGetVersion(&info.runtime_version), "device query");
  WT_CUDA(cudaMemGetInfo(&info.free_memory, &info.total_memory), "device query");
  return info;
}

}  // namespace wt::cuda

#include "cuda/device.hpp"

#include <cuda_runtime.h>

namespace wt::cuda {

int device_count() {
  int n = 0;
  if (cudaGetDeviceCount(&n) != cudaSuccess) {
    cudaGetLastError();  // clear the sticky "no device" error
    return 0;
  }
  return n;
}

void check(int code, const char* call, const char* stage) {
  if (code == cudaSuccess) return;
  auto err = static_cast<cudaError_t>(code);
  throw CudaError(std::string(stage) + ": " + call + " failed: " + cudaGetErrorName(err) + " (" +
                  cudaGetErrorString(err) + ")");
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

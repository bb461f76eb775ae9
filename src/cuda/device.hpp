// The CUDA device as the rest of the program sees it, and the error check that
// every CUDA call and launch goes through.
#pragma once

#include <cstddef>
#include <string>

#include "render/errors.hpp"

namespace wt::cuda {

// A failed CUDA call or launch: a failure of the device, not of the input.
struct CudaError : DeviceError {
  using DeviceError::DeviceError;
};

// Number of usable CUDA devices; 0 where there is no driver or no device.
int device_count();

struct DeviceInfo {
  std::string name;
  int sm_count = 0;
  int sm_clock_khz = 0;
  int memory_clock_khz = 0;
  int driver_version = 0;
  int runtime_version = 0;
  size_t total_memory = 0;
  size_t free_memory = 0;
};

DeviceInfo device_info();

// Throws CudaError "<stage>: <call> failed: <error>" when code is not cudaSuccess;
// for a call that ran out of memory, "<stage>: out of memory: <call> failed: ...".
void check(int code, const char* call, const char* stage);

// A device allocation of `bytes`: the same, with the size when the device is out of memory.
void check_allocation(int code, size_t bytes, const char* stage);

enum class Recovery {
  Clean,  // the context was usable: any error left by the failed call is cleared
  Reset,  // the context was poisoned (a sticky error: an illegal address, a kernel that
          // faulted) and the device was reset, freeing all this process held on it
};

// After a job failed with a DeviceError, makes the device fit for the next job. A
// reset destroys every allocation, stream and event of the process on the device:
// call it only when nothing of the failed job is still held. Throws CudaError when the
// device is still unusable after the reset.
Recovery recover_after_error();

}  // namespace wt::cuda

#define WT_CUDA(call, stage) ::wt::cuda::check(static_cast<int>(call), #call, stage)
// After a kernel launch: launch-configuration errors now, execution errors at the next sync.
#define WT_CUDA_LAUNCHED(kernel, stage) ::wt::cuda::check(static_cast<int>(cudaGetLastError()), kernel " launch", stage)

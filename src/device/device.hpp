// The CUDA device as the rest of the program sees it, and the error check that
// every CUDA call and launch goes through.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "errors/errors.hpp"

namespace wt::cuda {

// A failed CUDA call or launch: a failure of the device, not of the input.
struct CudaError : DeviceError {
  using DeviceError::DeviceError;
};

// Number of usable CUDA devices; 0 where there is no driver or no device.
int device_count();

// Throws InputError naming the first index that is not one of the `present` CUDA
// devices (0..present-1): the one check of a device list, from the command line or
// from a caller's options.
void require_cuda_devices(const std::vector<int>& devices, int present);

// Starts the CUDA runtime and the current device's context, which takes a good
// part of a second, so that it can run while a scene loads. Quiet where there is no
// device: the render that needs one says so.
// `device`: the device whose context to start (the first the job renders on).
void start_context(int device = 0);

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

// Loads a kernel's code on the current device now. CUDA loads each kernel at its
// first launch (lazy loading); a render loads the kernels it times before its timer
// starts, so that the first render of a process times the render alone.
void load_kernel(const void* kernel, const char* stage);

enum class Recovery {
  Clean,  // the context was usable: any error left by the failed call is cleared
  Lost,   // the context is poisoned (a sticky error: an illegal address, a kernel that
          // faulted): every later CUDA call of this process fails; only a new process
          // gets a clean context (cudaDeviceReset does not bring it back: on the H100
          // every call after it fails with cudaErrorDevicesUnavailable)
};

// After a job failed with a DeviceError, finds out whether the device can run the next
// job in this process, and clears an error that did not poison the context.
Recovery recover_after_error();

// What a job that met a sticky error adds to its line.
inline constexpr const char* kContextLost =
    "the CUDA context of this process cannot be recovered (a sticky error; a new process gets a clean one)";

}  // namespace wt::cuda

#define WT_CUDA(call, stage) ::wt::cuda::check(static_cast<int>(call), #call, stage)
// After a kernel launch: launch-configuration errors now, execution errors at the next sync.
#define WT_CUDA_LAUNCHED(kernel, stage) ::wt::cuda::check(static_cast<int>(cudaGetLastError()), kernel " launch", stage)

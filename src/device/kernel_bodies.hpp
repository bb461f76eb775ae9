// Whether this compilation emits the kernels' bodies as device code. It does, but in
// a host-only build (CMake's WAVETRACE_DEVICE_CODE=OFF: the sanitizer build), where
// the device pass compiles every kernel with an empty body: the device compiler then
// has next to nothing to do, the host code (what the sanitizers check) is compiled in
// full, and the CUDA backend reports no device (device_count), so the GPU tests skip
// as they do without a GPU. Each __global__ function's body is wrapped in
// `#if WT_KERNEL_BODIES`.
#pragma once

#if defined(WT_NO_DEVICE_CODE) && defined(__CUDA_ARCH__)
#define WT_KERNEL_BODIES 0
#else
#define WT_KERNEL_BODIES 1
#endif

#!/usr/bin/env bash
# Sourced by the build scripts: the CUDA architectures to build device code for, in
# $cuda_arch, and whether to optimize it, in $cuda_opt. $WAVETRACE_CUDA_ARCH where it is
# set; else 90 (the H100 and H200's machine code) where this machine has an NVIDIA GPU;
# else 90-virtual: the device code compiled to PTX only. That is still compiled and
# checked, but skips ptxas, which takes most of a CUDA file's time (the megakernel's:
# 128 s instead of 437 s on a 2-core machine): CI and the CPU backend have no GPU to run
# machine code on. A PTX-only binary that meets a GPU later still runs there, after the
# driver compiles the PTX on first use (minutes, then cached); scripts/gpu-build.sh
# builds machine code for the GPU machine. PTX alone is compiled to check it, with
# NVVM's optimizer off (WAVETRACE_DEVICE_OPT, CMakeLists.txt: the megakernel's PTX in
# 35 s instead of 141 s), so such a binary on a GPU runs slower still; machine code is
# optimized. WAVETRACE_CUDA_OPT=ON|OFF chooses otherwise.
if [[ -n ${WAVETRACE_CUDA_ARCH:-} ]]; then
  cuda_arch=$WAVETRACE_CUDA_ARCH
elif command -v nvidia-smi >/dev/null 2>&1 && nvidia-smi -L >/dev/null 2>&1; then
  cuda_arch=90
else
  cuda_arch=90-virtual
fi
if [[ -n ${WAVETRACE_CUDA_OPT:-} ]]; then
  cuda_opt=$WAVETRACE_CUDA_OPT
elif [[ $cuda_arch == *-virtual ]]; then
  cuda_opt=OFF
else
  cuda_opt=ON
fi
# Configures build folder $1 for $cuda_arch and $cuda_opt where it is configured
# otherwise.
cuda_arch_configure() {
  local cached cached_opt
  cached=$(sed -n 's/^CMAKE_CUDA_ARCHITECTURES:[A-Z]*=//p' "$1/CMakeCache.txt" 2>/dev/null || true)
  cached_opt=$(sed -n 's/^WAVETRACE_DEVICE_OPT:[A-Z]*=//p' "$1/CMakeCache.txt" 2>/dev/null || true)
  if [[ $cached != "$cuda_arch" || $cached_opt != "$cuda_opt" ]]; then
    cmake -S "$root" -B "$1" -DCMAKE_CUDA_ARCHITECTURES="$cuda_arch" -DWAVETRACE_DEVICE_OPT="$cuda_opt" >/dev/null
  fi
}

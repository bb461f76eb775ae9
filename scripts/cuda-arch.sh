#!/usr/bin/env bash
# Sourced by the build scripts: the CUDA architectures to build device code for, in
# $cuda_arch. $WAVETRACE_CUDA_ARCH where it is set; else 90 (the H100 and H200's
# machine code) where this machine has an NVIDIA GPU; else 90-virtual: the device
# code compiled to PTX only. That is still compiled and checked, but skips ptxas,
# which takes most of a CUDA file's time (the megakernel's: 128 s instead of 437 s
# on a 2-core machine): CI and the CPU backend have no GPU to run machine code on.
# A PTX-only binary that meets a GPU later still runs there, after the driver
# compiles the PTX on first use (minutes, then cached); scripts/gpu-build.sh builds
# machine code for the GPU machine.
if [[ -n ${WAVETRACE_CUDA_ARCH:-} ]]; then
  cuda_arch=$WAVETRACE_CUDA_ARCH
elif command -v nvidia-smi >/dev/null 2>&1 && nvidia-smi -L >/dev/null 2>&1; then
  cuda_arch=90
else
  cuda_arch=90-virtual
fi
# Configures build folder $1 for $cuda_arch where it is configured for another.
cuda_arch_configure() {
  local cached
  cached=$(sed -n 's/^CMAKE_CUDA_ARCHITECTURES:[A-Z]*=//p' "$1/CMakeCache.txt" 2>/dev/null || true)
  if [[ $cached != "$cuda_arch" ]]; then
    cmake -S "$root" -B "$1" -DCMAKE_CUDA_ARCHITECTURES="$cuda_arch" >/dev/null
  fi
}

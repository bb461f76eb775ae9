#!/usr/bin/env bash
# Installs what is missing, then configures and builds wavetrace into build/
# (or $WAVETRACE_BUILD): every target, or only those named (scripts/wavetrace names
# `wavetrace`, so the first render builds no test).
#   scripts/build.sh [TARGET...]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${WAVETRACE_BUILD:-$root/build}
bash "$root/scripts/setup.sh"
source "$root/scripts/cuda-arch.sh"
if [[ ! -f "$build/build.ninja" ]]; then
  # The Python module is built for Debian's Python, whose numpy and pytest setup.sh
  # installs (WAVETRACE_PYTHON_EXE: another).
  python_exe=${WAVETRACE_PYTHON_EXE:-/usr/bin/python3}
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CUDA_ARCHITECTURES="$cuda_arch" \
    -DWAVETRACE_DEVICE_OPT="$cuda_opt" \
    ${python_exe:+-DPython_EXECUTABLE="$python_exe"} >/dev/null
fi
cuda_arch_configure "$build"
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build "$build" --parallel "$(nproc)" "${targets[@]}"

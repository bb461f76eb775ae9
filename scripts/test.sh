#!/usr/bin/env bash
# Builds wavetrace and runs the whole test suite. GPU tests skip where no CUDA
# device is present, and say so.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${WAVETRACE_BUILD:-$root/build}
bash "$root/scripts/build.sh"
cd "$build"
ctest --output-on-failure --parallel "$(nproc)"

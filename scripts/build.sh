#!/usr/bin/env bash
# Installs what is missing, then configures and builds wavetrace into build/
# (or $WAVETRACE_BUILD). Quiet when there is nothing to do.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${WAVETRACE_BUILD:-$root/build}
bash "$root/scripts/setup.sh"
if [[ ! -f "$build/build.ninja" ]]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
cmake --build "$build" --parallel "$(nproc)" | grep -v -E '^\[[0-9]+/[0-9]+\] (Building|Linking)' || true
test -x "$build/wavetrace"

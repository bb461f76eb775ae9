#!/usr/bin/env bash
# Runs binaries built elsewhere on a GPU machine that cannot build: every test
# binary in the folder, then a short render of the reference scene with each GPU
# kernel; prints one summary line. Run from anywhere; test data is found relative
# to the repository root, and nothing here depends on paths of the build machine.
#   scripts/gpu-check.sh BIN_DIR [OUT_DIR]
set -uo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=$(cd "${1:?usage: gpu-check.sh BIN_DIR [OUT_DIR]}" && pwd)
out=${2:-$root/out/gpu-check}
mkdir -p "$out"
cd "$root"
export WAVETRACE_ROOT="$root"

passed=0 failed=0 skipped=0 broken=()
for t in "$bin"/*_tests; do
  [[ -x "$t" ]] || continue
  log="$out/$(basename "$t").log"
  "$t" --gtest_brief=0 >"$log" 2>&1
  rc=$?
  p=$(grep -oP '^\[  PASSED  \] \K[0-9]+' "$log" | tail -1)
  f=$(grep -oP '^\[  FAILED  \] \K[0-9]+(?= tests?, listed below)' "$log" | tail -1)
  s=$(grep -oP '^\[  SKIPPED \] \K[0-9]+(?= tests?,)' "$log" | tail -1)
  passed=$((passed + ${p:-0})) failed=$((failed + ${f:-0})) skipped=$((skipped + ${s:-0}))
  if ((rc != 0)); then
    broken+=("$(basename "$t")")
    grep -E '^\[  FAILED  \]' "$log" | sort -u
  fi
done

renders=0 render_failed=0
# The kernel list is the command's own; a binary that cannot list them fails a render.
kernels=$("$bin/wavetrace" kernels --backend cuda) || render_failed=$((render_failed + 1))
for kernel in $kernels; do
  if "$bin/wavetrace" render scenes/seed57.json -o "$out/seed57-$kernel.png" --width 640 --height 360 --spp 16 \
    --backend cuda --kernel "$kernel" --stats "$out/seed57-$kernel.json" -q; then
    renders=$((renders + 1))
  else
    render_failed=$((render_failed + 1))
  fi
done

echo "gpu-check: ${passed} passed, ${failed} failed, ${skipped} skipped; renders: ${renders} ok, ${render_failed} failed${broken:+; failing binaries: ${broken[*]}}"
((failed == 0 && render_failed == 0 && ${#broken[@]} == 0))

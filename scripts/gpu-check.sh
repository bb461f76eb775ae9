#!/usr/bin/env bash
# Runs binaries built elsewhere on a GPU machine that cannot build: every test
# binary in the folder, then a short render of the reference scene with each GPU
# kernel; prints one summary line. Run from anywhere; test data is found relative
# to the repository root, and nothing here depends on paths of the build machine.
# With --sanitize it then runs every test binary and a short render of each GPU
# kernel under compute-sanitizer's memcheck, racecheck, synccheck and initcheck,
# and fails on any error they report.
#   scripts/gpu-check.sh [--sanitize] BIN_DIR [OUT_DIR]
set -uo pipefail
sanitize=0
if [[ "${1:-}" == --sanitize ]]; then
  sanitize=1
  shift
fi
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=$(cd "${1:?usage: gpu-check.sh [--sanitize] BIN_DIR [OUT_DIR]}" && pwd)
out=${2:-$root/out/gpu-check}
mkdir -p "$out"
cd "$root"
export WAVETRACE_ROOT="$root"

# The glTF tiles, for the tests that read the generator's files (WAVETRACE_TILES).
if [[ -x "$bin/wavetrace-gltf-tiles" ]] && "$bin/wavetrace-gltf-tiles" "$out/tiles" >/dev/null; then
  export WAVETRACE_TILES="$out/tiles"
fi

passed=0 failed=0 skipped=0 broken=()
for t in "$bin"/*_tests; do
  [[ -x "$t" ]] || continue
  log="$out/$(basename "$t").log"
  # Test binaries that drive the command itself take its path; the others ignore it.
  "$t" --gtest_brief=0 "$bin/wavetrace" >"$log" 2>&1
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

sanitized="" sanitizer_errors=0 n=0
if ((sanitize)); then
  for tool in memcheck racecheck synccheck initcheck; do
    errors=0
    runs=()
    # The GPU tests of the test binary: the sanitizers check device code only. Left
    # out: the test that sends itself SIGTERM (compute-sanitizer takes the signal for
    # its own), the device-fault tests (their kernel faults on purpose) and the
    # 500-job soak (hours under the tools; the command's own renders below stand in).
    # Under racecheck also the split that names one GPU twice: two host threads
    # launching into one device do not finish there (memcheck, synccheck and
    # initcheck run it). Left out too: the converged-reference tests (16 renders of
    # eight scenes per kernel and setting, tens of minutes under the tools; their
    # kernels are the ones the other GPU tests and the renders below run).
    skip='*Sigterm*:Soak.*:DeviceFaults.*:*ConvergedReference*'
    [[ $tool == racecheck ]] && skip+=':Split.OneGpuTwice*'
    for t in "$bin"/wavetrace_tests; do
      [[ -x "$t" ]] && runs+=("$t --gtest_brief=1 --gtest_filter=*cuda*:*Cuda*:*Gpu*:*Constant*:-$skip")
    done
    for kernel in $kernels; do
      runs+=("$bin/wavetrace render scenes/seed57.json -o $out/sanitize-$kernel.png --width 160 --height 90 --spp 4 --backend cuda --kernel $kernel -q")
    done
    for run in "${runs[@]}"; do
      log="$out/sanitize-$tool-$(basename "${run%% *}")-$((++n)).log"
      # shellcheck disable=SC2086
      compute-sanitizer --tool "$tool" --error-exitcode 99 $run >"$log" 2>&1
      rc=$?
      # racecheck sums up as "RACECHECK SUMMARY: N hazards displayed (E errors, W warnings)".
      e=$(grep -oP '(ERROR SUMMARY: \K[0-9]+|RACECHECK SUMMARY: .*\(\K[0-9]+(?= errors))' "$log" | tail -1)
      if [[ -z "$e" ]] || ((rc == 99)); then
        e=${e:-1}
        echo "sanitize $tool: $run: $(grep -m3 -E '^========= (Invalid|Uninitialized|Race|Barrier|Error|Program hit)' "$log" | tr '\n' ' ')"
      fi
      errors=$((errors + e))
    done
    sanitized+="${sanitized:+, }$tool $errors"
    sanitizer_errors=$((sanitizer_errors + errors))
  done
  sanitized="; compute-sanitizer errors: $sanitized"
fi

echo "gpu-check: ${passed} passed, ${failed} failed, ${skipped} skipped; renders: ${renders} ok, ${render_failed} failed${broken:+; failing binaries: ${broken[*]}}${sanitized}"
((failed == 0 && render_failed == 0 && ${#broken[@]} == 0 && sanitizer_errors == 0))

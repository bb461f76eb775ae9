#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan) into build-fuzz/ and fuzzes each
# in turn, then merges what found new coverage into its corpus, fuzz/corpus/<target>.
# A crash, leak, hang or sanitizer report stops that target, leaves the input as
# build-fuzz/artifacts/<target>/crash-* (or leak-*, timeout-*, oom-*) and fails.
#   scripts/fuzz.sh [TARGET...]     (default: scene jobs image mesh)
#   FUZZ_SECONDS  time per target (default 600)
#   FUZZ_RUNS     executions per target, stopping at whichever comes first (default: no limit)
# Run it under `nice -n 19` on a shared machine.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${WAVETRACE_FUZZ_BUILD:-$root/build-fuzz}
seconds=${FUZZ_SECONDS:-600}
targets=("$@")
((${#targets[@]})) || targets=(scene jobs image mesh)

WAVETRACE_WITH_FUZZ=1 bash "$root/scripts/setup.sh"
export ASAN_SYMBOLIZER_PATH=/usr/lib/llvm-19/bin/llvm-symbolizer
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1:suppressions=$root/fuzz/ubsan.supp
if [[ ! -f "$build/build.ninja" ]]; then
  CC=clang-19 CXX=clang++-19 cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DWAVETRACE_FUZZ=ON >/dev/null
fi
cmake --build "$build" --parallel "$(nproc)" --target "${targets[@]/#/fuzz_}"

status=0
for t in "${targets[@]}"; do
  corpus=$root/fuzz/corpus/$t
  found=$build/found/$t
  artifacts=$build/artifacts/$t
  mkdir -p "$corpus" "$found" "$artifacts"
  options=(-max_total_time="$seconds" -timeout=10 -print_final_stats=1 -artifact_prefix="$artifacts/")
  [[ -n "${FUZZ_RUNS:-}" ]] && options+=(-runs="$FUZZ_RUNS")
  # The parsers read JSON: give libFuzzer the keys. Images are binary.
  [[ "$t" != image ]] && options+=(-dict="$root/fuzz/json.dict")
  log=$build/fuzz-$t.log
  echo "fuzz.sh: $t for ${seconds}s${FUZZ_RUNS:+ or $FUZZ_RUNS runs}; log: $log" >&2
  # New inputs go to $found; the committed corpus is only read.
  if ! "$build/fuzz/fuzz_$t" "${options[@]}" "$found" "$corpus" >"$log" 2>&1; then
    status=1
    echo "fuzz.sh: $t FAILED; the input is in $artifacts" >&2
  fi
  grep -E '^#[0-9]+ +DONE|^stat::number_of_executed_units|^SUMMARY' "$log" >&2 || true
  # Keep the corpus lean: add the fewest inputs that reach code it does not (edges
  # only: hit counts would keep hundreds of near copies).
  "$build/fuzz/fuzz_$t" -set_cover_merge=1 -use_counters=0 -timeout=10 "$corpus" "$found" 2>&1 |
    grep -E '^MERGE-OUTER: [0-9]+ new files' >&2 || true
done
exit $status

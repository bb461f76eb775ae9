#!/usr/bin/env bash
# Mutation testing: runs the CPU suite once with no mutant (it must pass), then once
# with each deliberate bug of include/wavetrace/mutant.hpp compiled in, and prints
# the table: mutant, then the tests that failed with it (killed it). Fails if any
# mutant is left alive, or if the suite fails without one.
#   scripts/mutants.sh [--build DIR] [--only NAME[,NAME...]] [--tests REGEX] [--no-baseline]
# --tests runs only the ctest tests that REGEX matches (ctest -R): CI names the
# tests that kill its two mutants (docs/testing.md's table), at a fraction of the
# suite's time.
# The build (default build-mutants/, or $WAVETRACE_MUTANT_BUILD) is configured with
# -DWAVETRACE_MUTANTS=ON; the mutant is chosen at run time by WAVETRACE_MUTANT, so
# one build serves them all. CI runs the two cheapest (docs/testing.md) in the
# sanitizer build, which is configured with mutants too.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${WAVETRACE_MUTANT_BUILD:-$root/build-mutants}
only="" baseline=1 select=()
while (($#)); do
  case "$1" in
    --build) build=$2; shift 2 ;;
    --only) only=$2; shift 2 ;;
    --no-baseline) baseline=0; shift ;;
    --tests) select=(-R "$2"); shift 2 ;;
    *) echo "usage: mutants.sh [--build DIR] [--only NAME[,NAME...]] [--tests REGEX] [--no-baseline]" >&2; exit 2 ;;
  esac
done
# The mutants, as WAVETRACE_MUTANT names them (mutant.hpp's WT_MUTANT_LIST).
all=$(grep -oP '^\s*X\(\w+, "\K[^"]+' "$root/include/wavetrace/mutant.hpp")
mutants=${only:+$(tr ',' '\n' <<<"$only")}
mutants=${mutants:-$all}
for m in $mutants; do
  grep -qxF -- "$m" <<<"$all" || { echo "mutants.sh: unknown mutant '$m' (known: $(echo $all))" >&2; exit 2; }
done

if [[ ! -f "$build/build.ninja" ]]; then
  bash "$root/scripts/setup.sh"
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DWAVETRACE_MUTANTS=ON >/dev/null
fi
grep -q '^WAVETRACE_MUTANTS:BOOL=ON' "$build/CMakeCache.txt" || {
  echo "mutants.sh: $build is not configured with -DWAVETRACE_MUTANTS=ON" >&2
  exit 2
}
cmake --build "$build" --parallel "$(nproc)"
cd "$build"

# The failed tests of the last ctest run, one name a line (without the parameter
# comment gtest_discover_tests appends).
failed_tests() {
  sed -n 's/^[0-9]*:\(.*\)$/\1/p' Testing/Temporary/LastTestsFailed.log 2>/dev/null | sed 's/  #.*//' | sort
}
run_suite() {
  rm -f Testing/Temporary/LastTestsFailed.log
  local start=$SECONDS
  local name=${1:-baseline}
  WAVETRACE_MUTANT=$1 ctest --parallel "$(nproc)" --timeout 600 "${select[@]}" >"$log_dir/${name//\//-}.log" 2>&1 || true
  elapsed=$((SECONDS - start))
}
log_dir=$build/mutants
rm -rf "$log_dir"
mkdir -p "$log_dir"

if ((baseline)); then
  run_suite ""
  if [[ -n "$(failed_tests)" ]]; then
    echo "mutants.sh: the suite fails with no mutant; the table would mean nothing:" >&2
    failed_tests >&2
    exit 1
  fi
  echo "no mutant: every test passed (${elapsed} s)"
fi

survivors=0
printf '%s\n' "| mutant | tests that killed it | killed by | seconds |" "|---|---|---|---|"
for m in $mutants; do
  run_suite "$m"
  # The first six by name, and how many more (the log has them all).
  n=$(failed_tests | wc -l)
  killers=$(failed_tests | head -6 | paste -sd, - | sed 's/,/, /g')
  ((n > 6)) && killers+=", and $((n - 6)) more"
  if ((n == 0)); then
    killers="**none: it lives**"
    survivors=$((survivors + 1))
  fi
  printf '| %s | %s | %s | %s |\n' "$m" "$killers" "$n" "$elapsed"
done
echo "logs: $log_dir"
if ((survivors)); then
  echo "mutants.sh: $survivors mutant(s) survived" >&2
  exit 1
fi

#!/usr/bin/env bash
# The whole benchmark on a CUDA machine, in one command: the grid of bench/study.json
# (each kernel's image checked against the megakernel's before it is timed), the
# Nsight Compute profiles, and the plots and tables, all under bench/results/.
#   scripts/bench.sh [BIN_DIR]     (default: build/, built first by scripts/build.sh)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
if [[ $# -eq 0 ]]; then
  bash "$root/scripts/build.sh"
fi
bin=${1:-${WAVETRACE_BUILD:-$root/build}}
results=${WAVETRACE_RESULTS:-$root/bench/results}
cd "$root"
commit=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["commit"])' "$bin/build-info.json" 2>/dev/null ||
  git rev-parse HEAD 2>/dev/null || echo unknown)
# A point that fails its image check is recorded as a failure; the profiles and
# plots still run, and the exit code says that something failed.
status=0
"$bin/wavetrace" bench bench/study.json -o "$results" --commit "$commit" || status=$?
bash scripts/profile.sh "$bin" "$results" || status=$?
python3 bench/profile_summary.py "$results" >/dev/null || status=$?
# PYTHON: an interpreter with matplotlib (Debian's python3-matplotlib is /usr/bin/python3's).
"${PYTHON:-python3}" bench/plot.py "$results/results.json" --out "$results" || status=$?
exit $status

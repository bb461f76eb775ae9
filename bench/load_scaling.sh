#!/usr/bin/env bash
# Scene loading against scene size: generates scenes of N random spheres
# (tools/make_spheres.py) and prints the load phases that `render --stats`
# records, plus the whole command's wall time, for each N. Not a test: a
# benchmark point, quoted in bench/RESULTS.md.
#   bench/load_scaling.sh [BIN_DIR] [N ...]     (default: 10000 100000 300000 1000000)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=${1:-$root/build}
shift || true
sizes=("$@")
((${#sizes[@]})) || sizes=(10000 100000 300000 1000000)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

printf '%9s %8s %9s %9s %9s %12s %10s\n' spheres parse validate bvh_build sum "us/sphere" "command"
for n in "${sizes[@]}"; do
  python3 "$root/tools/make_spheres.py" "$n" -o "$tmp/s.json" >/dev/null
  start=$(date +%s.%N)
  "$bin/wavetrace" render "$tmp/s.json" -o "$tmp/o.png" --width 8 --height 8 --spp 1 --depth 2 --backend cpu \
    --stats "$tmp/stats.json" -q 2>/dev/null
  end=$(date +%s.%N)
  python3 - "$tmp/stats.json" "$n" "$start" "$end" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))["load_seconds"]
n = int(sys.argv[2])
total = t["parse"] + t["validate"] + t["bvh_build"]
print("%9d %8.3f %9.3f %9.3f %9.3f %12.2f %10.2f" % (n, t["parse"], t["validate"], t["bvh_build"], total,
      total / n * 1e6, float(sys.argv[4]) - float(sys.argv[3])))
PY
done

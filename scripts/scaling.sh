#!/usr/bin/env bash
# The scaling benchmark (issue 10, item 5) on a CUDA machine, in one command: every
# kernel's throughput against resolution (seed57, 320x180 to 3840x2160, 128 spp),
# samples per pixel (seed57, 1920x1080, 1 to 4096 spp) and scene size (10 to 10^6
# spheres, 10 to 10^7 triangles), then the tables and a plot.
#   scripts/scaling.sh BIN_DIR [OUT_DIR [GROUP ...]]
# BIN_DIR holds wavetrace (e.g. .gpu/bin); OUT_DIR defaults to bench/results/scaling.
# GROUPs (resolution, spp, spheres-1e3, triangles-1e7, ...) run only those; the
# tables are still made from every group's results in OUT_DIR.
# Needs python3 (standard library only) and bash; no network, no other packages.
# SCALING_SPHERES_1E7=1 (or naming the group spheres-1e7) also writes and times 10^7
# spheres (bench/scaling-size-1e7.json: a 0.75 GB scene file, ~20 s to write and
# 40-60 s to load on the H100's host, for its one point).
#
# Each group runs as a `wavetrace bench --only GROUP` of its own into OUT_DIR/GROUP/
# (results.json, results.csv, bench.log): a bench that dies (out of memory at 10^7)
# loses only its group. OUT_DIR/timings.tsv has each group's wall time and exit code;
# OUT_DIR/tables.md and OUT_DIR/scaling.svg come from bench/scaling_tables.py.
# The exit code is 0 when every point ran or was refused for constant memory
# (megakernel-constant holds scenes up to 63 KiB: the small ones only).
# Expected on an H100: about 2.5 minutes of device time (a minute more with 10^7
# spheres); the spp series' 4096-spp point alone is ~40 s (5 kernels x 4 renders).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=$(cd "${1:?usage: scripts/scaling.sh BIN_DIR [OUT_DIR [GROUP ...]]}" && pwd)
out=${2:-$root/bench/results/scaling}
shift $(( $# < 2 ? $# : 2 ))
only=("$@")
mkdir -p "$out"
out=$(cd "$out" && pwd)
cd "$root"
[[ -x "$bin/wavetrace" ]] || { echo "scaling: no $bin/wavetrace" >&2; exit 2; }
commit=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["commit"])' "$bin/build-info.json" 2>/dev/null ||
  git rev-parse HEAD 2>/dev/null || echo unknown)

# The groups to run, spec by spec ("SPEC GROUP" a line). The 10^7 spheres run where
# SCALING_SPHERES_1E7=1 or where named.
specs=(bench/scaling.json bench/scaling-size.json bench/scaling-size-1e7.json)
plan=$(python3 - "${SCALING_SPHERES_1E7:-0}" "${#only[@]}" "${only[@]}" "${specs[@]}" <<'PY'
import json, sys
big, n = sys.argv[1] == "1", int(sys.argv[2])
only, specs = sys.argv[3:3 + n], sys.argv[3 + n:]
names = []
for spec in specs:
    for g in json.load(open(spec))["groups"]:
        names.append(g["name"])
        if g["name"] in only or (not only and (big or not spec.endswith("-1e7.json"))):
            print(spec, g["name"])
missing = [g for g in only if g not in names]
if missing:
    sys.exit("scaling: no group %s in %s" % (", ".join(missing), " ".join(specs)))
PY
)
wanted() { grep -qE " $1-" <<<"$plan"; }
sizes_of() { { grep -oE " $1-1e[0-9]+" <<<"$plan" || true; } | sed -E 's/.*-1e//' | while read -r k; do printf '1e%s,' "$k"; done; }

start_all=$(date +%s%N)
status=0
# The scene-size series' scenes (scenes/generated/scaling/, git-ignored; kept between
# runs when current), only the sizes that will run.
if wanted spheres || wanted triangles; then
  s=$(sizes_of spheres) t=$(sizes_of triangles)
  python3 tools/make_scaling_scenes.py --spheres "${s%,}" --triangles "${t%,}" || exit 1
fi

printf 'group\texit\tseconds\n' >"$out/timings.tsv.new"
[[ -f "$out/timings.tsv" ]] && tail -n +2 "$out/timings.tsv" |
  awk -F'\t' -v keep="$(cut -d' ' -f2 <<<"$plan" | tr '\n' ' ')" 'index(" " keep, " " $1 " ") == 0' >>"$out/timings.tsv.new"
while read -r spec group; do
  dir="$out/$group"
  mkdir -p "$dir"
  rm -f "$dir/results.json" "$dir/results.csv"
  t0=$(date +%s%N)
  set +e
  "$bin/wavetrace" bench "$spec" -o "$dir" --only "$group" --commit "$commit" 2>&1 | tee "$dir/bench.log"
  rc=${PIPESTATUS[0]}
  set -e
  ms=$(( ($(date +%s%N) - t0) / 1000000 ))
  printf '%s\t%d\t%d.%03d\n' "$group" "$rc" $((ms / 1000)) $((ms % 1000)) >>"$out/timings.tsv.new"
  # bench exits 1 where a point failed (a constant-memory refusal too: the tables
  # judge those); no results.json means it died, and the group is lost.
  if [[ ! -f "$dir/results.json" ]]; then
    echo "scaling: $group: bench exited $rc without results (see $dir/bench.log)" >&2
    status=1
  fi
done <<<"$plan"
mv "$out/timings.tsv.new" "$out/timings.tsv"

python3 bench/scaling_tables.py "$out"/*/results.json --md "$out/tables.md" --svg "$out/scaling.svg" || status=1
echo "scaling: $(( ($(date +%s%N) - start_all) / 1000000000 )) s in all; tables in $out/tables.md, plot $out/scaling.svg" >&2
exit $status

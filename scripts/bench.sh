#!/usr/bin/env bash
# The whole benchmark on a CUDA machine, in one command: the grid of bench/study.json
# (each kernel's image checked against the megakernel's before it is timed), the
# mesh and model scenes, the Nsight Compute profiles, the scaling study and the
# wavefront's bytes per ray, and the plots and tables, all under bench/results/.
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
# The mesh scenes: generated here (nothing is downloaded), then the shared models
# where they are present (WAVETRACE_MODELS, default ../shared/models).
python3 tools/make_terrain.py >/dev/null && python3 tools/make_instances.py >/dev/null || status=$?
"$bin/wavetrace" bench bench/meshes.json -o "$results/meshes" --commit "$commit" || status=$?
mesh_results=("$results/meshes/results.json")
models=${WAVETRACE_MODELS:-$root/../shared/models}
if [[ -d "$models" ]] && python3 tools/make_model_scenes.py "$models" >/dev/null; then
  "$bin/wavetrace" bench bench/models.json -o "$results/models" --commit "$commit" || status=$?
  mesh_results+=("$results/models/results.json")
else
  echo "bench: no models in $models; the model scenes are skipped" >&2
fi
python3 bench/mesh_tables.py "${mesh_results[@]}" >"$results/meshes/tables.md" || status=$?
# A picture of each mesh scene from each GPU kernel.
for scene in scenes/cornell-box.json scenes/glossy-lights.json scenes/sky-sun.json scenes/terrain.json scenes/instances.json scenes/generated/*.json; do
  [[ -f "$scene" ]] || continue
  for kernel in $("$bin/wavetrace" kernels --backend cuda); do
    "$bin/wavetrace" render "$scene" -o "$results/meshes/$(basename "$scene" .json)-$kernel.png" --width 480 \
      --height 270 --spp 256 --backend cuda --kernel "$kernel" -q 2>/dev/null ||
      echo "bench: $(basename "$scene") with $kernel: not rendered (see the results for why)" >&2
  done
done
bash scripts/profile.sh "$bin" "$results" || status=$?
# Throughput against resolution, samples and scene size; the wavefront's bytes per ray.
bash scripts/scaling.sh "$bin" "$results/scaling" || status=$?
bash scripts/bytes-per-ray.sh "$bin" "$results/bytes-per-ray" || status=$?
python3 bench/profile_summary.py "$results" >/dev/null || status=$?
# PYTHON: an interpreter with matplotlib (Debian's python3-matplotlib is /usr/bin/python3's).
"${PYTHON:-python3}" bench/plot.py "$results/results.json" --out "$results" || status=$?
exit $status

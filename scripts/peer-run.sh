#!/usr/bin/env bash
# The Mitsuba 3 column of the benchmark, on the GPU machine (python3.12 and the
# NVIDIA driver, no network): unpacks .gpu/peer/mitsuba-peer.tar.xz (made by
# scripts/peer-pack.sh) into /tmp/peer, checks that the CUDA variant and OptiX
# start, and renders each scene with bench/mitsuba_peer.py in both loop modes.
#   scripts/peer-run.sh [OUT_DIR [SCENE...]]
# OUT_DIR: default $OUT/mitsuba-peer where $OUT is set, else .gpu/peer-results.
# SCENE: seed57 rtiow-cover cornell-box terrain (the default: all four, at the
# benchmark's configurations below). One command may run for at most 10 minutes
# on the lent machines: give one or two scenes a call.
# Environment: PEER_PYTHON (default python3.12), PEER_TARBALL, PEER_MODES (both,
# symbolic or evaluated), PEER_LANE_BUDGET (samples a pass holds in the evaluated
# mode, default 2^26), PEER_REPEATS (3), PEER_KERNEL_HISTORY=1 (one more render per
# mode, recording Dr.Jit's kernel count and device seconds). For a smoke test
# elsewhere: PEER_SITE (a site-packages to use instead of the tarball), PEER_VARIANT
# (default cuda_ad_rgb), PEER_ARGS (replaces each scene's size, spp and depth).
# PEER_FLAGS: more options for bench/mitsuba_peer.py render (--no-python-plugins,
# --instancing, --sky-sampling always, --passes N).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
if [[ -n "${OUT:-}" ]]; then default_out=$OUT/mitsuba-peer; else default_out=$root/.gpu/peer-results; fi
out=${1:-$default_out}
shift || true
scenes=("$@")
[[ ${#scenes[@]} -gt 0 ]] || scenes=(seed57 rtiow-cover cornell-box terrain)
py=${PEER_PYTHON:-python3.12}
tarball=${PEER_TARBALL:-$root/.gpu/peer/mitsuba-peer.tar.xz}
modes=${PEER_MODES:-both}
variant=${PEER_VARIANT:-cuda_ad_rgb}
mkdir -p "$out"

if ! "$py" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 12))' 2>/dev/null; then
  echo "peer-run: $py is not Python 3.12 (the wheels are cp312); set PEER_PYTHON" >&2
  exit 2
fi
if [[ -n "${PEER_SITE:-}" ]]; then
  export PYTHONPATH=$PEER_SITE${PYTHONPATH:+:$PYTHONPATH}
else
  [[ -f "$tarball" ]] || { echo "peer-run: no $tarball (run scripts/peer-pack.sh and carry .gpu/peer)" >&2; exit 2; }
  rm -rf /tmp/peer
  mkdir -p /tmp/peer
  tar -xJf "$tarball" -C /tmp/peer
  export PYTHONPATH=/tmp/peer/site-packages${PYTHONPATH:+:$PYTHONPATH}
  cat /tmp/peer/MANIFEST.txt
fi

# Before anything is timed: the driver, the CUDA backend and OptiX (Mitsuba's CUDA
# variants trace rays with OptiX, whose library libnvoptix.so.1 comes with the
# driver), through a render of a sphere.
nvidia-smi --query-gpu=name,driver_version,memory.total,memory.used --format=csv,noheader || true
ldconfig -p 2>/dev/null | grep -E "libnvoptix|libcuda\.so" || echo "peer-run: ldconfig lists no libnvoptix / libcuda" >&2
if ! "$py" - "$variant" <<'EOF'
import sys, time
import drjit as dr
import mitsuba as mi
t = time.perf_counter()
mi.set_variant(sys.argv[1])
scene = mi.load_dict({"type": "scene", "integrator": {"type": "path", "max_depth": 3},
                      "sensor": {"type": "perspective", "fov": 40,
                                 "film": {"type": "hdrfilm", "width": 32, "height": 32,
                                          "rfilter": {"type": "box"}}},
                      "ball": {"type": "sphere", "center": [0, 0, 5]},
                      "sky": {"type": "constant"}})
img = mi.render(scene, spp=4)
mean = dr.mean(img.array)
dr.sync_thread()
print("peer-run: %s works (image mean %.3f, %.1f s); mitsuba %s, drjit %s"
      % (sys.argv[1], mean[0], time.perf_counter() - t, mi.__version__, dr.__version__))
EOF
then
  echo "peer-run: the CUDA variant does not start (see above): no driver, no libnvoptix.so.1, or no GPU" >&2
  exit 3
fi

status=0
for scene in "${scenes[@]}"; do
  # The points of bench/study.json and bench/meshes.json. `wavetrace bench` renders
  # a point that names no roulette_depth with roulette_depth = depth (no roulette),
  # whatever the scene's render section says, and with seed 1: so here too.
  case $scene in
    seed57)      args=(--width 1920 --height 1080 --spp 300 --depth 30 --roulette-depth 30) ;;  # the headline
    rtiow-cover) args=(--width 1920 --height 1080 --spp 100 --depth 50 --roulette-depth 50) ;;
    cornell-box) args=(--width 1920 --height 1080 --spp 64 --depth 16 --roulette-depth 16) ;;
    terrain)     args=(--width 1920 --height 1080 --spp 64 --depth 16 --roulette-depth 16)
                 "$py" tools/make_terrain.py >/dev/null ;;
    *)           args=() ;;
  esac
  args+=(--seed 1)
  file=scenes/$scene.json
  [[ -f "$file" ]] || file=$scene
  name=$(basename "$file")
  name=${name%.*}  # .json, or a Mitsuba scene's .xml (rendered as it is)
  extra=()
  [[ "${PEER_KERNEL_HISTORY:-0}" == 1 ]] && extra+=(--kernel-history)
  [[ -n "${PEER_ARGS:-}" ]] && read -r -a args <<<"$PEER_ARGS"
  [[ -n "${PEER_FLAGS:-}" ]] && read -r -a flags <<<"$PEER_FLAGS" && extra+=("${flags[@]}")
  echo "peer-run: $name ${args[*]}"
  if ! "$py" bench/mitsuba_peer.py render "$file" "${args[@]}" --mode "$modes" --variant "$variant" \
      --repeats "${PEER_REPEATS:-3}" --lane-budget "${PEER_LANE_BUDGET:-67108864}" "${extra[@]}" \
      -o "$out/$name" --json "$out/results.json" 2>"$out/$name.log"; then
    echo "peer-run: $name failed:" >&2
    tail -20 "$out/$name.log" >&2
    status=1
  fi
done
echo "peer-run: records in $out/results.json"
exit $status

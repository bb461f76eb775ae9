#!/usr/bin/env bash
# Bytes per ray of the wavefront's stages, read with Nsight Compute: for every kernel
# launch of a render, the DRAM bytes read and written, the L2 traffic (and its
# split into reads, writes, atomics and reductions) and the launch's size; the
# render's --stats (rays, shadow rays, live paths per bounce) give the items each
# launch handled. bench/bytes_per_ray.py turns the CSVs into bytes_per_ray.md.
#   scripts/bytes-per-ray.sh BIN_DIR OUT_DIR
#
# Three profiles per kernel (KERNELS, default: wavefront wavefront-unsorted), all on
# SCENE (default scenes/seed57.json):
#   whole   every launch of a short render (WHOLE_ARGS: 1920x1080, 2 spp, depth 30;
#           the default wave holds all its 4.1 M paths): the whole-render bytes per
#           ray, the tail of bounces included, and each bounce on its own.
#   steady  STEADY_COUNT launches after STEADY_SKIP of the headline render (300 spp,
#           16 Mi slots, about 112 bounces of which 80 run a full wave): the
#           steady state. bytes_per_ray.py keeps the whole bounces of the window.
#   whole-wN  (wavefront-unsorted only; L2_WAVE, default 262144 slots, empty: none)
#           the whole render again with a wave small enough that a bounce's hot
#           state (about 120-170 bytes a slot) is near the 50 MB L2.
# The stage kernels are one generic kernel (for_each_kernel / for_each_bounded_kernel,
# cuda/executor.cuh) over each stage's item: IntersectItem (generate fused in),
# AdvanceCountersItem, ShadeItem, ShadowItem (stages/intersect.hpp, stages/shade.hpp);
# compact and sort are CUB's kernels (DeviceSelect::If, DeviceRadixSort). Every
# kernel of the render is profiled (no name filter), so that the per-bounce
# grouping (a bounce starts at its IntersectItem launch) sees all of them.
#
# ncu runs with --replay-mode application and --cache-control none: each pass is a
# fresh, unmodified run of the render, so the L2 holds between kernels what it would
# hold anyway and no memory save/restore touches it (kernel replay copies the memory
# a kernel can reach, 2.9 GB in bench/results' profiles, around its passes). DRAM
# bytes are then where the traffic really happens: a stage's dirty lines still in
# L2 at its end are written back (and counted) in a later kernel. L2 bytes do not
# depend on that. CACHE_CONTROL=all and REPLAY=kernel give ncu's defaults instead
# (each kernel from a flushed L2).
#
# Expected time on an H100: about 1-2 minutes in all (a pass is one run of the
# render under ncu, 150-350 profiled launches; the metrics take one or two passes).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=$(cd "${1:?usage: bytes-per-ray.sh BIN_DIR OUT_DIR}" && pwd)
out=${2:?usage: bytes-per-ray.sh BIN_DIR OUT_DIR}
mkdir -p "$out"
out=$(cd "$out" && pwd)
cd "$root"

scene=${SCENE:-scenes/seed57.json}
kernels=${KERNELS:-wavefront wavefront-unsorted}
whole_args=${WHOLE_ARGS:---width 1920 --height 1080 --spp 2 --depth 30}
steady_args=${STEADY_ARGS:---width 1920 --height 1080 --spp 300 --depth 30}
steady_skip=${STEADY_SKIP:-100}
steady_count=${STEADY_COUNT:-40}
l2_wave=${L2_WAVE-262144}
cache_control=${CACHE_CONTROL:-none}
replay=${REPLAY:-application}
default_metrics=dram__bytes_read.sum,dram__bytes_write.sum,lts__t_bytes.sum
default_metrics+=,lts__t_sectors_op_read.sum,lts__t_sectors_op_write.sum,lts__t_sectors_op_atom.sum,lts__t_sectors_op_red.sum
default_metrics+=,gpu__time_duration.sum,launch__grid_size,launch__block_size,launch__thread_count
metrics=${METRICS:-$default_metrics}

ncu=${NCU:-$(command -v ncu || echo /usr/local/cuda/bin/ncu)}
[[ -x $ncu ]] || { echo "bytes-per-ray: no ncu (Nsight Compute) on PATH or at $ncu; set NCU" >&2; exit 1; }
status=0

# profile LABEL KERNEL "NCU_FILTER_ARGS" RENDER_ARGS...: bytes-LABEL-KERNEL.csv (ncu's raw
# page), .stats.json (the render's --stats), .log (ncu's and the render's stderr),
# .cmd (the command, read by bytes_per_ray.py).
profile() {
  local label=$1 kernel=$2 filter=$3
  shift 3
  local base="$out/bytes-$label-$kernel"
  rm -f "$base.csv" "$base.stats.json" "$base.log" "$base.cmd"
  # shellcheck disable=SC2206
  local cmd=("$ncu" --replay-mode "$replay" --cache-control "$cache_control" --clock-control none
    --metrics "$metrics" --kernel-name-base demangled $filter --csv --page raw
    "$bin/wavetrace" render "$scene" "$@" --warmup 0 -o "$out/bytes-profile.png" --backend cuda --kernel "$kernel"
    -q --profile --stats "$base.stats.json")
  echo "${cmd[*]}" >"$base.cmd"
  local start=$SECONDS
  if "${cmd[@]}" >"$base.csv" 2>"$base.log"; then
    echo "bytes-per-ray: $label $kernel: $((SECONDS - start)) s" >&2
  else
    echo "bytes-per-ray: the profile of $kernel ($label) failed; see $base.log" >&2
    status=1
  fi
}

for kernel in $kernels; do
  # shellcheck disable=SC2086
  profile whole "$kernel" "" $whole_args
  if [[ $steady_count -gt 0 ]]; then
    # shellcheck disable=SC2086
    profile steady "$kernel" "--launch-skip $steady_skip --launch-count $steady_count" $steady_args
  fi
done
if [[ -n $l2_wave ]]; then
  # shellcheck disable=SC2086
  profile "whole-w$l2_wave" wavefront-unsorted "" $whole_args --wave-size "$l2_wave"
fi
rm -f "$out/bytes-profile.png"
python3 bench/bytes_per_ray.py "$out" || status=1
exit $status

#!/usr/bin/env bash
# Reads, with Nsight Compute, what the study reported for its kernels: registers
# per thread, achieved occupancy, warp execution efficiency and memory throughput,
# for each kernel at the headline configuration (seed57, 1920x1080, 300 spp,
# depth 30), and on the divergent scene, where shading diverges most.
#   scripts/profile.sh BIN_DIR OUT_DIR
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=$(cd "${1:?usage: profile.sh BIN_DIR OUT_DIR}" && pwd)
out=${2:?usage: profile.sh BIN_DIR OUT_DIR}
mkdir -p "$out"
cd "$root"
metrics=launch__registers_per_thread,sm__warps_active.avg.pct_of_peak_sustained_active,smsp__thread_inst_executed_per_inst_executed.ratio,dram__throughput.avg.pct_of_peak_sustained_elapsed,gpu__compute_memory_throughput.avg.pct_of_peak_sustained_elapsed,gpu__time_duration.sum

# profile LABEL WAVEFRONT_SKIP SCENE ARGS...: each kernel's profile into profile-LABEL-KERNEL.csv.
# The megakernels' first launch is profiled; the wavefront's intersect and shade
# (the generic stage kernel over IntersectItem and ShadeItem) after WAVEFRONT_SKIP
# launches, in the steady state with the wave full.
profile() {
  local label=$1 skip=$2
  shift 2
  for kernel in $("$bin/wavetrace" kernels --backend cuda); do
    local filter="regex:IntersectItem|ShadeItem" from=$skip count=4
    case $kernel in
      megakernel) filter="regex:megakernel_global" from=0 count=1 ;;
      megakernel-constant) filter="regex:megakernel_constant" from=0 count=1 ;;
    esac
    ncu --clock-control none --metrics "$metrics" --kernel-name-base demangled -k "$filter" \
      --launch-skip "$from" --launch-count "$count" \
      --csv --page raw "$bin/wavetrace" render "$@" -o "$out/profile.png" --backend cuda -q --kernel "$kernel" \
      >"$out/profile-$label-$kernel.csv" || echo "profile of $kernel on $label failed"
  done
}
profile seed57 20 scenes/seed57.json --width 1920 --height 1080 --spp 300 --depth 30
profile divergent 10 scenes/divergent.json --width 1920 --height 1080
rm -f "$out/profile.png"

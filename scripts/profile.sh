#!/usr/bin/env bash
# Reads, with Nsight Compute, what the study reported for its kernels: registers
# per thread, achieved occupancy, warp execution efficiency and memory throughput,
# for each kernel at the headline configuration (seed57, 1920x1080, 300 spp, depth 30).
#   scripts/profile.sh BIN_DIR OUT_DIR
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=$(cd "${1:?usage: profile.sh BIN_DIR OUT_DIR}" && pwd)
out=${2:?usage: profile.sh BIN_DIR OUT_DIR}
mkdir -p "$out"
cd "$root"
metrics=launch__registers_per_thread,sm__warps_active.avg.pct_of_peak_sustained_active,smsp__thread_inst_executed_per_inst_executed.ratio,dram__throughput.avg.pct_of_peak_sustained_elapsed,gpu__compute_memory_throughput.avg.pct_of_peak_sustained_elapsed,gpu__time_duration.sum
render=(render scenes/seed57.json -o "$out/profile.png" --width 1920 --height 1080 --spp 300 --depth 30 --backend cuda -q)
# The megakernels run in ten launches of 30 samples: the first is profiled.
# The wavefront's kernels are profiled at bounces in the steady state (the wave full).
declare -A filter=(
  [megakernel]="regex:megakernel_global"
  [megakernel-constant]="regex:megakernel_constant"
  [wavefront]="regex:intersect_kernel|shade_kernel"
  [wavefront-unsorted]="regex:intersect_kernel|shade_kernel"
)
declare -A skip=([megakernel]=0 [megakernel-constant]=0 [wavefront]=20 [wavefront-unsorted]=20)
declare -A count=([megakernel]=1 [megakernel-constant]=1 [wavefront]=4 [wavefront-unsorted]=4)
for kernel in megakernel megakernel-constant wavefront wavefront-unsorted; do
  ncu --clock-control none --metrics "$metrics" -k "${filter[$kernel]}" --launch-skip "${skip[$kernel]}" \
    --launch-count "${count[$kernel]}" --csv --page raw "$bin/wavetrace" "${render[@]}" --kernel "$kernel" \
    >"$out/profile-$kernel.csv" || echo "profile of $kernel failed"
done
rm -f "$out/profile.png"

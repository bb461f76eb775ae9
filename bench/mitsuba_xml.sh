#!/usr/bin/env bash
# The Mitsuba 3 scenes of scenes/mitsuba/ rendered from the one file by wavetrace
# (the CUDA megakernel and wavefront) and by Mitsuba 3 (cuda_ad_rgb, symbolic loops,
# through scripts/peer-run.sh), on the GPU machine; bench/mitsuba_xml_tables.py then
# compares the images and the speeds (bench/RESULTS.md, "Mitsuba scenes").
#   bench/mitsuba_xml.sh BIN_DIR OUT_DIR [SPP]
# BIN_DIR holds wavetrace (scripts/gpu-build.sh's .gpu/bin); OUT_DIR gets wt/ (PFM
# images and stats) and peer/ (the peer's images and results.json). SPP: samples
# per pixel for both renderers (default 1024), each scene at its own size and depth.
# A cross-check without a GPU: BACKEND=cpu (wavetrace's CPU backend, no warm-up) with
# PEER_VARIANT=llvm_ad_rgb and PEER_SITE (a site-packages with Mitsuba's LLVM variant).
set -uo pipefail
bin=$1
out=$2
spp=${3:-1024}
backend=${BACKEND:-cuda}
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
mkdir -p "$out/wt" "$out/peer"
status=0
scenes=(scenes/mitsuba/*.xml)
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .xml)
  for kernel in megakernel wavefront; do
    # One warm-up render (the device and the scene's upload), then the timed one.
    [[ $backend == cuda ]] && "$bin/wavetrace" render "$scene" -o "$out/wt/$name-$kernel.pfm" --spp "$spp" --seed 1 \
      --backend cuda --kernel "$kernel" -q >/dev/null 2>&1
    if ! "$bin/wavetrace" render "$scene" -o "$out/wt/$name-$kernel.pfm" --spp "$spp" --seed 1 --backend "$backend" \
        --kernel "$kernel" --stats "$out/wt/$name-$kernel.json" -q 2>"$out/wt/$name-$kernel.log"; then
      echo "mitsuba_xml: wavetrace failed on $scene ($kernel):" >&2
      cat "$out/wt/$name-$kernel.log" >&2
      status=1
    fi
  done
done
PEER_ARGS="--spp $spp" PEER_MODES=symbolic PEER_REPEATS=${PEER_REPEATS:-3} bash scripts/peer-run.sh "$out/peer" "${scenes[@]}" || status=1
exit $status

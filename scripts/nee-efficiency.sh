#!/usr/bin/env bash
# Light sampling against pure path tracing on the CUDA wavefront: a high-sample
# reference per scene, then each mode at two sample counts, timed; the table
# (bench/nee_efficiency.py) says how much lower light sampling's error is at equal
# time. Usage: scripts/nee-efficiency.sh [BIN_DIR] [OUT_DIR]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=${1:-$root/build}
out=${2:-$root/bench/results/nee}
mkdir -p "$out"
render() {  # scene width height spp nee seed output [png] [more options]
  "$bin/wavetrace" render "$root/scenes/$1.json" -o "$7.pfm" --stats "$7.json" --width "$2" --height "$3" \
    --spp "$4" --nee "$5" --seed "$6" --backend cuda --kernel wavefront --warmup 1 -q "${@:9}"
  if [[ ${8:-} == png ]]; then  # the same render (same seed) as a picture
    "$bin/wavetrace" render "$root/scenes/$1.json" -o "$7.png" --width "$2" --height "$3" \
      --spp "$4" --nee "$5" --seed "$6" --backend cuda --kernel wavefront -q "${@:9}"
  fi
}
for spec in "cornell-box 256 256" "divergent 480 270" "glossy-lights 480 270" "sky-sun 480 270"; do
  read -r scene w h <<<"$spec"
  render "$scene" "$w" "$h" 16384 1 99 "$out/$scene-reference"
  for spp in 16 256; do
    render "$scene" "$w" "$h" "$spp" 1 1 "$out/$scene-nee-$spp" $([[ $spp == 256 ]] && echo png)
    render "$scene" "$w" "$h" "$spp" 0 1 "$out/$scene-pt-$spp" $([[ $spp == 256 ]] && echo png)
  done
done
# The part of divergent's error that no light sampling touches: its camera rays
# alone (depth 1: what each pixel sees directly, emitters' edges and textures
# included), against a reference of the same.
render divergent 480 270 16384 0 99 "$out/divergent-camera-rays-reference" "" --depth 1
render divergent 480 270 256 0 1 "$out/divergent-camera-rays-pt-256" "" --depth 1
python3 "$root/bench/nee_efficiency.py" "$out" | tee "$out/efficiency.md"

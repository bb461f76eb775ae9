#!/usr/bin/env bash
# The long renders a farm leaves running, on a GPU machine: seed57 at 3840x2160 with
# 4096 samples per pixel (34 G paths, far past 2^32) on every GPU kernel, with the
# time and the counted rays; then the wavefront's render killed with SIGTERM about
# halfway, resumed from its checkpoint, and compared with the uninterrupted image.
#   scripts/long-render-check.sh BIN_DIR [OUT_DIR] [WIDTH HEIGHT SPP]
set -uo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=$(cd "${1:?usage: long-render-check.sh BIN_DIR [OUT_DIR] [WIDTH HEIGHT SPP]}" && pwd)
out=${2:-$root/out/long-render}
w=${3:-3840} h=${4:-2160} spp=${5:-4096}
mkdir -p "$out"
cd "$root"
size=(--width "$w" --height "$h" --spp "$spp" --depth 30 --roulette-depth 30 --backend cuda)
status=0

for kernel in $("$bin/wavetrace" kernels --backend cuda); do
  start=$(date +%s.%N)
  if "$bin/wavetrace" render scenes/seed57.json -o "$out/whole-$kernel.pfm" "${size[@]}" --kernel "$kernel" -q \
    --stats "$out/whole-$kernel.json"; then
    python3 - "$out/whole-$kernel.json" "$kernel" "$start" <<'PY'
import json, sys, time
s = json.load(open(sys.argv[1]))
print("%-20s %dx%d %d spp: %.2f s GPU (%.1f s wall), %d paths, %d rays, %.0f M rays/s, %.0f M paths/s" % (
    sys.argv[2], s["settings"]["width"], s["settings"]["height"], s["settings"]["spp"], s["seconds"],
    time.time() - float(sys.argv[3]), s["paths"], s["rays"], s["m_rays_per_s"], s["m_paths_per_s"]))
PY
  else
    echo "$kernel: render failed"
    status=1
  fi
done

# Killed halfway (by the whole render's wall time), then resumed.
kernel=wavefront
half=$(python3 -c 'import json,sys; print(max(1.0, json.load(open(sys.argv[1]))["seconds"] / 2))' "$out/whole-$kernel.json")
rm -f "$out/resumed.pfm" "$out/resumed.ckpt"
"$bin/wavetrace" render scenes/seed57.json -o "$out/resumed.pfm" "${size[@]}" --kernel "$kernel" -q \
  --checkpoint "$out/resumed.ckpt" --checkpoint-every 1 &
pid=$!
sleep "$half"
kill -TERM "$pid"
wait "$pid"
rc=$?
echo "SIGTERM after ${half} s: exit $rc, image written: $([[ -e $out/resumed.pfm ]] && echo yes || echo no), checkpoint: $(ls -l "$out/resumed.ckpt" 2>/dev/null | awk '{print $5}') bytes"
((rc == 143)) || status=1
"$bin/wavetrace" render scenes/seed57.json -o "$out/resumed.pfm" "${size[@]}" --kernel "$kernel" -q \
  --resume "$out/resumed.ckpt" --stats "$out/resumed.json" || status=1
python3 - "$out/whole-$kernel.pfm" "$out/resumed.pfm" "$out/resumed.json" <<'PY' || status=1
import array, json, sys
def floats(path):
    data = open(path, "rb").read()
    at = 0
    for _ in range(3):
        at = data.index(b"\n", at) + 1
    a = array.array("f")
    a.frombytes(data[at:])
    return a
a, b = floats(sys.argv[1]), floats(sys.argv[2])
worst = max(abs(x - y) / max(1.0, abs(x)) for x, y in zip(a, b))
resumed = json.load(open(sys.argv[3])).get("resumed_from_sample")
print("resumed from sample %s: %d values, largest difference from the uninterrupted image %.2e (relative)" % (
    resumed, len(a), worst))
sys.exit(0 if len(a) == len(b) and worst <= 1e-5 else 1)
PY
exit $status

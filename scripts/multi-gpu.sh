#!/usr/bin/env bash
# The figures of bench/RESULTS.md's "Two GPUs and MPI ranks": on a machine with
# several GPUs, one seed57 image on one GPU and on all of them (each kernel, twice,
# the images compared), a batch of 16 jobs on one and on all (a worker per lane, and
# a process per job, with where each job's time went), and, where mpirun is found,
# the same image and batch over two ranks. Prints one line a measurement.
#   scripts/multi-gpu.sh BIN_DIR [OUT_DIR]
# BACKEND, WIDTH, HEIGHT, SPP (the image), BATCH_SPP (the batches' jobs: a batch of
# each) and KERNELS change the defaults (cuda, 1920, 1080, 1200, "300 1200",
# "megakernel wavefront"); with BACKEND=cpu it runs on host "devices", to try the
# script on a machine without a GPU. A batch of one job on one device shows what a
# batch pays once whatever its length (starting CUDA and the worker, ending them).
set -uo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=$(cd "${1:?usage: multi-gpu.sh BIN_DIR [OUT_DIR]}" && pwd)
out=${2:-$root/out/multi-gpu}
backend=${BACKEND:-cuda} width=${WIDTH:-1920} height=${HEIGHT:-1080} spp=${SPP:-1200}
batch_spp=${BATCH_SPP:-300 1200} kernels=${KERNELS:-megakernel wavefront}
b="$bin/wavetrace"
mkdir -p "$out"
cd "$root"
export WAVETRACE_ROOT="$root"
all=all
[[ $backend == cpu ]] && all=0,1
seconds() { python3 -c "import sys; print('%.2f' % (float(sys.argv[2]) - float(sys.argv[1])))" "$@"; }

for rep in 1 2; do
  for k in $kernels; do
    for d in 0 "$all"; do
      "$b" render scenes/seed57.json -o "$out/image-$k-$d.pfm" --width "$width" --height "$height" --spp "$spp" \
        --depth 30 --backend "$backend" --kernel "$k" --devices "$d" --warmup 1 --stats "$out/image-$k-$d-$rep.json" -q \
        2>"$out/image.err" || { echo "image $k on devices $d failed: $(tail -1 "$out/image.err")"; continue 2; }
    done
    python3 - "$out/image-$k-0.pfm" "$out/image-$k-$all.pfm" "$out/image-$k-0-$rep.json" "$out/image-$k-$all-$rep.json" "$k" <<'PY'
import json, struct, sys
def pfm(p):
    f = open(p, 'rb'); f.readline(); w, h = map(int, f.readline().split()); s = float(f.readline())
    d = f.read(); return struct.unpack(('<' if s < 0 else '>') + 'f' * (len(d) // 4), d)
a, b = pfm(sys.argv[1]), pfm(sys.argv[2])
rel = max(abs(x - y) / (1e-6 + abs(x)) for x, y in zip(a, b))
one, many = json.load(open(sys.argv[3])), json.load(open(sys.argv[4]))
shares = ', '.join('%s %.1f spp %.3f s' % (s['device'], s['paths'] / (one['settings']['width'] * one['settings']['height']),
                                          s['seconds']) for s in many.get('devices', []))
print('image %s: one device %.3f s, %d devices %.3f s, %.2fx; max relative difference %.1e; %s' % (
    sys.argv[5], one['seconds'], len(many.get('devices', [])) or 1, many['seconds'], one['seconds'] / many['seconds'], rel, shares))
PY
  done
done

jobs_file() {  # jobs_file SPP COUNT: writes COUNT seed57 jobs of SPP samples; prints the file's path
  python3 - "$root" "$out" "$backend" "$1" "$2" "$width" "$height" <<'PY'
import json, sys
root, out, backend, spp, n, width, height = sys.argv[1:8]
jobs = [{"scene": root + "/scenes/seed57.json", "output": out + "/batch/j%02d.png" % i, "stats": out + "/batch/j%02d.json" % i,
         "seed": i + 1} for i in range(int(n))]
path = out + "/jobs-%s-%s.json" % (spp, n)
json.dump({"defaults": {"width": int(width), "height": int(height), "spp": int(spp), "depth": 30, "backend": backend, "kernel": "wavefront"},
           "jobs": jobs}, open(path, "w"))
print(path)
PY
}
phases() {
  python3 - "$out/batch" <<'PY'
import glob, json, statistics as st, sys
rows = [json.load(open(f)) for f in sorted(glob.glob(sys.argv[1] + '/j*.json'))]
load = lambda r: sum(r['load_seconds'][k] for k in ('parse', 'validate', 'texture_load', 'bvh_build'))
med = lambda f: st.median(f(r) for r in rows)
print('job %.3f s: render %.3f, scene %.3f, write %.3f, rest %.3f (medians)' % (
    med(lambda r: r['job_seconds']), med(lambda r: r['seconds']), med(lambda r: load(r) + r['upload_seconds']),
    med(lambda r: r['write_seconds']),
    med(lambda r: r['job_seconds'] - r['seconds'] - load(r) - r['upload_seconds'] - r['write_seconds'])))
PY
}
# batch FILE DEVICES [FLAGS...]: runs it into a clean output folder; sets rc and elapsed.
batch() {
  local file=$1 d=$2 start end
  shift 2
  rm -rf "$out/batch" && mkdir -p "$out/batch"
  start=$(date +%s.%N)
  "$b" batch "$file" --devices "$d" "$@" >"$out/batch.txt" 2>"$out/batch.err"
  rc=$?
  end=$(date +%s.%N)
  elapsed=$(seconds "$start" "$end")
}
first_spp=${batch_spp%% *}
for bspp in $batch_spp; do
  batch "$(jobs_file "$bspp" 1)" 0
  echo "batch of 1 job ($bspp spp) on device 0: rc $rc, $elapsed s; $(phases)"
  file=$(jobs_file "$bspp" 16)
  for rep in 1 2; do
    for mode in worker process-per-job; do
      # A process per job once, at the first size: it only adds each job's own start.
      [[ $mode == process-per-job && ($rep == 2 || $bspp != "$first_spp") ]] && continue
      flag=()
      [[ $mode == process-per-job ]] && flag=(--process-per-job)
      for d in 0 "$all"; do
        batch "$file" "$d" "${flag[@]}"
        echo "batch of 16 ($bspp spp, $mode) on devices $d: rc $rc, $elapsed s; $(tail -1 "$out/batch.txt"); $(phases)"
      done
    done
  done
done

if command -v mpirun >/dev/null; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  for k in $kernels; do
    start=$(date +%s.%N)
    timeout 300 mpirun --oversubscribe -n 2 "$b" render scenes/seed57.json -o "$out/mpi-$k.pfm" --width "$width" \
      --height "$height" --spp "$spp" --depth 30 --backend "$backend" --kernel "$k" --warmup 1 \
      --stats "$out/mpi-$k.json" -q 2>"$out/mpi.err" || { echo "mpirun -n 2 render $k failed: $(tail -1 "$out/mpi.err")"; continue; }
    end=$(date +%s.%N)
    echo "mpirun -n 2 render $k: $(python3 -c "import json, sys; j = json.load(open(sys.argv[1])); print('slowest rank %.3f s, rank 0 wall %.3f s' % (j['seconds'], j['wall_seconds']))" "$out/mpi-$k.json"), the whole command $(seconds "$start" "$end") s"
  done
  rm -rf "$out/batch" && mkdir -p "$out/batch"
  start=$(date +%s.%N)
  timeout 300 mpirun --oversubscribe -n 2 "$b" batch "$(jobs_file "$first_spp" 16)" >"$out/batch.txt" 2>"$out/batch.err"
  rc=$?
  end=$(date +%s.%N)
  echo "mpirun -n 2 batch of 16 ($first_spp spp): rc $rc, $(seconds "$start" "$end") s; $(tail -1 "$out/batch.txt"); on rank 1: $(grep -c 'on rank 1' "$out/batch.err")"
fi

#!/usr/bin/env bash
# Packs .gpu/bin (scripts/gpu-build.sh) for a GPU machine that is handed a copy of the
# working tree with a limit on what travels beside it: one xz stream (the binaries
# share their device code, which one dictionary holds once), split into parts of at
# most PART_BYTES (default 33000000: with the tree, about 28 MB, under a 64 MiB
# limit), each alone in .gpu/part1, .gpu/part2, ... so that each call carries one
# folder. On the GPU machine, each call but the last stages its part
# (`scripts/gpu-pack.sh --stage N` copies .gpu/partN/ to $STAGE, default
# /root/stage), and the last unpacks them all with its own (`--unpack DIR`: the
# binaries in DIR/bin).
#   scripts/gpu-pack.sh                 pack (here)
#   scripts/gpu-pack.sh --stage N       stage part N (there)
#   scripts/gpu-pack.sh --unpack DIR    unpack the staged parts and the last (there)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
stage=${STAGE:-/root/stage}
case "${1:-}" in
  --stage)
    mkdir -p "$stage" && cp "$root/.gpu/part${2:?part number}"/bin.part* "$stage/"
    ls -l "$stage"
    ;;
  --unpack)
    out=${2:?folder}
    mkdir -p "$stage" && for p in "$root"/.gpu/part*/bin.part*; do [[ -e $p ]] && cp -n "$p" "$stage/"; done
    rm -rf "$out/bin" && mkdir -p "$out"
    cat $(ls "$stage"/bin.part* | sort -V) | xz -d | tar -x -C "$out"
    cat "$out/bin/build-info.json"
    ;;
  "")
    [[ -f "$root/.gpu/bin/build-info.json" ]] || { echo "gpu-pack: no .gpu/bin: run scripts/gpu-build.sh" >&2; exit 2; }
    rm -rf "$root"/.gpu/part* && tmp=$(mktemp -d)
    tar -C "$root/.gpu" -cf - bin | xz -T0 --lzma2=preset=6,dict=192MiB >"$tmp/bin.tar.xz"
    split -b "${PART_BYTES:-33000000}" -d -a 1 "$tmp/bin.tar.xz" "$tmp/p"
    n=0
    for p in $(ls "$tmp"/p* | sort -V); do
      n=$((n + 1)) && mkdir -p "$root/.gpu/part$n" && mv "$p" "$root/.gpu/part$n/bin.part$n"
    done
    rm -rf "$tmp"
    du -b "$root"/.gpu/part*/bin.part* && cat "$root/.gpu/bin/build-info.json"
    ;;
  *) echo "usage: gpu-pack.sh [--stage N | --unpack DIR]" >&2; exit 2 ;;
esac

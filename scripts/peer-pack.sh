#!/usr/bin/env bash
# Packs Mitsuba 3 (cuda_ad_rgb only) for a GPU machine that has python3.12 and the
# NVIDIA driver but no network and no pip packages: .gpu/peer/mitsuba-peer.tar.xz,
# unpacked there by scripts/peer-run.sh.
#   scripts/peer-pack.sh
# Environment:
#   PEER_WHEELS   folder of the two wheels (downloaded into it when missing;
#                 default $PEER_BUILD/wheels)
#   PEER_BUILD    scratch folder (default $TMPDIR/wavetrace-peer-build; outside the
#                 repository, so that carrying .gpu never takes its 400 MB along)
#   PEER_PYTHON   a python3.12 for the checks (default: python3.12 on PATH, then pyenv's)
# Steps: download the cp312 wheels if missing; pip install --no-deps --target a
# staging folder; trim it to what cuda_ad_rgb and the plugins that
# bench/mitsuba_peer.py emits need; check what can be checked without a GPU (every
# kept library's dependencies resolve; `import mitsuba` works; every kept plugin and
# the cuda_ad_rgb module load with all symbols bound; each shipped scene renders
# with the trimmed plugins through the LLVM variant, added to a scratch copy only);
# write the tarball (xz -9) and print its size.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
MITSUBA_VERSION=3.7.1
DRJIT_VERSION=1.2.0
build=${PEER_BUILD:-${TMPDIR:-/tmp}/wavetrace-peer-build}
wheels=${PEER_WHEELS:-$build/wheels}
out_dir=$root/.gpu/peer              # carried: only the tarball lives here
out=$out_dir/mitsuba-peer.tar.xz
mkdir -p "$wheels" "$out_dir" "$build"

# Every plugin the converter emits (bench/mitsuba_peer.py, EMITTED_PLUGINS) and what
# loading them pulls in (isotropic, the homogeneous medium's default phase function; srgb for 'rgb' values, uniform for float parameters, d65
# and regular for the rgb variants' illuminants, merge for the scene's shape
# merging): found by recording the plugins a process had mapped after loading and
# rendering every shipped scene (and the shapegroup path) with the LLVM variant.
# "scene" is part of libmitsuba. The glTF tiles add principledthin, mask, the
# punctual lights (point, spot, directional), and volpath with a homogeneous
# medium of a constvolume for absorbing volumes; bump maps add bumpmap; the shipped
# Mitsuba scenes (scenes/mitsuba/) the built-in shapes, serialized, checkerboard and
# blendbsdf (which wavetrace's blend converts to as well).
PLUGINS="area isotropic bitmap box conductor constant d65 dielectric diffuse envmap hdrfilm independent instance merge
bumpmap normalmap obj path perspective plastic ply principled regular roughconductor roughdielectric roughplastic shapegroup sphere
srgb thindielectric thinlens twosided uniform principledthin mask point spot directional volpath homogeneous constvolume
rectangle cube disk cylinder serialized checkerboard blendbsdf"

py_local=$(command -v python3)
export PIP_ROOT_USER_ACTION=ignore PIP_DISABLE_PIP_VERSION_CHECK=1
have_wheel() { compgen -G "$wheels/$1-$2-cp312-*manylinux*x86_64*.whl" >/dev/null; }
if ! have_wheel mitsuba "$MITSUBA_VERSION" || ! have_wheel drjit "$DRJIT_VERSION"; then
  echo "peer-pack: downloading the wheels into $wheels" >&2
  "$py_local" -m pip download --no-deps --python-version 312 --only-binary=:all: \
    --platform manylinux_2_17_x86_64 -d "$wheels" "mitsuba==$MITSUBA_VERSION" "drjit==$DRJIT_VERSION"
fi
mapfile -t whl < <(ls "$wheels"/mitsuba-"$MITSUBA_VERSION"-cp312-*.whl "$wheels"/drjit-"$DRJIT_VERSION"-cp312-*.whl)

stage=$build/stage
tree=$build/tree
rm -rf "$stage" "$tree"
"$py_local" -m pip install --quiet --no-deps --no-index --no-compile --target "$stage" \
  --python-version 312 --only-binary=:all: --platform manylinux_2_17_x86_64 "${whl[@]}"

# --- trim -----------------------------------------------------------------
mkdir -p "$tree/site-packages"
cp -a "$stage/mitsuba" "$stage/drjit" "$stage/drjit.libs" "$tree/site-packages/"   # drjit.libs: its libatomic
mi=$tree/site-packages/mitsuba
dj=$tree/site-packages/drjit
# Other variants' Python modules.
for f in "$mi"/*.cpython-312-x86_64-linux-gnu.so; do
  case $(basename "$f") in
    cuda_ad_rgb.*|mitsuba_ext.*|mitsuba_alias.*) ;;
    *) rm "$f" ;;
  esac
done
# Plugins nobody loads.
for f in "$mi"/plugins/*.so; do
  name=$(basename "$f" .so)
  [[ " $(echo $PLUGINS) " == *" $name "* ]] || rm "$f"
done
# Headers, CMake files, type stubs, tests, byte code; spectral data (srgb.coeff is the
# spectral variants' RGB upsampling table), conductor IOR tables (the converter's
# conductors are material 'none' or give eta and k as RGB values) and sun-sky tables;
# but the conductors' tables, which Mitsuba scenes may name by `material` and
# wavetrace maps every one of (docs/scene-format.md, "Mitsuba 3 scenes"; 0.6 MB).
kept_ior=$build/kept-ior
rm -rf "$kept_ior" && mkdir -p "$kept_ior"
cp "$mi"/data/ior/*.spd "$kept_ior/"
rm -rf "$mi/include" "$mi/cmake" "$mi/mitsuba_stubs" "$mi/python/test" "$mi/data" \
       "$dj/include" "$dj/cmake"
mkdir -p "$mi/data/ior" && cp "$kept_ior"/*.spd "$mi/data/ior/"
find "$tree" \( -name '__pycache__' -o -name '*.pyi' -o -name 'py.typed' -o -name 'stubs.pat' \) -prune \
  -exec rm -rf {} +
# libembree3.so stays: libmitsuba.so (and every plugin) lists it as DT_NEEDED, so
# nothing imports without it, although the CUDA variant traces rays with OptiX.
for lib in libembree3.so; do
  readelf -d "$mi/libmitsuba.so" | grep -q "NEEDED.*\[$lib\]" || echo "peer-pack: note: $lib is no longer needed" >&2
done

# --- checks ---------------------------------------------------------------
status=0
# 1. Every dependency of every kept library resolves (libcuda and libnvoptix are
#    opened at run time by Dr.Jit, from the driver: they are not DT_NEEDED). The
#    plugins find libmitsuba and Dr.Jit's libraries already loaded, by name (their
#    RPATH points beside them): they are checked with those folders on the path.
while IFS= read -r -d '' f; do
  path=
  [[ $f == */plugins/* ]] && path=$mi:$dj:$tree/site-packages/drjit.libs
  if LD_LIBRARY_PATH=$path ldd "$f" 2>&1 | grep -q "not found"; then
    echo "peer-pack: unresolved dependencies of $f:" >&2
    LD_LIBRARY_PATH=$path ldd "$f" | grep "not found" >&2
    status=1
  fi
done < <(find "$tree" -name '*.so*' -type f -print0)

py=${PEER_PYTHON:-}
if [[ -z "$py" ]]; then
  for c in python3.12 "$HOME"/.pyenv/versions/3.12*/bin/python3.12 python3; do
    if "$c" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 12))' >/dev/null 2>&1; then
      py=$(command -v "$c"); break
    fi
  done
fi
if [[ -z "$py" ]]; then
  echo "peer-pack: no python3.12 here (set PEER_PYTHON): import and render checks skipped" >&2
else
  # 2. The package imports (cuda_ad_rgb itself needs a GPU to be selected).
  PYTHONPATH=$tree/site-packages "$py" -c 'import mitsuba as mi; print("peer-pack: variants", mi.variants())' ||
    status=1
  # 3. The cuda_ad_rgb module and every kept plugin load with every symbol bound.
  PYTHONPATH=$tree/site-packages "$py" - "$mi" <<'EOF' || status=1
import ctypes, glob, os, sys
mi = sys.argv[1]
mode = os.RTLD_NOW | os.RTLD_GLOBAL
ctypes.CDLL(os.path.join(mi, "libmitsuba.so"), mode)
files = glob.glob(os.path.join(mi, "cuda_ad_rgb.*.so")) + sorted(glob.glob(os.path.join(mi, "plugins", "*.so")))
for f in files:
    ctypes.CDLL(f, mode)
print("peer-pack: %d libraries load with all symbols bound (cuda_ad_rgb + %d plugins)" % (len(files), len(files) - 1))
EOF
  # 4. The trimmed plugins and data render every shipped scene: a scratch copy with
  #    the LLVM variant's module added (plugins serve every variant).
  check=$build/check
  rm -rf "$check"
  cp -a "$tree" "$check"
  cp "$stage"/mitsuba/llvm_ad_rgb.cpython-312-x86_64-linux-gnu.so "$check/site-packages/mitsuba/"
  if PYTHONPATH=$check/site-packages "$py" -c 'import mitsuba as mi; mi.set_variant("llvm_ad_rgb")' 2>/dev/null; then
    [[ -f "$root/scenes/generated/terrain.glb" ]] || python3 "$root/tools/make_terrain.py" >/dev/null
    for scene in seed57 rtiow-cover cornell-box terrain glossy-lights sky-sun quick materials cornell-materials; do
      if ! PYTHONPATH=$check/site-packages "$py" "$root/bench/mitsuba_peer.py" render "$root/scenes/$scene.json" \
          --variant llvm_ad_rgb --mode both --width 32 --height 18 --spp 2 --warmup 0 --repeats 1 \
          >"$build/check-$scene.log" 2>&1; then
        echo "peer-pack: $scene does not render with the trimmed package (see $build/check-$scene.log)" >&2
        status=1
      fi
    done
    # The Mitsuba scenes (scenes/mitsuba/), rendered as they are, at 2 spp.
    for xml in "$root"/scenes/mitsuba/*.xml; do
      if ! PYTHONPATH=$check/site-packages "$py" "$root/bench/mitsuba_peer.py" render "$xml" \
          --variant llvm_ad_rgb --mode symbolic --spp 2 --warmup 0 --repeats 1 \
          >"$build/check-$(basename "$xml").log" 2>&1; then
        echo "peer-pack: $xml does not render with the trimmed package (see $build/check-$(basename "$xml").log)" >&2
        status=1
      fi
    done
    [[ $status -eq 0 ]] && echo "peer-pack: every scene renders with the trimmed plugins (LLVM variant)"
  else
    echo "peer-pack: the LLVM variant cannot start here (no libLLVM): render check skipped" >&2
  fi
fi
[[ $status -eq 0 ]] || { echo "peer-pack: checks failed; no tarball written" >&2; exit 1; }

# --- the tarball ------------------------------------------------------------
{
  echo "mitsuba $MITSUBA_VERSION, drjit $DRJIT_VERSION (cp312, manylinux_2_17_x86_64), variant cuda_ad_rgb"
  echo "plugins: $(echo $PLUGINS)"
} >"$tree/MANIFEST.txt"
tmp=$out.tmp
tar -C "$tree" -cf - MANIFEST.txt site-packages | xz -9 -T1 >"$tmp"
mv "$tmp" "$out"
echo "peer-pack: $out: $(stat -c %s "$out") bytes ($(du -sh "$tree" | cut -f1) unpacked)"

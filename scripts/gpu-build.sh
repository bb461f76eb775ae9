#!/usr/bin/env bash
# Builds the binaries for a GPU machine that cannot build (no packages there) into
# .gpu/bin, a folder git ignores, with a build-info.json that names the commit. Its
# own build folder, build-gpu/, holds machine code for the GPU (sm_90: H100, H200),
# where build/ on a machine without a GPU holds PTX only (scripts/cuda-arch.sh).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
export WAVETRACE_BUILD=${WAVETRACE_BUILD:-$root/build-gpu}
export WAVETRACE_CUDA_ARCH=${WAVETRACE_CUDA_ARCH:-90}
# The Python module for the GPU machine's Python (3.12): python3.12 on PATH, else
# pyenv's, else none (WAVETRACE_PYTHON_EXE: another). Read when build-gpu/ is
# first configured.
if [[ -z ${WAVETRACE_PYTHON_EXE:-} ]]; then
  WAVETRACE_PYTHON_EXE=$(command -v python3.12 || ls "${PYENV_ROOT:-$HOME/.pyenv}"/versions/3.12*/bin/python3.12 2>/dev/null | tail -1 || true)
  export WAVETRACE_PYTHON_EXE
fi
bash "$root/scripts/build.sh"
mkdir -p "$root/.gpu/bin"
cp "$WAVETRACE_BUILD/wavetrace" "$WAVETRACE_BUILD"/*_tests "$WAVETRACE_BUILD/wavetrace-gltf-tiles" "$root/.gpu/bin/"
# The shared libraries they load beside them in lib/, where their RPATH looks first:
# every one ldd finds (OpenEXR's family; Assimp's libassimp.so.5 with libdraco.so.7,
# libminizip.so.1 and libz.so.1; the C++ runtime they need), so a new dependency
# comes along by itself. glibc itself is the GPU machine's, and so is Open MPI (its
# mpirun and libmpi.so.40 must be one installation).
rm -rf "$root/.gpu/bin/lib" && mkdir -p "$root/.gpu/bin/lib"
# The Python package (module, stubs), where the build made one, in python/.
rm -rf "$root/.gpu/bin/python"
if [[ -d "$WAVETRACE_BUILD/python/wavetrace" ]]; then
  mkdir -p "$root/.gpu/bin/python" && cp -r "$WAVETRACE_BUILD/python/wavetrace" "$root/.gpu/bin/python/"
fi
for b in "$root/.gpu/bin/wavetrace" "$root/.gpu/bin"/*_tests "$root/.gpu/bin"/python/wavetrace/*.so; do
  if [[ -e $b ]]; then ldd "$b"; fi
done |
  awk '$2 == "=>" && $3 ~ /^\// {print $3}' | sort -u |
  grep -vE '/(libc|libm|libpthread|libdl|librt|libresolv|ld-linux[^/]*)\.so' |
  grep -vE '/lib(mpi|open-pal|open-rte|hwloc|event[^/]*|udev|pmix)\.so' |
  xargs -r cp -L -t "$root/.gpu/bin/lib"
commit=$(git -C "$root" rev-parse HEAD)
dirty=$(git -C "$root" status --porcelain --untracked-files=no | grep -q . && echo true || echo false)
printf '{"commit": "%s", "dirty": %s}\n' "$commit" "$dirty" >"$root/.gpu/bin/build-info.json"
grep -qx '/.gpu/' "$root/.git/info/exclude" 2>/dev/null || echo '/.gpu/' >>"$root/.git/info/exclude"

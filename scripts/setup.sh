#!/usr/bin/env bash
# Installs the Debian packages wavetrace builds against. Safe to run again:
# packages already present are left alone and nothing is fetched.
set -euo pipefail
packages=(cmake ninja-build g++ libglm-dev nlohmann-json3-dev libstb-dev libcli11-dev libgtest-dev zlib1g-dev
  libtinyobjloader-dev libtinygltf-dev libopenexr-dev libpugixml-dev libassimp-dev python3 libopenmpi-dev
  openmpi-bin)
# The Python module (python/, docs/python.md): Debian's Python with its headers, numpy
# and pytest.
if [[ "${WAVETRACE_WITH_PYTHON:-1}" == 1 ]]; then
  packages+=(python3-dev python3-numpy python3-pytest)
fi
if [[ "${WAVETRACE_WITH_PLOTS:-0}" == 1 ]]; then
  packages+=(python3-matplotlib)
fi
# scripts/fuzz.sh: clang, its libFuzzer and sanitizer runtimes, llvm-symbolizer. Version
# 19: bookworm's default clang (14) rejects lambdas that capture structured bindings.
if [[ "${WAVETRACE_WITH_FUZZ:-0}" == 1 ]]; then
  packages+=(clang-19 libclang-rt-19-dev llvm-19)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  sudo_cmd=""
  [[ $(id -u) -ne 0 ]] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
# nanobind, which Debian does not package, from PyPI into .deps/nanobind (its CMake
# files and sources; CMakeLists.txt looks there). Without network the module is not
# built, and the build says so.
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
if [[ "${WAVETRACE_WITH_PYTHON:-1}" == 1 && ! -f "$root/.deps/nanobind/nanobind/cmake/nanobind-config.cmake" ]]; then
  python3 -m pip install --quiet --disable-pip-version-check --no-deps --target "$root/.deps/nanobind" \
    "nanobind==3.1.0" 2>/dev/null ||
    echo "setup: nanobind not installed: the Python module is not built (its tests do not run)" >&2
fi
# Intel Open Image Denoise, which only --denoise needs (src/image/denoise.hpp): the
# libraries of the PyPI wheel pyoidn, unpacked into .deps/oidn/lib. Without network
# the rest of the set-up stands, and --denoise says OIDN is missing.
if [[ "${WAVETRACE_WITH_OIDN:-1}" == 1 ]]; then
  python3 "$(dirname "${BASH_SOURCE[0]}")/fetch-oidn.py" ||
    echo "setup: Open Image Denoise not installed: --denoise will not run (the tests that need it skip)" >&2
fi

#!/usr/bin/env bash
# Builds wavetrace with AddressSanitizer (leaks included) and UndefinedBehaviorSanitizer
# into build-asan/ (or $WAVETRACE_ASAN_BUILD) and runs the whole test suite there:
# the C++ code, the host side of the .cu files (through nvcc -Xcompiler) and the fuzz
# corpus regression tests. Any report fails the test that made it. CI runs this after
# scripts/test.sh; GPU tests skip where there is no CUDA device, as they do there.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${WAVETRACE_ASAN_BUILD:-$root/build-asan}
bash "$root/scripts/setup.sh"
sanitize=(-fsanitize=address -fsanitize=undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
# The mutants of mutation testing are compiled in (include/wavetrace/mutant.hpp; none
# is active unless WAVETRACE_MUTANT names one), so that CI's mutants run in this
# build instead of a third one.
source "$root/scripts/cuda-arch.sh"
if [[ ! -f "$build/build.ninja" ]]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CUDA_ARCHITECTURES="$cuda_arch" \
    -DWAVETRACE_DEVICE_OPT="$cuda_opt" \
    -DCMAKE_CXX_FLAGS="${sanitize[*]}" \
    -DCMAKE_CUDA_FLAGS="${sanitize[*]/#/-Xcompiler=}" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address -fsanitize=undefined" >/dev/null
fi
# -O1, ASan's own advice: the sanitized sources compile in about 40% of -O3's time
# (bsdf_test.cpp: 9 s against 24 s), and the short tests run here are not slowed
# to matter. Host-only (WAVETRACE_DEVICE_CODE=OFF, src/device/kernel_bodies.hpp): the
# sanitizers check host code, and the kernels' device code took most of this build.
# The .cu files' host code at -O0: with no device, most of it does not run here, and
# UBSan at -O1 took tests/stages_test.cu's host compile 374 s (52 s at -O0), the
# last half of this build on 2 cores.
cmake -S "$root" -B "$build" -DWAVETRACE_MUTANTS=ON -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" \
  -DCMAKE_CUDA_FLAGS_RELEASE="-O0 -DNDEBUG" -DWAVETRACE_DEVICE_CODE=OFF -DWAVETRACE_PYTHON=OFF >/dev/null
cuda_arch_configure "$build"
cmake --build "$build" --parallel "$(nproc)"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
cd "$build"
# The long Monte Carlo tests (chi-square, furnace and convergence tests of 10^5 to
# 10^6 samples) run in the release suite (scripts/test.sh) and not here: under the
# sanitizers they took about 800 of the suite's 1200 CPU seconds, repeating code
# that the short tests run under the sanitizers too (docs/testing.md lists them).
# WAVETRACE_ASAN_ALL=1 runs them as well.
statistical='^(BsdfChiSquare|BsdfFurnace|PrincipledLayers|PrincipledLayersRender|LightSamplingRender|GlossyLightSampling|SkyLight|AlphaLamp|BlendChiSquare)\.|^MaterialRender\.(GlassSpheresOfAnyRoughnessVanishUnderAUniformSky|LightSamplingOnAndOffConvergeToTheSameImage)$'
if [[ ${WAVETRACE_ASAN_ALL:-0} == 1 ]]; then statistical='^$'; fi
ctest --output-on-failure --parallel "$(nproc)" -E "$statistical"

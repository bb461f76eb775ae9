// accumulate: adds a finished contribution to its pixel of the film. Fused into the
// stages that end paths (intersect for the sky, shade for emitters): a separate
// pass would re-read the state of every path.
#pragma once

#include "wavetrace/config.hpp"

namespace wt {

WT_HD WT_INLINE void accumulate_one(float* film, uint32_t pixel, const vec3& c) {
#if defined(__CUDA_ARCH__)
  atomicAdd(film + 3 * pixel + 0, c.x);
  atomicAdd(film + 3 * pixel + 1, c.y);
  atomicAdd(film + 3 * pixel + 2, c.z);
#else
  // Host threads: a compare-and-swap loop through the GCC atomic builtins keeps
  // the CPU wavefront free of locks.
  auto add = [](float* p, float v) {
    float old;
    __atomic_load(p, &old, __ATOMIC_RELAXED);
    float desired;
    do {
      desired = old + v;
    } while (!__atomic_compare_exchange(p, &old, &desired, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED));
  };
  add(film + 3 * pixel + 0, c.x);
  add(film + 3 * pixel + 1, c.y);
  add(film + 3 * pixel + 2, c.z);
#endif
}

}  // namespace wt

// The wavefront's stages as per-item functions, with no knowledge of how they are
// launched: the CUDA kernels and the CPU backend both call these. The light
// transport itself is path.hpp's, shared with the megakernel.
#pragma once

#include "queues/path_queue.hpp"
#include "wavetrace/path.hpp"

namespace wt {

// Where a wave draws its paths from and what it has handed out so far.
struct WaveCounters {
  uint32_t queued[2];  // paths waiting in each queue (the current one, and the one shade fills)
  uint32_t next_path;  // first path index not yet generated
  uint32_t hits;       // entries compact kept this bounce
  uint64_t rays;       // rays intersected, all bounces
};

// Paths live in slots [0, live) once generate has filled the free slots.
WT_HD WT_INLINE uint32_t live_paths(uint32_t queued, uint32_t next_path, uint32_t total_paths, uint32_t capacity) {
  uint64_t want = static_cast<uint64_t>(queued) + (total_paths - next_path);
  return static_cast<uint32_t>(want < capacity ? want : capacity);
}

// generate: slot `slot` >= queued starts path next_path + (slot - queued).
template <class Scene>
WT_HD WT_INLINE void generate_one(uint32_t slot, uint32_t queued, uint32_t next_path, const Scene& scene,
                                  const RenderParams& rp, const PathQueue& q) {
  const uint32_t pixels = static_cast<uint32_t>(rp.width) * rp.height;
  PathState s;
  s.path = next_path + (slot - queued);
  s.bounce = 0;
  s.throughput = vec3(1.0f);
  s.ray = primary_ray(scene, rp, s.path % pixels, s.path / pixels);
  q.store(slot, s);
}

// accumulate: adds a finished contribution to the path's pixel. Fused into the
// stages that end paths (a separate pass would re-read the state of every path).
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

// intersect: the closest hit of slot i's ray and its sort entry. A miss adds the
// sky and ends the path (its entry carries kSortKeyMiss, which compact drops).
template <class Scene>
WT_HD WT_INLINE uint32_t intersect_one(uint32_t i, const Scene& scene, const RenderParams& rp, const PathQueue& q,
                                       const HitQueue& hits, float* film) {
  Ray ray{vec3(q.ox[i], q.oy[i], q.oz[i]), vec3(q.dx[i], q.dy[i], q.dz[i])};
  Hit h = intersect_scene(scene, ray);
  hits.store(i, h);
  if (h.sphere < 0) {
    const uint32_t pixels = static_cast<uint32_t>(rp.width) * rp.height;
    vec3 t(q.tr[i], q.tg[i], q.tb[i]);
    accumulate_one(film, q.path[i] % pixels, t * scene.sky.radiance(ray.dir));
    return pack_entry(kSortKeyMiss, i);
  }
  return pack_entry(scene.material_of(h.sphere).sort_key, i);
}

// shade: scatters the path in slot `slot`; on true `next` is the path's next
// bounce, to be pushed into the other queue.
template <class Scene>
WT_HD WT_INLINE bool shade_one(uint32_t slot, const Scene& scene, const RenderParams& rp, const PathQueue& q,
                               const HitQueue& hits, float* film, PathState& next) {
  PathState s = q.load(slot);
  const uint32_t pixels = static_cast<uint32_t>(rp.width) * rp.height;
  const uint32_t pixel = s.path % pixels;
  vec3 radiance(0.0f);
  bool alive = shade_hit(scene, rp, hits.load(slot), pixel, s.path / pixels, s.bounce, s.ray, s.throughput, radiance);
  if (radiance.x != 0.0f || radiance.y != 0.0f || radiance.z != 0.0f) accumulate_one(film, pixel, radiance);
  s.bounce += 1;
  next = s;
  return alive && static_cast<int>(s.bounce) < rp.depth;
}

}  // namespace wt

// intersect: each live ray's closest hit and its sort entry (the material's sort key
// above the slot). Free slots first start their camera paths (generate, fused here).
// A miss adds the sky to the film, ends the path and gets the miss key, which
// compact drops. Then the counters advance (rays, next path) and the other queue is
// emptied for shade's pushes.
#pragma once

#include "queues/push.hpp"
#include "queues/wave.hpp"
#include "stages/accumulate.hpp"
#include "stages/generate.hpp"
#include "wavetrace/path.hpp"

namespace wt {

// Slot i's ray is `ray`; on a miss the path's index and throughput are read from the
// queue. Kinds: the primitive kinds the scene holds (a superset gives the same hits).
template <uint32_t Kinds = kAllKinds, class Scene>
WT_HD WT_INLINE uint32_t intersect_one(uint32_t i, const Ray& ray, const Scene& scene, const RenderParams& rp,
                                       const PathQueue& q, const HitQueue& hits, float* film,
                                       const PassPixels& pass = {}) {
  Hit h = intersect_scene<Kinds>(scene, ray);
  store_hit<Kinds>(hits, i, h);
  if (h.missed()) {
    vec3 t(q.tr[i], q.tg[i], q.tb[i]);
    accumulate_one(film, pass_pixel(q.path[i], pass, rp.width, rp.height), t * sky_seen(scene, rp, ray.dir, q.pdf[i]));
    return pack_entry(kSortKeyMiss, i);
  }
  return pack_entry(scene.material(shading_material_index<Kinds>(scene, ray, h)).sort_key, i);
}

// Slot i's ray as the queue holds it.
WT_HD WT_INLINE Ray queued_ray(const PathQueue& q, uint32_t i) {
  return Ray{vec3(q.ox[i], q.oy[i], q.oz[i]), vec3(q.dx[i], q.dy[i], q.dz[i])};
}

// Over every slot of the wave: free slots start a path, then every live slot's ray
// is traced. Slots past the live ones get a miss entry, so that compact, which runs
// over the whole capacity without the host knowing the count, drops them.
template <uint32_t Kinds>
struct IntersectItem {
  // On the GPU, at most 64 registers a thread for scenes with triangles
  // (cuda/executor.cuh): their traversal waits on memory, and the occupancy this
  // buys traces the mesh scenes 5-6% faster than the 69 registers it takes
  // unbounded. Spheres alone need 44 and keep the unbounded kernel.
  static constexpr int kMinBlocksPerSm = spheres_only(Kinds) ? 0 : 4;
  SceneView scene;
  RenderParams rp;
  PathQueue queue;
  HitQueue hits;
  uint32_t* entries;
  WaveCounters* counters;  // read, but for the key mask this bounce's hits set
  int cur;
  uint32_t total_paths;  // of this pass
  uint32_t first_sample;  // of this pass
  uint32_t capacity;
  float* film;
  PassPixels pass{};  // the pass's pixels: every one by default

  WT_HD void operator()(uint32_t i) const {
    const uint32_t queued = counters->queued[cur];
    const uint32_t next_path = counters->next_path;
    if (i >= live_paths(queued, next_path, total_paths, capacity)) {
      entries[i] = pack_entry(kSortKeyMiss, i);
      return;
    }
    Ray ray;
    if (i >= queued) {
      const PathState s = start_path(i, queued, next_path, first_sample, scene, rp, pass);
      queue.store(i, s);
      ray = s.ray;
    } else {
      ray = queued_ray(queue, i);
    }
    const uint32_t entry = intersect_one<Kinds>(i, ray, scene, rp, queue, hits, film, pass);
    entries[i] = entry;
    const uint32_t key = entry_key(entry);
    or_bits(&counters->key_mask[cur], key < kSortKeyMiss ? 1u << key : 0u);
  }
};

// One item, launched after every intersect item has read the counters. It also
// counts the shadow rays the last bounce traced and empties their queue, which the
// shadow stage has read by now.
struct AdvanceCountersItem {
  WaveCounters* counters;
  int cur;
  uint32_t total_paths;
  uint32_t capacity;

  WT_HD void operator()(uint32_t) const {
    WaveCounters& c = *counters;
    const uint32_t queued = c.queued[cur];
    const uint32_t live = live_paths(queued, c.next_path, total_paths, capacity);
    c.rays += live;
    c.next_path += live - queued;
    c.queued[cur] = live;
    c.queued[1 - cur] = 0;
    c.shadow_rays += c.shadows;
    c.shadows = 0;
    c.key_mask[1 - cur] = 0;
  }
};

// Where the wave's next new path starts: `first`, a block of paths taken from a
// PathFeed (render_types.hpp) once the block before it is used up. One thread.
struct SetNextPathItem {
  WaveCounters* counters;
  uint32_t first;

  WT_HD void operator()(uint32_t) const { counters->next_path = first; }
};

}  // namespace wt

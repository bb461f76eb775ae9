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

// What slot i's traced ray `ray` found: the hit is kept for shade; a miss adds the
// sky to the film (the path's index and throughput read from the queue). Returns the
// slot's sort entry.
template <uint32_t Kinds = kAllKinds, class Scene>
WT_HD WT_INLINE uint32_t record_hit(uint32_t i, const Ray& ray, const Hit& h, const Scene& scene,
                                    const RenderParams& rp, const PathQueue& q, const HitQueue& hits, float* film) {
  store_hit<Kinds>(hits, i, h);
  if (h.missed()) {
    vec3 t(q.tr[i], q.tg[i], q.tb[i]);
    accumulate_one(film, path_pixel(q.path[i], rp.width, rp.height), t * sky_seen(scene, rp, ray.dir, q.pdf[i]));
    return pack_entry(kSortKeyMiss, i);
  }
  return pack_entry(scene.material(material_index<Kinds>(scene, h)).sort_key, i);
}

// Slot i's ray `ray` traced and recorded. Kinds: the primitive kinds the scene holds
// (a superset gives the same hits).
template <uint32_t Kinds = kAllKinds, class Scene>
WT_HD WT_INLINE uint32_t intersect_one(uint32_t i, const Ray& ray, const Scene& scene, const RenderParams& rp,
                                       const PathQueue& q, const HitQueue& hits, float* film) {
  return record_hit<Kinds>(i, ray, intersect_scene<Kinds>(scene, ray), scene, rp, q, hits, film);
}

// Slot i's ray as the queue holds it.
WT_HD WT_INLINE Ray queued_ray(const PathQueue& q, uint32_t i) {
  return Ray{vec3(q.ox[i], q.oy[i], q.oz[i]), vec3(q.dx[i], q.dy[i], q.dz[i])};
}

// Over every slot of the wave: free slots start a path, then every live slot's ray
// is traced. Slots past the live ones get a miss entry, so that compact, which runs
// over the whole capacity without the host knowing the count, drops them.
//
// An item is a slot's whole work (operator()), and also its three parts, so that the
// GPU can run scenes with triangles in fetching warps (cuda/executor.cuh: a warp
// suspends its walks once enough of its lanes are done and hands those lanes new
// slots): wave() the counters once, begin(i) a live slot's ray, the Walk over the
// scene, and finish(i) what it found. Both ways give every slot the same hit.
template <uint32_t Kinds>
struct IntersectItem {
  // On the GPU, at most 64 registers a thread for scenes with triangles
  // (cuda/executor.cuh): their traversal waits on memory, and the occupancy this
  // buys traces the mesh scenes 5-6% faster than the 69 registers it takes
  // unbounded. Spheres alone need 44 and keep the unbounded kernel.
  static constexpr int kMinBlocksPerSm = spheres_only(Kinds) ? 0 : 4;
  // Scenes with triangles are traced by fetching warps on the GPU; spheres alone,
  // whose walks are short and alike, by a thread a slot.
  static constexpr bool kFetching = !spheres_only(Kinds);
  using Walk = Traversal<Kinds>;
  SceneView scene;
  RenderParams rp;
  PathQueue queue;
  HitQueue hits;
  uint32_t* entries;
  WaveCounters* counters;  // read, but for the key mask this bounce's hits set and the fetch counter
  int cur;
  uint32_t total_paths;  // of this pass
  uint32_t first_sample;  // of this pass
  uint32_t capacity;
  float* film;
  int min_busy;  // fetching warps' (RenderOptions::fetch_min_busy); 0: a thread a slot

  // Where the wave stands this bounce: the paths queued, the next new one, and the
  // slots [0, live) that hold a path once the free ones have started theirs.
  struct Wave {
    uint32_t queued, next_path, live;
  };
  WT_HD WT_INLINE Wave wave() const {
    const uint32_t queued = counters->queued[cur];
    const uint32_t next_path = counters->next_path;
    return Wave{queued, next_path, live_paths(queued, next_path, total_paths, capacity)};
  }
  // The counter fetching warps take slots from (AdvanceCountersItem clears it).
  WT_HD uint32_t* fetch_counter() const { return &counters->fetched; }

  // A slot past the live ones: the entry compact drops.
  WT_HD WT_INLINE void skip(uint32_t i) const { entries[i] = pack_entry(kSortKeyMiss, i); }

  // Live slot i's ray: a free slot starts its path first.
  WT_HD WT_INLINE Ray begin(uint32_t i, const Wave& w) const {
    if (i >= w.queued) {
      const PathState s = start_path(i, w.queued, w.next_path, first_sample, scene, rp);
      queue.store(i, s);
      return s.ray;
    }
    return queued_ray(queue, i);
  }

  // What slot i's ray found: its hit and sort entry, and its key in the mask.
  WT_HD WT_INLINE void finish(uint32_t i, const Ray& ray, const Hit& h) const {
    const uint32_t entry = record_hit<Kinds>(i, ray, h, scene, rp, queue, hits, film);
    entries[i] = entry;
    const uint32_t key = entry_key(entry);
    or_bits(&counters->key_mask[cur], key < kSortKeyMiss ? 1u << key : 0u);
  }

  WT_HD void operator()(uint32_t i) const {
    const Wave w = wave();
    if (i >= w.live) {
      skip(i);
      return;
    }
    const Ray ray = begin(i, w);
    finish(i, ray, intersect_scene<Kinds>(scene, ray));
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
    c.fetched = 0;
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

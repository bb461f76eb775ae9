// shade: scatters each listed path (in sorted order, so a warp mostly runs one
// material's code), adds emission to the film, and pushes survivors into the other
// queue, which leaves the next queue dense.
#pragma once

#include "queues/push.hpp"
#include "queues/wave.hpp"
#include "stages/accumulate.hpp"
#include "wavetrace/path.hpp"

namespace wt {

// Scatters the path in slot `slot` (of the pass whose first sample is
// `first_sample`); on true `next` is the path's next bounce.
// Kinds: the primitive kinds the scene holds (a superset shades the same).
template <uint32_t Kinds = kAllKinds, class Scene>
WT_HD WT_INLINE bool shade_one(uint32_t slot, uint32_t first_sample, const Scene& scene, const RenderParams& rp,
                               const PathQueue& q, const HitQueue& hits, float* film, PathState& next) {
  PathState s = q.load(slot);
  const uint32_t pixels = static_cast<uint32_t>(rp.width) * rp.height;
  const uint32_t pixel = s.path % pixels;
  vec3 radiance(0.0f);
  bool alive = shade_hit<Kinds>(scene, rp, hits.load(slot), pixel, first_sample + s.path / pixels, s.bounce, s.ray,
                         s.throughput, radiance);
  if (radiance.x != 0.0f || radiance.y != 0.0f || radiance.z != 0.0f) accumulate_one(film, pixel, radiance);
  s.bounce += 1;
  next = s;
  return alive && static_cast<int>(s.bounce) < rp.depth;
}

// Over the `count` entries of `list`.
template <uint32_t Kinds>
struct ShadeItem {
  SceneView scene;
  RenderParams rp;
  PathQueue queue;
  HitQueue hits;
  PathQueue next_queue;
  uint32_t* next_count;
  const uint32_t* list;
  uint32_t first_sample;  // of this pass
  float* film;

  WT_HD void operator()(uint32_t i) const {
    PathState next;
    const bool alive = shade_one<Kinds>(entry_slot(list[i]), first_sample, scene, rp, queue, hits, film, next);
    // Every item reaches the push, so that a warp reserves its slots with one atomic.
    const uint32_t slot = push_slot(next_count, alive);
    if (alive) next_queue.store(slot, next);
  }
};

}  // namespace wt

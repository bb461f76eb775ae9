// shade: scatters each listed path (in sorted order, so a warp mostly runs one
// material's code), adds emission to the film, queues its light sample for the
// shadow stage, and pushes survivors into the other queue, which leaves the next
// queue dense.
#pragma once

#include "queues/push.hpp"
#include "queues/wave.hpp"
#include "stages/accumulate.hpp"
#include "wavetrace/path.hpp"

namespace wt {

// Scatters the path in slot `slot` (of the pass whose first sample is
// `first_sample`); on true `next` is the path's next bounce.
// Kinds: the primitive kinds the scene holds (a superset shades the same).
template <uint32_t Kinds = kEverything, class Scene>
// `shadow` (with shadow.valid) is the light sample taken there, for `pixel`.
WT_HD WT_INLINE bool shade_one(uint32_t slot, uint32_t first_sample, const Scene& scene, const RenderParams& rp,
                               const PathQueue& q, const HitQueue& hits, float* film, PathState& next,
                               ShadowRay& shadow, uint32_t& pixel, const PassPixels& pass = {}) {
  PathState s = q.load(slot);
  const uint32_t pixels = pass_pixels(pass, rp.width, rp.height);
  pixel = pass_pixel(s.path, pass, rp.width, rp.height);
  vec3 radiance(0.0f);
  bool alive = shade_hit<Kinds>(scene, rp, load_hit<Kinds>(hits, slot), pixel, first_sample + s.path / pixels, s.bounce, s.ray,
                                s.throughput, radiance, s.pdf, shadow);
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
  ShadowQueue shadows;
  uint32_t* shadow_count;
  const uint32_t* list;
  uint32_t first_sample;  // of this pass
  float* film;
  PassPixels pass{};  // the pass's pixels: every one by default

  // Forced inline: called through the executor, a shade too large for nvcc's own
  // choice becomes a call with a 736-byte stack frame (the microfacet kernels, 2x
  // slower on the materials scene).
  WT_HD WT_INLINE void operator()(uint32_t i) const {
    PathState next;
    ShadowRay shadow;
    uint32_t pixel;
    const bool alive =
        shade_one<Kinds>(entry_slot(list[i]), first_sample, scene, rp, queue, hits, film, next, shadow, pixel, pass);
    // Every item reaches the pushes, so that a warp reserves its slots with one atomic.
    const uint32_t slot = push_slot(next_count, alive);
    if (alive) next_queue.store(slot, next);
    const uint32_t shadow_slot = push_slot(shadow_count, shadow.valid);
    if (shadow.valid) shadows.store(shadow_slot, ShadowState{shadow.ray, shadow.tmax, shadow.contribution, pixel});
  }
};

// shadow: each queued light sample's shadow ray, traced until anything blocks it;
// an unblocked one adds its contribution to the film. Launched over the wave's
// capacity: the count is on the device, where shade left it.
template <uint32_t Kinds>
struct ShadowItem {
  // On the GPU, registers bounded as intersect's are (stages/intersect.hpp).
  static constexpr int kMinBlocksPerSm = spheres_only(Kinds) ? 0 : 4;
  SceneView scene;
  ShadowQueue shadows;
  const WaveCounters* counters;
  float* film;

  WT_HD void operator()(uint32_t i) const {
    if (i >= counters->shadows) return;
    const ShadowState s = shadows.load(i);
    if (!occluded<Kinds>(scene, s.ray, s.tmax)) accumulate_one(film, s.pixel, s.contribution);
  }
};

}  // namespace wt

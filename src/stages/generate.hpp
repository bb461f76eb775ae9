// generate: fills the free slots of the current queue with new camera paths while
// paths remain (path regeneration), so the wave stays full until the last paths.
#pragma once

#include "queues/wave.hpp"
#include "wavetrace/path.hpp"

namespace wt {

// Slot `slot` >= queued starts path next_path + (slot - queued).
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

// Over every slot of the wave; the free ones read the counters to know their path.
struct GenerateItem {
  SceneView scene;
  RenderParams rp;
  PathQueue queue;
  const WaveCounters* counters;
  int cur;
  uint32_t total_paths;
  uint32_t capacity;

  WT_HD void operator()(uint32_t slot) const {
    const uint32_t queued = counters->queued[cur];
    const uint32_t next_path = counters->next_path;
    if (slot < queued || slot >= live_paths(queued, next_path, total_paths, capacity)) return;
    generate_one(slot, queued, next_path, scene, rp, queue);
  }
};

}  // namespace wt

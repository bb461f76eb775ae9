// generate: a free slot of the current queue starts a new camera path while paths
// remain (path regeneration), so the wave stays full until the last paths. It runs
// inside intersect's launch (stages/intersect.hpp): the thread that starts a path
// traces its first ray at once, and the wave is not walked twice per bounce.
#pragma once

#include "queues/wave.hpp"
#include "wavetrace/path.hpp"

namespace wt {

// The path that free slot `slot` (>= queued) starts: path next_path + (slot - queued)
// of the pass whose first sample is `first_sample`, over the pass's pixels.
template <class Scene>
WT_HD WT_INLINE PathState start_path(uint32_t slot, uint32_t queued, uint32_t next_path, uint32_t first_sample,
                                     const Scene& scene, const RenderParams& rp, const PassPixels& pass = {}) {
  const uint32_t pixels = pass_pixels(pass, rp.width, rp.height);
  PathState s;
  s.path = next_path + (slot - queued);
  s.bounce = 0;
  s.throughput = vec3(1.0f);
  s.pdf = 0.0f;
  s.ray = primary_ray(scene, rp, pass_pixel(s.path, pass, rp.width, rp.height), first_sample + s.path / pixels);
  return s;
}

}  // namespace wt

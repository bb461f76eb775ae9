// How a render's samples are split into passes: every backend and kernel renders
// samples [first, first + count) of every pixel as a list of these.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "render/render_types.hpp"

namespace wt {

struct SamplePass {
  int32_t first;  // the pass's first sample of every pixel
  int32_t count;  // its samples per pixel
};

// Samples [first, first + count) of `pixels` pixels in passes of as even a size as
// possible: at least `min_passes` (as far as there are samples), at most
// `samples_per_pass` samples each (0: no limit) unless that gives fewer than
// `min_paths` paths a pass, and never more than `max_paths` paths in a pass.
inline std::vector<SamplePass> plan_passes(uint64_t pixels, int32_t first, int32_t count, int32_t min_passes,
                                           int32_t samples_per_pass, uint64_t max_paths, uint64_t min_paths = 0) {
  if (count <= 0) return {};
  const int64_t by_paths = static_cast<int64_t>(std::max<uint64_t>(max_paths / pixels, 1));
  const int64_t fill = static_cast<int64_t>((min_paths + pixels - 1) / pixels);
  const int64_t asked = samples_per_pass > 0 ? std::max<int64_t>(samples_per_pass, fill) : by_paths;
  const int64_t largest = std::min<int64_t>(asked, by_paths);
  const int64_t n = std::min<int64_t>(count, std::max<int64_t>(min_passes, (count + largest - 1) / largest));
  std::vector<SamplePass> passes;
  int32_t at = first;
  for (int64_t p = 0; p < n; ++p) {
    const int32_t samples = static_cast<int32_t>(count / n + (p < count % n ? 1 : 0));
    passes.push_back(SamplePass{at, samples});
    at += samples;
  }
  return passes;
}

// The passes of a render with these options. What the kernel wants: `min_passes`
// (e.g. for progress lines between its launches), and `min_paths` a pass (the
// wavefront: enough to refill its wave a few times, since every pass ends with the
// wave draining).
inline std::vector<SamplePass> plan_passes(const RenderOptions& o, int32_t min_passes, uint64_t min_paths = 0) {
  const RenderParams& rp = o.params;
  const int32_t count = o.sample_count > 0 ? o.sample_count : rp.spp - o.first_sample;
  return plan_passes(std::max<uint64_t>(rendered_pixels(o), 1), o.first_sample, count, min_passes,
                     o.samples_per_pass, o.max_paths_per_pass, min_paths);
}

}  // namespace wt

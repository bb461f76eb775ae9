#include "cpu/cpu_wavefront.hpp"

#include "cpu/executor.hpp"
#include "stages/wavefront.hpp"

namespace wt::cpu {

namespace {
// A quarter of a million slots keep every core busy through the last bounces while
// the wave's state (about 17 MB) stays small next to the host's memory.
constexpr int64_t kDefaultWaveSlots = int64_t(1) << 18;
}  // namespace

int64_t choose_wave_size(int64_t requested, const RenderParams& rp) {
  const int64_t total = static_cast<int64_t>(rp.width) * rp.height * rp.spp;
  return wt::choose_wave_size(requested, total, WaveBudget{kDefaultWaveSlots, 0, wavefront_bytes<Executor>(1)});
}

RenderResult render_wavefront(const SceneView& scene, int key_bits, const RenderOptions& options, int64_t wave_size) {
  Executor ex(options.threads);
  return wt::render_wavefront(ex, scene, key_bits, options, wave_size);
}

}  // namespace wt::cpu

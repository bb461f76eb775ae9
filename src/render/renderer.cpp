#include "render/renderer.hpp"

#include <string>

#include "cpu/cpu_backend.hpp"
#include "cuda/cuda_backend.hpp"
#include "render/settings.hpp"

namespace wt {

const char* backend_name(Backend b) { return b == Backend::Cuda ? "cuda" : "cpu"; }


void validate_params(const RenderParams& p) {
  for (SettingId id : render_settings()) check_setting(id, get_param(p, id));
  // Path indices are 32-bit on every backend.
  if (static_cast<uint64_t>(p.width) * p.height * p.spp > 0xffffffffull) {
    throw SceneError("spp: width x height x spp must stay below 2^32 paths (got " +
                     std::to_string(static_cast<uint64_t>(p.width) * p.height * p.spp) + ")");
  }
}

RenderParams default_params(const Scene& scene) { return scene.render; }

RenderResult render(const Scene& scene, const RenderOptions& options) {
  validate_params(options.params);
  if (options.wave_size != 0) check_setting(SettingId::WaveSize, options.wave_size);
  RenderResult r = options.backend == Backend::Cuda ? cuda::render(scene, options) : cpu::render(scene, options);
  // The backends return each pixel's sum over its samples: the mean is taken here, once.
  const float inv = 1.0f / static_cast<float>(options.params.spp);
  for (float& v : r.rgb) v *= inv;
  r.radiance = Radiance::MeanOfSamples;
  return r;
}

}  // namespace wt

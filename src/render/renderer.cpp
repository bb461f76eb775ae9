#include "render/renderer.hpp"

#include <string>

#include "cpu/cpu_backend.hpp"
#include "cuda/cuda_backend.hpp"
#include "queues/wave.hpp"

namespace wt {

const char* backend_name(Backend b) { return b == Backend::Cuda ? "cuda" : "cpu"; }

const char* kernel_name(Kernel k) {
  switch (k) {
    case Kernel::Megakernel: return "megakernel";
    case Kernel::MegakernelConstant: return "megakernel-constant";
    case Kernel::Wavefront: return "wavefront";
    case Kernel::WavefrontUnsorted: return "wavefront-unsorted";
  }
  return "?";
}

namespace {
void require_range(const char* name, int64_t value, int64_t lo, int64_t hi) {
  if (value < lo || value > hi) {
    throw SceneError(std::string(name) + ": must be in " + std::to_string(lo) + ".." + std::to_string(hi) +
                     " (got " + std::to_string(value) + ")");
  }
}
}  // namespace

void validate_params(const RenderParams& p) {
  require_range("width", p.width, 1, kMaxImageSide);
  require_range("height", p.height, 1, kMaxImageSide);
  require_range("spp", p.spp, 1, kMaxSpp);
  require_range("depth", p.depth, 1, kMaxPathDepth);
  require_range("roulette_depth", p.roulette_depth, 0, 1 << 30);
  // Path indices are 32-bit on every backend.
  if (static_cast<uint64_t>(p.width) * p.height * p.spp > 0xffffffffull) {
    throw SceneError("spp: width x height x spp must stay below 2^32 paths (got " +
                     std::to_string(static_cast<uint64_t>(p.width) * p.height * p.spp) + ")");
  }
}

RenderParams default_params(const Scene& scene) {
  RenderParams p{};
  p.width = scene.render.width;
  p.height = scene.render.height;
  p.spp = scene.render.spp;
  p.depth = scene.render.depth;
  p.roulette_depth = scene.render.roulette_depth;
  p.seed = scene.render.seed;
  return p;
}

RenderResult render(const Scene& scene, const RenderOptions& options) {
  validate_params(options.params);
  if (options.wave_size != 0) {
    require_range("wave_size", options.wave_size, kMinWaveSlots, static_cast<int64_t>(kMaxWaveSize));
  }
  RenderResult r = options.backend == Backend::Cuda ? cuda::render(scene, options) : cpu::render(scene, options);
  // The backends return each pixel's sum over its samples: the mean is taken here, once.
  const float inv = 1.0f / static_cast<float>(options.params.spp);
  for (float& v : r.rgb) v *= inv;
  r.radiance = Radiance::MeanOfSamples;
  return r;
}

}  // namespace wt

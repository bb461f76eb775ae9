#include "dispatch/renderer.hpp"

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>

#include "cpu/cpu_backend.hpp"
#include "cpu/parallel.hpp"
#include "cuda/cuda_backend.hpp"
#include "dispatch/split.hpp"
#include "render/adaptive.hpp"
#include "errors/errors.hpp"
#include "render/settings.hpp"

namespace wt {

const char* backend_name(Backend b) { return b == Backend::Cuda ? "cuda" : "cpu"; }

namespace {

// On one device, the backend's own render; on several (options.devices), the split
// over the backend's renderer of each, labelled "cuda:1", "cpu:0", ...
void check_kernel_runs(const RenderOptions& options) {
  if (!kernel_runs_on(options.kernel, options.backend)) {
    throw InputError(std::string("kernel: ") + kernel_name(options.kernel) +
                     " needs the cuda backend (constant memory is a GPU memory)");
  }
}

// The devices' labels: "cuda:1", "cpu:0", ...
std::vector<std::string> device_labels(const RenderOptions& options) {
  std::vector<std::string> labels;
  for (int d : options.devices) labels.push_back(std::string(backend_name(options.backend)) + ":" + std::to_string(d));
  return labels;
}

// The backend's renderer of device `i` of the options' devices.
DeviceRenderer device_renderer(const Scene& scene, const RenderOptions& options, size_t i) {
  return options.backend == Backend::Cuda ? cuda::device_renderer(scene, options, i)
                                          : cpu::device_renderer(scene, options, i);
}

RenderResult render_on_backend(const Scene& scene, const RenderOptions& options) {
  check_kernel_runs(options);
  const bool gpu = options.backend == Backend::Cuda;
  if (gpu) cuda::check_devices(options);
  if (options.devices.size() <= 1) return gpu ? cuda::render(scene, options) : cpu::render(scene, options);
  return render_split(options, device_labels(options),
                      [&](size_t i) { return device_renderer(scene, options, i); });
}

}  // namespace


void validate_params(const RenderParams& p) {
  for (SettingId id : render_settings()) check_setting(id, get_param(p, id));
}

RenderParams default_params(const Scene& scene) { return scene.render; }

namespace {

// Adaptive sampling on the options' devices, its rounds rendered by `rounds`.
RenderResult render_adaptively(const Scene& scene, const RenderOptions& options, const AdaptiveHooks& hooks) {
  return render_adaptive_rounds(adaptive_rounds(scene, options), options, hooks);
}

}  // namespace

ChunkRenderer adaptive_rounds(const Scene& scene, const RenderOptions& options) {
  if (options.initial_film || options.after_pass || options.path_feed || options.device_film) {
    throw std::logic_error("an adaptive render keeps its checkpoints and ranks through AdaptiveHooks");
  }
  check_kernel_runs(options);
  if (options.backend == Backend::Cuda) cuda::check_devices(options);
  if (options.devices.size() <= 1) {
    RenderOptions one = options;
    one.devices = {options.devices.empty() ? 0 : options.devices.front()};
    auto device = std::make_shared<DeviceRenderer>(device_renderer(scene, one, 0));
    return [device](const RenderOptions& round) { return device->render(round); };
  }
  auto split = std::make_shared<PixelSplit>(options, device_labels(options),
                                            [&](size_t i) { return device_renderer(scene, options, i); });
  return [split](const RenderOptions& round) { return split->render(round); };
}

RenderResult render_adaptive_rounds(const ChunkRenderer& rounds, const RenderOptions& options,
                                    const AdaptiveHooks& hooks) {
  if (options.min_spp > options.params.spp) {
    throw InputError("--min-spp: " + std::to_string(options.min_spp) + " is more than the " +
                     std::to_string(options.params.spp) + " samples per pixel (--spp, the most a pixel takes)");
  }
  RenderOptions o = options;
  o.devices.clear();
  const double threshold = options.noise_threshold > 0 ? options.noise_threshold : -1.0;
  RenderResult r = render_adaptive(rounds, o, threshold, resolved_min_spp(options.min_spp, options.params.spp), hooks);
  if (options.progress) options.progress(1.0, r.rays, r.seconds);
  return r;
}

RenderResult render(const Scene& scene, const RenderOptions& options) { return render(scene, options, AdaptiveHooks{}); }

RenderResult render(const Scene& scene, const RenderOptions& options, const AdaptiveHooks& hooks) {
  if (options.noise_threshold != 0) {
    validate_render(options);
    return render_adaptively(scene, options, hooks);
  }
  RenderResult r = render_sums(scene, options);
  take_mean(r);
  return r;
}

void validate_render(const RenderOptions& options) {
  const RenderParams& p = options.params;
  validate_params(p);
  if (options.wave_size != 0) check_setting(SettingId::WaveSize, options.wave_size);
  if (options.first_sample < 0 || options.first_sample >= p.spp || options.sample_count < 0 ||
      options.sample_count > p.spp - options.first_sample) {
    throw InputError("samples: " + std::to_string(options.first_sample) + " + " +
                     std::to_string(options.sample_count) + " does not lie within the " + std::to_string(p.spp) +
                     " samples per pixel");
  }
  const size_t film_floats = static_cast<size_t>(p.width) * p.height * 3;
  if (options.initial_film && options.initial_film->size() != film_floats) {
    throw InputError("film: the sums to start from hold " + std::to_string(options.initial_film->size()) +
                     " values; a " + std::to_string(p.width) + " x " + std::to_string(p.height) + " film holds " +
                     std::to_string(film_floats));
  }
}

bool renders_to_device(const RenderOptions& options) {
  return options.backend == Backend::Cuda && options.devices.size() <= 1 && options.noise_threshold == 0 &&
         options.first_sample == 0 && !options.initial_film && !options.after_pass && !options.path_feed &&
         !options.device_film && !options.active_pixels;
}

RenderResult render_to_device(const Scene& scene, const RenderOptions& options, cuda::DeviceImage& image,
                              const cuda::ImageMemory& memory) {
  if (!renders_to_device(options)) throw std::logic_error("render_to_device: options it does not take");
  validate_render(options);
  check_kernel_runs(options);
  cuda::check_devices(options);
  image = cuda::DeviceImage{};
  if (memory) image.rgba = memory(static_cast<size_t>(options.params.width) * options.params.height * 4);
  return cuda::render_image(scene, options, image);
}

RenderResult render_sums(const Scene& scene, const RenderOptions& options) {
  validate_render(options);
  return render_on_backend(scene, options);
}

AovSums render_aovs(const Scene& scene, const RenderOptions& options, const std::vector<int32_t>* pixel_samples) {
  validate_params(options.params);
  const size_t pixels = static_cast<size_t>(options.params.width) * options.params.height;
  if (pixel_samples && pixel_samples->size() != pixels) {
    throw std::logic_error("render_aovs: a count of samples for each pixel, or none");
  }
  AovSums out;
  if (options.backend == Backend::Cpu) {
    out = cpu::render_aov_sums(scene, options, pixel_samples);
  } else {
    cuda::check_devices(options);
    out = cuda::render_aov_sums(scene, options, pixel_samples);
  }
  if (pixel_samples) out.pixel_samples = *pixel_samples;
  return out;
}

std::shared_ptr<ResidentScenes> keep_scene(const Scene& scene, Backend backend) {
  return backend == Backend::Cuda ? cuda::keep_scene(scene) : nullptr;
}

int64_t scene_uploads(const ResidentScenes* resident) { return resident ? cuda::uploads(*resident) : 0; }

void take_mean(RenderResult& r) {
  const float inv = 1.0f / static_cast<float>(r.samples);
  // Over the host's threads: a 1080p film is 6 M floats, a share of a short render.
  float* v = r.rgb.data();
  cpu::parallel_for(static_cast<int64_t>(r.rgb.size()), int64_t(1) << 18, cpu::thread_count(0),
                    [v, inv](int64_t begin, int64_t end, int) {
                      for (int64_t i = begin; i < end; ++i) v[i] *= inv;
                    });
  r.radiance = Radiance::MeanOfSamples;
}

}  // namespace wt

#include "render/settings.hpp"

#include <cstdio>

#include "errors/errors.hpp"
#include "queues/wave.hpp"

namespace wt {

const std::vector<Setting>& settings() {
  static const RenderDefaults d;
  static const std::vector<Setting> table = {
      {SettingId::Width, "width", "--width", SettingType::Int32, 1, kMaxImageSide, d.width, "image width in pixels"},
      {SettingId::Height, "height", "--height", SettingType::Int32, 1, kMaxImageSide, d.height,
       "image height in pixels"},
      {SettingId::Spp, "spp", "--spp", SettingType::Int32, 1, kMaxSpp, d.spp, "samples per pixel"},
      {SettingId::Depth, "depth", "--depth", SettingType::Int32, 1, kMaxPathDepth, d.depth, "most rays per path"},
      {SettingId::RouletteDepth, "roulette_depth", "--roulette-depth", SettingType::Int32, 0, kMaxRouletteDepth,
       d.roulette_depth, "Russian roulette from this many bounces on"},
      {SettingId::Seed, "seed", "--seed", SettingType::UInt32, 0, UINT32_MAX, d.seed, "render seed"},
      {SettingId::Nee, "nee", "--nee", SettingType::Int32, 0, 1, d.nee,
       "1: sample the emitters at diffuse hits (next-event estimation, weighted by MIS); 0: pure path tracing"},
      {SettingId::Warmup, "warmup", "--warmup", SettingType::Int32, 0, 100, 0, "untimed renders before the timed one"},
      {SettingId::WaveSize, "wave_size", "--wave-size", SettingType::Int64, kMinWaveSlots,
       static_cast<int64_t>(kMaxWaveSize), 0, "wavefront path slots (default: chosen from free memory)"},
      {SettingId::Threads, "threads", "--threads", SettingType::Int32, 1, 1024, 0, "CPU threads (default: all cores)"},
      {SettingId::CheckpointEvery, "checkpoint_every", "--checkpoint-every", SettingType::Int32, 1, 30 * 24 * 3600,
       300, "seconds between checkpoints (with --checkpoint)"},
      {SettingId::MegakernelBatch, "megakernel_batch", "--megakernel-batch", SettingType::Int32, 0, 1024, 0,
       "CUDA megakernels: samples a launch of one thread a pixel and sample takes (default 0: chosen by the "
       "image's size and the device's; 1: one thread a pixel); the image is the same"},
      {SettingId::MinSpp, "min_spp", "--min-spp", SettingType::Int32, 0, kMaxSpp, 0,
       "with --noise-threshold: the samples every pixel takes first (default 0: 16, or spp where less)"},
      {SettingId::NoiseThreshold, "noise_threshold", "--noise-threshold", SettingType::Real, 0, 0, 0,
       "adaptive sampling: each pixel stops once its neighbourhood's relative error is at most this (e.g. 0.01), "
       "after --min-spp samples and at most --spp",
       0.0, 1.0},
  };
  return table;
}

const Setting& setting(SettingId id) { return settings()[static_cast<size_t>(id)]; }

const std::vector<SettingId>& render_settings() {
  static const std::vector<SettingId> ids = {SettingId::Width,         SettingId::Height, SettingId::Spp,
                                             SettingId::Depth,         SettingId::RouletteDepth,
                                             SettingId::Seed,          SettingId::Nee};
  return ids;
}

int64_t get_param(const RenderParams& p, SettingId id) {
  switch (id) {
    case SettingId::Width: return p.width;
    case SettingId::Height: return p.height;
    case SettingId::Spp: return p.spp;
    case SettingId::Depth: return p.depth;
    case SettingId::RouletteDepth: return p.roulette_depth;
    case SettingId::Seed: return p.seed;
    case SettingId::Nee: return p.nee;
    default: throw std::logic_error(std::string("not a render parameter: ") + setting(id).key);
  }
}

void set_param(RenderParams& p, SettingId id, int64_t value) {
  switch (id) {
    case SettingId::Width: p.width = static_cast<int32_t>(value); break;
    case SettingId::Height: p.height = static_cast<int32_t>(value); break;
    case SettingId::Spp: p.spp = static_cast<int32_t>(value); break;
    case SettingId::Depth: p.depth = static_cast<int32_t>(value); break;
    case SettingId::RouletteDepth: p.roulette_depth = static_cast<int32_t>(value); break;
    case SettingId::Seed: p.seed = static_cast<uint32_t>(value); break;
    case SettingId::Nee: p.nee = static_cast<int32_t>(value); break;
    default: throw std::logic_error(std::string("not a render parameter: ") + setting(id).key);
  }
}

void check_setting(SettingId id, int64_t value) {
  const Setting& s = setting(id);
  if (value < s.lo || value > s.hi) {
    throw InputError(std::string(s.key) + ": must be in " + std::to_string(s.lo) + ".." + std::to_string(s.hi) +
                     " (got " + std::to_string(value) + ")");
  }
}

void check_real_setting(SettingId id, double value) {
  const Setting& s = setting(id);
  if (!(value > s.real_above && value <= s.real_most)) {
    char text[160];
    std::snprintf(text, sizeof text, "%s: must be above %g and at most %g (got %g)", s.key, s.real_above, s.real_most,
                  value);
    throw InputError(text);
  }
}

const std::vector<SettingId>& scene_settings() {
  static const std::vector<SettingId> ids = [] {
    std::vector<SettingId> v = render_settings();
    v.push_back(SettingId::MinSpp);
    v.push_back(SettingId::NoiseThreshold);
    return v;
  }();
  return ids;
}

namespace {

struct KernelInfo {
  Kernel kernel;
  const char* name;
  bool cuda_only;
};

// The one list of kernels: their names, in the order the docs and plots list them,
// and where they run. The constant-memory megakernel needs CUDA's __constant__ memory.
const std::vector<KernelInfo>& kernel_table() {
  static const std::vector<KernelInfo> table = {
      {Kernel::Megakernel, "megakernel", false},
      {Kernel::MegakernelConstant, "megakernel-constant", true},
      {Kernel::Wavefront, "wavefront", false},
      {Kernel::WavefrontSorted, "wavefront-sorted", false},
      {Kernel::WavefrontUnsorted, "wavefront-unsorted", false},
  };
  return table;
}

const KernelInfo& kernel_info(Kernel k) {
  for (const KernelInfo& info : kernel_table()) {
    if (info.kernel == k) return info;
  }
  throw std::logic_error("a kernel missing from the kernel table");
}

}  // namespace

const char* kernel_name(Kernel k) { return kernel_info(k).name; }

const std::vector<Kernel>& kernels() {
  static const std::vector<Kernel> all = [] {
    std::vector<Kernel> out;
    for (const KernelInfo& info : kernel_table()) out.push_back(info.kernel);
    return out;
  }();
  return all;
}

bool kernel_runs_on(Kernel kernel, Backend backend) {
  return backend == Backend::Cuda || !kernel_info(kernel).cuda_only;
}

std::vector<std::string> kernel_names() {
  std::vector<std::string> names;
  for (Kernel k : kernels()) names.push_back(kernel_name(k));
  return names;
}

std::vector<std::string> kernel_names(Backend backend) {
  std::vector<std::string> names;
  for (Kernel k : kernels()) {
    if (kernel_runs_on(k, backend)) names.push_back(kernel_name(k));
  }
  return names;
}

Kernel parse_kernel(const std::string& name) {
  for (Kernel k : kernels()) {
    if (name == kernel_name(k)) return k;
  }
  throw InputError("kernel: unknown kernel '" + name + "' (expected " + listed(kernel_names()) + ")");
}

const std::vector<std::string>& backend_choices() {
  static const std::vector<std::string> names = {"cuda", "cpu", "auto"};
  return names;
}

const std::vector<std::string>& encoding_choices() {
  static const std::vector<std::string> names = {"srgb", "gamma2"};
  return names;
}

const std::vector<std::string>& denoise_quality_choices() {
  static const std::vector<std::string> names = {"high", "balanced"};
  return names;
}

}  // namespace wt

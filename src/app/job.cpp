#include "app/job.hpp"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/progress.hpp"
#include "app/stats.hpp"
#include "cuda/device.hpp"

namespace wt::app {

Backend parse_backend(const std::string& name) {
  if (name == "cuda") return Backend::Cuda;
  if (name == "cpu") return Backend::Cpu;
  if (name == "auto") {
    if (cuda::device_count() > 0) return Backend::Cuda;
    std::fprintf(stderr, "wavetrace: no CUDA device found; rendering on the CPU backend\n");
    return Backend::Cpu;
  }
  throw SceneError("backend: unknown backend '" + name + "' (expected cuda, cpu or auto)");
}

Kernel parse_kernel(const std::string& name) {
  for (Kernel k : {Kernel::Megakernel, Kernel::MegakernelConstant, Kernel::Wavefront, Kernel::WavefrontUnsorted}) {
    if (name == kernel_name(k)) return k;
  }
  throw SceneError("kernel: unknown kernel '" + name +
                   "' (expected megakernel, megakernel-constant, wavefront or wavefront-unsorted)");
}

namespace {

RenderParams resolve_params(const Scene& scene, const Job& job) {
  RenderParams p = default_params(scene);
  if (job.width) p.width = *job.width;
  if (job.height) p.height = *job.height;
  if (job.spp) p.spp = *job.spp;
  if (job.depth) p.depth = *job.depth;
  if (job.roulette_depth) p.roulette_depth = *job.roulette_depth;
  if (job.seed) p.seed = *job.seed;
  try {
    validate_params(p);
  } catch (const SceneError& e) {
    throw SceneError(job.scene + ": settings: " + e.what());
  }
  return p;
}

void print_profile(const RenderResult& r) {
  double total = 0;
  for (const StageTime& s : r.stages) total += s.ms;
  std::fprintf(stderr, "%-10s %10s %7s\n", "stage", "ms", "share");
  for (const StageTime& s : r.stages) {
    std::fprintf(stderr, "%-10s %10.2f %6.1f%%\n", s.name.c_str(), s.ms, total > 0 ? 100.0 * s.ms / total : 0.0);
  }
  std::fprintf(stderr, "%-10s %10.2f  (render %.2f ms; the rest is launch gaps)\n", "sum", total, r.seconds * 1e3);
  std::fprintf(stderr, "bounces %zu, live paths per bounce:", r.live_per_bounce.size());
  for (size_t i = 0; i < r.live_per_bounce.size() && i < 40; ++i) {
    std::fprintf(stderr, " %llu", static_cast<unsigned long long>(r.live_per_bounce[i]));
  }
  std::fprintf(stderr, r.live_per_bounce.size() > 40 ? " ...\n" : "\n");
}

}  // namespace

JobOutcome run_job(const Job& job) {
  JobOutcome out;
  try {
    check_output_path(job.output);
    if (!job.stats.empty()) check_output_path_for_text(job.stats);
    Scene scene = load_scene(job.scene);
    RenderOptions options;
    options.params = resolve_params(scene, job);
    options.kernel = parse_kernel(job.kernel);
    options.backend = parse_backend(job.backend);
    options.warmup = job.warmup;
    options.wave_size = job.wave_size;
    options.threads = job.threads;
    out.params = options.params;
    out.backend = backend_name(options.backend);
    out.kernel = kernel_name(options.kernel);

    const uint64_t paths = static_cast<uint64_t>(options.params.width) * options.params.height * options.params.spp;
    {
      ProgressLine progress(paths);
      if (job.progress) options.progress = progress.callback();
      out.result = render(scene, options);
    }
    write_image(job.output, options.params.width, options.params.height, out.result.rgb, job.encoding);
    if (!job.stats.empty()) write_text_file(job.stats, stats_json(job, out).dump(2) + "\n");
    if (job.profile) print_profile(out.result);
  } catch (const SceneError& e) {
    out.exit_code = kExitBadInput;
    out.message = e.what();
  } catch (const OutputError& e) {
    out.exit_code = kExitBadInput;
    out.message = e.what();
  } catch (const cuda::CudaError& e) {
    out.exit_code = kExitFailure;
    out.message = std::string("CUDA error: ") + e.what();
  } catch (const DeviceError& e) {
    out.exit_code = kExitFailure;
    out.message = e.what();
  } catch (const std::exception& e) {
    out.exit_code = kExitFailure;
    out.message = e.what();
  }
  return out;
}

}  // namespace wt::app

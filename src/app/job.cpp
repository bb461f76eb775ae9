#include "app/job.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <thread>
#include <new>
#include <nlohmann/json.hpp>

#include "app/checkpoint.hpp"
#include "app/distributed.hpp"
#include "app/job_files.hpp"
#include "app/progress.hpp"
#include "app/signals.hpp"
#include "app/stats.hpp"
#include "cpu/parallel.hpp"
#include "device/device.hpp"
#include "errors/errors.hpp"
#include "image/denoise.hpp"
#include "scene/scene_file.hpp"
#include "render/adaptive.hpp"

namespace wt::app {

using nlohmann::json;

Backend parse_backend(const std::string& name) {
  if (name == "cuda") return Backend::Cuda;
  if (name == "cpu") return Backend::Cpu;
  if (name == "auto") {
    if (cuda::device_count() > 0) return Backend::Cuda;
    std::fprintf(stderr, "wavetrace: no CUDA device found; rendering on the CPU backend\n");
    return Backend::Cpu;
  }
  throw InputError("backend: unknown backend '" + name + "' (expected cuda, cpu or auto)");
}

std::vector<int> parse_devices(const std::string& text, Backend backend, int present) {
  if (text == "all" || text.empty()) {
    std::vector<int> all;
    if (backend == Backend::Cuda) {
      for (int d = 0; d < present; ++d) all.push_back(d);
    }
    return all;
  }
  std::vector<int> out;
  size_t at = 0;
  while (at <= text.size()) {
    const size_t comma = std::min(text.find(',', at), text.size());
    const std::string item = text.substr(at, comma - at);
    const bool digits = !item.empty() && item.size() <= 4 && item.find_first_not_of("0123456789") == std::string::npos;
    if (!digits) {
      throw InputError("devices: '" + text + "' is not 'all' or a list of device indices such as 0,1");
    }
    out.push_back(std::stoi(item));
    at = comma + 1;
  }
  if (backend == Backend::Cuda) cuda::require_cuda_devices(out, present);
  return out;
}

const std::string& checkpoint_of(const Job& job) { return job.checkpoint.empty() ? job.resume : job.checkpoint; }

void check_denoiser(const std::string& field) {
  std::string why;
  if (!oidn_available(why)) throw InputError(field + ": " + why);
}

uint64_t count_nonfinite_pixels(const std::vector<float>& rgb) {
  std::atomic<uint64_t> n{0};
  const float* v = rgb.data();
  cpu::parallel_for(static_cast<int64_t>(rgb.size() / 3), int64_t(1) << 16, cpu::thread_count(0),
                    [v, &n](int64_t begin, int64_t end, int) {
                      uint64_t here = 0;
                      for (int64_t p = 3 * begin; p < 3 * end; p += 3) {
                        here += !(std::isfinite(v[p]) && std::isfinite(v[p + 1]) && std::isfinite(v[p + 2]));
                      }
                      n += here;
                    });
  return n;
}

namespace {

RenderParams resolve_params(const Scene& scene, const Job& job) {
  RenderParams p = default_params(scene);
  for (SettingId id : render_settings()) {
    if (const std::optional<int64_t> v = given_setting(job, id)) set_param(p, id, *v);
  }
  try {
    validate_params(p);
  } catch (const InputError& e) {
    throw InputError(job.scene + ": settings: " + e.what());
  }
  return p;
}

void print_load_times(const LoadTimes& t, double upload_seconds) {
  std::fprintf(stderr,
               "load: parse %.3f s, validate %.3f s, texture load %.3f s, mesh load %.3f s, BVH build %.3f s, "
               "upload %.3f s\n",
               t.parse, t.validate, t.texture_load, t.mesh_load, t.bvh_build, upload_seconds);
}

void print_geometry(const Scene::Summary& g) {
  std::fprintf(stderr, "geometry: %zu spheres, %zu triangles stored, %zu placed, %zu instances, %zu BVH nodes\n",
               g.spheres, g.triangles, g.instanced_triangles, g.instances, g.bvh_nodes);
  if (g.dropped_degenerate || g.dropped_nan) {
    std::fprintf(stderr, "geometry: dropped %zu degenerate and %zu non-finite triangles\n", g.dropped_degenerate,
                 g.dropped_nan);
  }
  for (const auto& m : g.meshes) {
    std::fprintf(stderr, "mesh %s: %zu triangles, BVH %zu nodes, depth %d, SAH cost %.1f\n", m.name.c_str(),
                 size_t{m.triangle_count}, m.bvh.nodes, m.bvh.depth, m.bvh.sah_cost);
  }
}

void print_profile(const RenderResult& r) {
  double total = 0;
  for (const StageTime& s : r.stages) total += s.part ? 0.0 : s.ms;
  std::fprintf(stderr, "%-10s %10s %7s\n", "stage", "ms", "share");
  for (const StageTime& s : r.stages) {
    if (s.part && s.ms == 0.0) continue;
    std::fprintf(stderr, "%-10s %10.2f %6.1f%%%s\n", s.name.c_str(), s.ms, total > 0 ? 100.0 * s.ms / total : 0.0,
                 s.part ? " (of shade, in sorted bounces)" : "");
  }
  std::fprintf(stderr, "%-10s %10.2f  (render %.2f ms; the rest is launch gaps)\n", "sum", total, r.seconds * 1e3);
  std::fprintf(stderr, "bounces %zu, live paths per bounce:", r.live_per_bounce.size());
  for (size_t i = 0; i < r.live_per_bounce.size() && i < 40; ++i) {
    std::fprintf(stderr, " %llu", static_cast<unsigned long long>(r.live_per_bounce[i]));
  }
  std::fprintf(stderr, r.live_per_bounce.size() > 40 ? " ...\n" : "\n");
  std::fprintf(stderr, "bounces sorted: %llu of %llu\n", static_cast<unsigned long long>(r.bounces_sorted),
               static_cast<unsigned long long>(r.bounces_shaded));
}

// After a device failure: an error that left the context usable is cleared; a sticky
// one is said, since nothing more of CUDA can run in this process.
void recover_device(JobOutcome& out) {
  out.device_lost = cuda::recover_after_error() == cuda::Recovery::Lost;
  if (out.device_lost) out.message += "; " + std::string(cuda::kContextLost);
}

// Runs one phase of a job: its errors become the outcome's exit code and message.
template <class F>
void guarded(JobOutcome& out, F&& phase) {
  try {
    phase();
  } catch (const InputError& e) {
    out.exit_code = kExitBadInput;
    out.message = e.what();
  } catch (const OutputWriteError& e) {
    out.exit_code = kExitFailure;  // the path was fine; the disk was not
    out.message = e.what();
  } catch (const OutputError& e) {
    out.exit_code = kExitBadInput;
    out.message = e.what();
  } catch (const DeviceError& e) {
    out.exit_code = kExitFailure;
    out.message = (dynamic_cast<const cuda::CudaError*>(&e) ? "CUDA error: " : "") + std::string(e.what());
    recover_device(out);
  } catch (const std::bad_alloc&) {
    out.exit_code = kExitFailure;
    out.message = "out of host memory (std::bad_alloc)";
  } catch (const std::exception& e) {
    out.exit_code = kExitFailure;
    out.message = e.what();
  } catch (...) {
    out.exit_code = kExitFailure;
    out.message = "failed with an unknown error";
  }
}

// What every rank of an MPI render must share: the settings, kernel and scene's size.
std::string render_signature(const JobOutcome& o) {
  const RenderParams& p = o.params;
  return std::to_string(p.width) + "x" + std::to_string(p.height) + ", " + std::to_string(p.spp) + " spp, depth " +
         std::to_string(p.depth) + ", roulette depth " + std::to_string(p.roulette_depth) + ", seed " +
         std::to_string(p.seed) + ", light sampling " + std::to_string(p.nee) +
         (o.noise_threshold != 0 ? ", noise threshold " + json(o.noise_threshold).dump() + " min spp " +
                                       std::to_string(o.min_spp)
                                 : std::string()) +
         ", " + o.backend + "/" + o.kernel +
         ", " + std::to_string(o.geometry.spheres) + " spheres and " + std::to_string(o.geometry.instanced_triangles) +
         " triangles";
}

}  // namespace

JobOutcome run_job(const Job& job) { return run_job(job, Cluster()); }

namespace {

// The CUDA context starts while the scene loads: that of the first device the job
// renders on (a batch lane's job starts none on another lane's device). A bad device
// list is left for the render's own parse to report.
class ContextStart {
 public:
  explicit ContextStart(const Job& job) {
    if (job.backend == "cpu") return;
    thread_ = std::thread([devices = job.devices] {
      int first = 0;
      try {
        const std::vector<int> list = parse_devices(devices, Backend::Cuda, cuda::device_count());
        if (!list.empty()) first = list[0];
      } catch (const InputError&) {
      }
      cuda::start_context(first);
    });
  }
  ~ContextStart() {
    if (thread_.joinable()) thread_.join();
  }
  ContextStart(const ContextStart&) = delete;
  ContextStart& operator=(const ContextStart&) = delete;

 private:
  std::thread thread_;
};

// Every file the job writes, checked before the scene loads: a bad path costs
// nothing, and no output may overwrite another. Of an MPI run, rank 0 alone writes
// (and keeps no checkpoint).
void check_outputs(const Job& job, bool distributed) {
  if (job.noise_threshold) {
    const Setting& t = setting(SettingId::NoiseThreshold);
    try {
      check_real_setting(t.id, *job.noise_threshold);
    } catch (const InputError& e) {
      throw InputError(std::string(t.flag) + std::string(e.what()).substr(std::strlen(t.key)));
    }
  }
  if (job.keep_noisy && !job.denoise) throw InputError("--keep-noisy: keeps the render beside a denoised image: give --denoise too");
  if (job.denoise) check_denoiser("--denoise");
  const std::string noisy = noisy_output(job);
  const std::vector<JobFile> aovs = aov_outputs(job);  // the --aov list checked
  check_output_path(job.output);
  if (!noisy.empty()) check_output_path(noisy);
  for (const JobFile& f : aovs) check_output_path(f.path);
  if (!job.stats.empty()) check_output_path_for_text(job.stats);
  check_distinct_files(job);
  check_creatable(job.output, "image");
  if (!noisy.empty()) check_creatable(noisy, "noisy image");
  for (const JobFile& f : aovs) check_creatable(f.path, f.field);
  if (!job.stats.empty()) check_creatable(job.stats, "stats file");
  if (!distributed && !checkpoint_of(job).empty()) {
    check_output_folder(checkpoint_of(job));
    check_creatable(checkpoint_of(job), job.checkpoint.empty() ? "resume file (written back to)" : "checkpoint");
  }
}

// The render's options from the job and its scene.
}  // namespace

RenderOptions resolve_options(const Job& job, const Scene& scene) {
  RenderOptions options;
  options.params = resolve_params(scene, job);
  options.kernel = parse_kernel(job.kernel);
  options.backend = parse_backend(job.backend);
  options.warmup = static_cast<int>(job.warmup);
  options.shade_by_kind = job.profile;
  options.wave_size = job.wave_size;
  options.megakernel_batch = static_cast<int32_t>(job.megakernel_batch);
  // Adaptive sampling: the job's, else the scene's `render` section's.
  options.noise_threshold = job.noise_threshold.value_or(scene.render.noise_threshold);
  options.min_spp = static_cast<int32_t>(job.min_spp > 0 ? job.min_spp : scene.render.min_spp);
  if (options.min_spp > 0 && options.noise_threshold == 0) {
    throw InputError(job.min_spp > 0 ? "--min-spp: the samples every pixel takes before adaptive sampling stops any; "
                                       "give --noise-threshold too"
                                     : job.scene + ": /render/min_spp: the samples every pixel takes before adaptive "
                                                   "sampling stops any; give noise_threshold too");
  }
  // The variance AOV is the adaptive rounds' estimate: without a threshold, the same
  // rounds with no pixel stopping.
  if (options.noise_threshold == 0 && job_asks_for(job, AovKind::Variance)) options.noise_threshold = -1;
  options.threads = static_cast<int>(job.threads);
  options.devices = parse_devices(job.devices, options.backend, cuda::device_count());
  return options;
}

namespace {

// Of an MPI run: this rank's share of its host's devices or cores (and no checkpoint).
void take_rank_share(const Job& job, const Cluster& cluster, RenderOptions& options) {
  if (!job.checkpoint.empty() || !job.resume.empty()) {
    throw InputError(std::string(job.checkpoint.empty() ? "resume" : "checkpoint") +
                     ": checkpoints are kept by one process; a render over " + std::to_string(cluster.ranks()) +
                     " MPI ranks has none (render its parts as jobs of a batch instead)");
  }
  if (options.backend == Backend::Cuda) {
    // The ranks of one host share its GPUs out (parse_devices lists them all for "all").
    options.devices = local_share(options.devices, cluster.local_rank(), cluster.local_ranks());
  } else if (options.threads == 0) {
    // The ranks of one host share its cores out.
    options.threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / cluster.local_ranks());
  }
}

// The first phase: the outputs checked, the scene loaded, the options resolved.
void load_job(const Job& job, const Cluster& cluster, JobOutcome& out, std::optional<Scene>& scene,
              RenderOptions& options) {
  if (cluster.root()) check_outputs(job, cluster.distributed());
  scene.emplace(load_scene(job.scene, job.defines));
  out.load_times = scene->load_times;
  out.geometry = scene->summary();
  // What a mesh file holds that is not rendered, once (by the root rank), and in the
  // stats file.
  out.scene_warnings = scene->warnings;
  if (cluster.root()) {
    for (const std::string& w : out.scene_warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    for (const auto& m : out.geometry.meshes) {
      for (const std::string& w : m.warnings) std::fprintf(stderr, "warning: %s: %s\n", m.file.c_str(), w.c_str());
    }
  }
  options = resolve_options(job, *scene);
  out.params = options.params;
  if (options.noise_threshold != 0) {
    out.noise_threshold = options.noise_threshold;
    out.min_spp = resolved_min_spp(options.min_spp, options.params.spp);
  }
  out.backend = backend_name(options.backend);
  out.kernel = kernel_name(options.kernel);
  if (cluster.distributed()) take_rank_share(job, cluster, options);
}

// What a render with a checkpoint keeps while it runs.
struct CheckpointState {
  Checkpoint resumed;
  std::optional<SignalCatcher> signals;
  // Once a pass says stop, the render ends as it is: its progress line stays where it was.
  std::atomic<bool> stopping{false};
  // An adaptive render's: where it resumes from, and what it does after each step.
  AdaptiveHooks adaptive;
};

// Whether a checkpoint is due: on a signal (and the render stops), or every
// checkpoint_every seconds until the last pass or step.
class CheckpointClock {
 public:
  CheckpointClock(CheckpointState& state, int64_t every_seconds) : state_(state), every_(every_seconds) {}
  // Returns {write now, go on}.
  std::pair<bool, bool> due(bool last) {
    const bool stop = state_.signals->caught() != 0;
    if (stop) state_.stopping = true;
    const auto now = std::chrono::steady_clock::now();
    const bool write = stop || (!last && now - last_write_ >= std::chrono::seconds(every_));
    if (write) last_write_ = now;
    return {write, !stop};
  }

 private:
  CheckpointState& state_;
  int64_t every_;
  std::chrono::steady_clock::time_point last_write_ = std::chrono::steady_clock::now();
};

// Locks the job's checkpoint (held until the image is written), resumes from the one
// there is, and has the render write it every checkpoint_every seconds and when a
// signal stops it: a uniform render in passes short enough that a signal is answered
// within about 1/256 of the render, an adaptive one after each of its steps.
void watch_checkpoint(const Job& job, const JobOutcome& out, RenderOptions& options, CheckpointState& state,
                      CheckpointLock& lock) {
  const RenderParams& rp = options.params;
  const std::string& path = checkpoint_of(job);
  lock = CheckpointLock(path);
  CheckpointIdentity identity = checkpoint_identity(job.scene, job.defines, rp, out.kernel, out.backend);
  identity.noise_threshold = out.noise_threshold;
  identity.min_spp = out.min_spp;
  const std::string from =
      !job.resume.empty() ? job.resume : (std::filesystem::exists(job.checkpoint) ? job.checkpoint : "");
  const bool adaptive = options.noise_threshold != 0;
  if (!from.empty()) {
    state.resumed = read_checkpoint(from);
    require_same_render(from, state.resumed.identity, identity);
    if (adaptive) {
      state.adaptive.resume = &*state.resumed.adaptive;
      state.resumed.samples = state.resumed.adaptive->samples;
    } else {
      options.first_sample = state.resumed.samples;
      options.initial_film = &state.resumed.film;
    }
  }
  state.signals.emplace();
  if (adaptive) {
    state.adaptive.after_step = [&path, identity, clock = CheckpointClock(state, job.checkpoint_every)](
                                    const AdaptiveState& now, bool last) mutable {
      const auto [write, go_on] = clock.due(last);
      if (write) {
        Checkpoint c{identity, now.samples, {}, now};
        write_checkpoint(path, c);
      }
      return go_on;
    };
    return;
  }
  options.samples_per_pass = std::max(1, rp.spp / 256);
  options.after_pass = [&path, spp = rp.spp, identity, clock = CheckpointClock(state, job.checkpoint_every)](
                           int32_t samples, const FilmReader& film) mutable {
    const auto [write, go_on] = clock.due(samples >= spp);
    if (write) write_checkpoint(path, Checkpoint{identity, samples, film(), std::nullopt});
    return go_on;
  };
}

// The second phase, in one process: the render, from and into its checkpoint where
// the job has one.
void render_alone(const Job& job, const Scene& scene, RenderOptions& options, JobOutcome& out, CheckpointLock& lock) {
  const RenderParams& rp = options.params;
  // Checkpoints go to job.checkpoint, or back into the file resumed from.
  const std::string& checkpoint_path = checkpoint_of(job);
  CheckpointState state;
  if (!checkpoint_path.empty()) {
    watch_checkpoint(job, out, options, state, lock);
    out.resumed_from_sample = state.resumed.samples;
  }
  if (state.resumed.samples >= rp.spp && !state.resumed.film.empty()) {
    // Every sample was done before: the image is the checkpoint's film.
    out.result.rgb = state.resumed.film;
    out.result.samples = rp.spp;
    take_mean(out.result);
  } else {
    const uint64_t pixels = static_cast<uint64_t>(rp.width) * rp.height;
    ProgressLine progress(pixels * (rp.spp - options.first_sample));
    if (job.progress) {
      options.progress = [&state, draw = progress.callback()](double done, uint64_t rays, double seconds) {
        if (!state.stopping) draw(done, rays, seconds);
      };
      if (options.noise_threshold > 0) {
        state.adaptive.converged = progress.converged_callback(pixels);
      }
    }
    out.result = render(scene, options, state.adaptive);
  }
  if (out.result.interrupted) {
    const int sig = state.signals->caught();
    out.exit_code = 128 + sig;
    out.message = "interrupted by " + signal_name(sig) + " at sample " + std::to_string(out.result.samples) + " of " +
                  std::to_string(rp.spp) + "; checkpoint written to " + checkpoint_path + " (resume with --resume " +
                  checkpoint_path + ")";
  }
  // The image is about to be written: the checkpoint has served its purpose once it is.
  out.checkpoint = checkpoint_path;
}

// The second phase as a rank of an MPI run: this rank's samples' sums (rank 0 adds
// the others' to its own); of an adaptive render, this rank's part of each round
// (render_adaptive_ranks), rank 0's result the whole image.
void render_rank(const Job& job, const Scene& scene, RenderOptions& options, const Cluster& cluster,
                 const std::vector<double>& weights, JobOutcome& out) {
  const RenderParams& rp = options.params;
  if (options.noise_threshold != 0) {
    const uint64_t pixels = static_cast<uint64_t>(rp.width) * rp.height;
    ProgressLine progress(pixels * rp.spp);
    AdaptiveHooks hooks;
    if (job.progress && cluster.root()) {
      options.progress = progress.callback();
      if (options.noise_threshold > 0) {
        hooks.converged = progress.converged_callback(pixels);
      }
    }
    out.result = render_adaptive_ranks(cluster, adaptive_rounds(scene, options), options, weights, hooks);
    return;
  }
  if (options.sample_count == 0) {
    out.result.rgb.assign(static_cast<size_t>(rp.width) * rp.height * 3, 0.0f);
    out.result.device = "no samples";
    return;
  }
  ProgressLine progress(static_cast<uint64_t>(rp.width) * rp.height * options.sample_count);
  if (job.progress && cluster.root()) options.progress = progress.callback();  // rank 0's part
  out.result = render_sums(scene, options);
}

}  // namespace

void render_first_surface(const Job& job, const Scene& scene, const RenderOptions& options, JobOutcome& out) {
  bool first_surface = job.denoise;
  for (AovKind k : job_aovs(job)) first_surface = first_surface || from_first_surface(k);
  // An adaptive render's pass takes each pixel's own samples.
  if (first_surface) {
    out.aovs = render_aovs(scene, options, out.result.pixel_samples.empty() ? nullptr : &out.result.pixel_samples);
  }
}

std::vector<float> denoise_outcome(const Job& job, const RenderOptions& options, JobOutcome& out) {
  const int w = options.params.width, h = options.params.height;
  std::vector<float> denoised;
  // Guided by the albedo and the normal of the first-surface pass.
  const std::vector<float> albedo = denoise_albedo(out.aovs);
  const std::vector<float> normal = denoise_normal(out.aovs);
  const auto start = std::chrono::steady_clock::now();
  DenoiseDevice device = options.backend == Backend::Cuda ? DenoiseDevice::Cuda : DenoiseDevice::Cpu;
  const DenoiseQuality quality = job.denoise_quality == "balanced" ? DenoiseQuality::Balanced : DenoiseQuality::High;
  try {
    denoised = denoise({w, h, out.result.rgb.data(), albedo.data(), normal.data()}, quality, device);
  } catch (const DeviceError& e) {
    if (device == DenoiseDevice::Cpu) throw;
    // OIDN without its CUDA device here (a driver it does not take, a module not
    // installed): the CPU's, said on stderr.
    std::fprintf(stderr, "wavetrace: %s; denoising on the CPU\n", e.what());
    device = DenoiseDevice::Cpu;
    denoised = denoise({w, h, out.result.rgb.data(), albedo.data(), normal.data()}, quality, device);
  }
  out.denoise_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.denoise_device = device == DenoiseDevice::Cuda ? "cuda" : "cpu";
  return denoised;
}

std::vector<AovImage> job_aov_images(const Job& job, const JobOutcome& out) {
  std::vector<AovImage> aovs;
  for (AovKind k : job_aovs(job)) {
    aovs.push_back(from_first_surface(k) ? aov_image(k, out.aovs) : result_aov_image(k, out.result));
  }
  return aovs;
}

namespace {

// Says so where pixels are not finite (the stats count them too).
void warn_nonfinite(const Job& job, JobOutcome& out) {
  out.nonfinite_pixels = count_nonfinite_pixels(out.result.rgb);
  if (out.nonfinite_pixels == 0) return;
  std::fprintf(stderr, "wavetrace: %s: warning: %llu pixels are not finite (NaN or an infinity); %s\n",
               job.output.c_str(), static_cast<unsigned long long>(out.nonfinite_pixels),
               nonfinite_pixels_written(job.output));
}

// The last phase: the image and the stats written, the checkpoint removed.
void write_job(const Job& job, const RenderOptions& options, JobOutcome& out,
               std::chrono::steady_clock::time_point job_start) {
  warn_nonfinite(job, out);
  // Both files are written in full before either takes its name: a disk that fills
  // up during the second leaves neither.
  const int w = options.params.width, h = options.params.height;
  const ExrPixels exr = job.exr_float ? ExrPixels::Float : ExrPixels::Half;
  // A denoised job's output is the denoiser's image, the render itself its noisy
  // image where kept.
  const std::vector<float> denoised = job.denoise ? denoise_outcome(job, options, out) : std::vector<float>{};
  const auto write_start = std::chrono::steady_clock::now();
  // The AOVs: layers of an OpenEXR output, else files of their own beside it.
  const std::vector<AovImage> aovs = job_aov_images(job, out);
  const std::vector<JobFile> aov_files = aov_outputs(job);
  std::vector<ImageLayer> layers;
  if (aov_files.empty()) {
    for (const AovImage& a : aovs) layers.push_back({a.name, a.channels, &a.values});
  }
  StagedFile image =
      stage_image(job.output, w, h, job.denoise ? denoised : out.result.rgb, job.encoding, exr, layers);
  std::vector<StagedFile> aov_staged;
  for (size_t i = 0; i < aov_files.size(); ++i) {
    aov_staged.push_back(stage_pfm_image(aov_files[i].path, w, h, aovs[i].values,
                                         static_cast<int>(aovs[i].channels.size())));
  }
  const std::string noisy_path = noisy_output(job);
  StagedFile noisy =
      noisy_path.empty() ? StagedFile() : stage_image(noisy_path, w, h, out.result.rgb, job.encoding, exr);
  const auto written = std::chrono::steady_clock::now();
  out.write_seconds = std::chrono::duration<double>(written - write_start).count();
  out.job_seconds = std::chrono::duration<double>(written - job_start).count();
  StagedFile stats = job.stats.empty() ? StagedFile() : stage_file(job.stats, stats_json(job, out).dump(2) + "\n");
  image.commit();
  noisy.commit();
  for (StagedFile& f : aov_staged) f.commit();
  stats.commit();
  // The image is written: the checkpoint has served its purpose.
  if (!out.checkpoint.empty()) std::filesystem::remove(out.checkpoint);
  if (job.profile) {
    print_load_times(out.load_times, out.result.upload_seconds);
    print_geometry(out.geometry);
    print_profile(out.result);
  }
}

}  // namespace

JobOutcome run_job(const Job& job, const Cluster& cluster) {
  const auto job_start = std::chrono::steady_clock::now();
  JobOutcome out;
  const bool distributed = cluster.distributed();
  const ContextStart context(job);
  std::optional<Scene> scene;
  RenderOptions options;
  std::vector<double> rank_weights;  // of an MPI run: each rank's share
  // Held from before the checkpoint is read until the image is written.
  CheckpointLock checkpoint_lock;
  // Each phase guarded, so that every rank of an MPI run reaches every exchange.
  guarded(out, [&] { load_job(job, cluster, out, scene, options); });
  if (distributed) {
    const double weight = options.backend == Backend::Cuda ? std::max<size_t>(1, options.devices.size())
                                                           : std::max(1, options.threads);
    if (!agree_on_samples(cluster, out, options, render_signature(out), weight, &rank_weights)) return out;
    out.ranks = cluster.ranks();
  }
  const auto started = std::chrono::steady_clock::now();
  if (out.exit_code != 0) return out;
  guarded(out, [&] {
    if (distributed) {
      render_rank(job, *scene, options, cluster, rank_weights, out);
    } else {
      render_alone(job, *scene, options, out, checkpoint_lock);
    }
  });
  if (distributed) {
    combine_results(cluster, out, options.noise_threshold != 0);
    out.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  }
  if (out.exit_code != 0 || !cluster.root()) return out;
  guarded(out, [&] {
    if (distributed && out.result.radiance == Radiance::SumOfSamples) take_mean(out.result);
    render_first_surface(job, *scene, options, out);
    write_job(job, options, out, job_start);
  });
  return out;
}

void print_outcome(const Job& job, const JobOutcome& o) {
  const RenderResult& r = o.result;
  if (o.resumed_from_sample > 0 && o.resumed_from_sample >= o.params.spp) {
    std::fprintf(stderr, "%s: every one of its %d samples was in the checkpoint %s; nothing was left to render\n",
                 job.output.c_str(), o.params.spp, checkpoint_of(job).c_str());
    return;
  }
  std::fprintf(stderr, "%s: %s/%s on %s: %.3f s, %llu rays, %.1f M rays/s, %.1f M paths/s\n", job.output.c_str(),
               o.backend.c_str(), o.kernel.c_str(), r.device.c_str(), r.seconds,
               static_cast<unsigned long long>(r.rays), r.rays / r.seconds / 1e6, r.paths / r.seconds / 1e6);
  if (o.ranks > 1) {
    std::fprintf(stderr, "  %d ranks: %.3f s wall clock from every rank's start to the summed film\n", o.ranks,
                 o.wall_seconds);
  }
  const double pixels = static_cast<double>(o.params.width) * o.params.height;
  if (o.noise_threshold > 0 && pixels > 0) {
    std::fprintf(stderr, "  adaptive: %llu of %.0f pixels converged under %g; %.1f spp on average, %d at most\n",
                 static_cast<unsigned long long>(r.converged), pixels, o.noise_threshold, mean_spp(r),
                 r.samples);
  }
  for (const DeviceShare& s : r.shares) {
    // Chunks of samples, or (a wavefront's devices sharing the paths) blocks of paths,
    // or an adaptive render's rounds (a run of their pixels each).
    std::fprintf(stderr, "  %s (%s): %.1f spp in %d %s, %.3f s, %.1f M rays/s\n", s.device.c_str(), s.name.c_str(),
                 pixels > 0 ? s.paths / pixels : 0.0, s.chunks,
                 o.noise_threshold != 0 ? "rounds" : s.samples > 0 ? "chunks" : "blocks of paths",
                 s.seconds, s.seconds > 0 ? s.rays / s.seconds / 1e6 : 0.0);
  }
}

}  // namespace wt::app

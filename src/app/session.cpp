#include "app/session.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

#include "app/stats.hpp"
#include "app/job_files.hpp"
#include "device/device.hpp"
#include "dispatch/renderer.hpp"

namespace wt::app {

Session::Session(std::shared_ptr<const Scene> scene, std::string source)
    : scene_(std::move(scene)), source_(std::move(source)) {}

SessionRender Session::render(const Job& given, const std::function<void(double)>& progress,
                              const std::function<bool()>& stop, const cuda::ImageMemory& image_memory) const {
  const auto start = std::chrono::steady_clock::now();
  Job job = given;
  job.scene = source_;
  SessionRender done;
  JobOutcome& out = done.outcome;
  RenderOptions options = resolve_options(job, *scene_);
  const bool with_aovs = !job_aovs(job).empty();  // the list checked before the render
  if (job.denoise) check_denoiser("denoise");
  if (options.backend == Backend::Cuda) {
    std::lock_guard<std::mutex> lock(resident_mutex_);
    if (!resident_) resident_ = keep_scene(*scene_, options.backend);
    options.resident = resident_;
    done.cuda_device = options.devices.empty() ? 0 : options.devices.front();
  }
  out.params = options.params;
  out.noise_threshold = options.noise_threshold > 0 ? options.noise_threshold : 0;
  out.min_spp = options.min_spp;
  out.backend = backend_name(options.backend);
  out.kernel = kernel_name(options.kernel);
  out.load_times = scene_->load_times;
  out.geometry = scene_->summary();
  out.scene_warnings = scene_->warnings;
  // A stop is asked wherever the render tells its progress (each bounce of a
  // wavefront, each row chunk of the CPU megakernel, each pass of the CUDA
  // megakernel, each step of an adaptive render), so that the render keeps its own
  // passes and speed; a stop unwinds it from there. Both are asked at most every
  // kAskEvery: a wavefront's bounce can take a tenth of a millisecond, and the Python
  // module takes the interpreter's lock for each ask. The render's own 1 (a wavefront
  // tells it once its last path starts, and again at its end) is not passed on: the
  // session tells 1 once the render has returned.
  struct Stopped {};
  if (progress || stop) {
    static constexpr std::chrono::milliseconds kAskEvery{10};
    options.progress = [&progress, &stop, asked = std::chrono::steady_clock::time_point{}](
                           double done, uint64_t, double) mutable {
      const auto now = std::chrono::steady_clock::now();
      if (now - asked < kAskEvery) return;
      asked = now;
      if (progress && done < 1.0) progress(done);
      if (stop && stop()) throw Stopped{};
    };
  }
  AdaptiveHooks hooks;
  if (stop && options.noise_threshold != 0) {
    hooks.after_step = [&stop](const AdaptiveState&, bool) { return !stop(); };
  }
  // A render that needs no image on the host for its AOVs or its denoiser keeps its
  // image on the device it ran on, for the caller to take from there or bring back.
  const bool on_device = renders_to_device(options) && !job.denoise && !with_aovs;
  try {
    out.result = on_device ? render_to_device(*scene_, options, done.image, image_memory)
                           : wt::render(*scene_, options, hooks);
  } catch (const Stopped&) {
    out.result = RenderResult{};
    out.result.interrupted = true;
    done.image = cuda::DeviceImage{};
  } catch (const DeviceError&) {
    // As run_job does: an error that left the context usable is cleared, so that the
    // next render (and the kept copies, still valid) can run.
    cuda::recover_after_error();
    throw;
  }
  if (progress && !out.result.interrupted) progress(1.0);
  out.nonfinite_pixels = done.image.rgba ? done.image.nonfinite_pixels : count_nonfinite_pixels(out.result.rgb);
  if (!out.result.interrupted) {
    options.progress = nullptr;
    render_first_surface(job, *scene_, options, out);
    if (job.denoise) done.denoised = denoise_outcome(job, options, out);
    done.aovs = job_aov_images(job, out);
  }
  out.job_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return done;
}

int64_t Session::uploads() const {
  std::lock_guard<std::mutex> lock(resident_mutex_);
  return released_uploads_ + scene_uploads(resident_.get());
}

void Session::release_devices() {
  std::lock_guard<std::mutex> lock(resident_mutex_);
  released_uploads_ += scene_uploads(resident_.get());
  resident_.reset();
}

nlohmann::json Session::stats(const Job& given, const JobOutcome& outcome) const {
  Job job = given;
  job.scene = source_;
  job.output.clear();
  return stats_json(job, outcome);
}

}  // namespace wt::app

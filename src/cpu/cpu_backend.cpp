// The CPU backend: the same per-path code as the GPU, on every core.
#include "cpu/cpu_backend.hpp"

#include <atomic>
#include <chrono>
#include <thread>

#include "cpu/cpu_wavefront.hpp"
#include "cpu/parallel.hpp"
#include "render/settings.hpp"
#include "wavetrace/path.hpp"

namespace wt::cpu {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

RenderResult render_megakernel(const SceneView& view, const RenderParams& rp, const RenderOptions& options) {
  RenderResult out;
  const int64_t pixels = static_cast<int64_t>(rp.width) * rp.height;
  out.rgb.assign(pixels * 3, 0.0f);
  std::atomic<uint64_t> rays{0};
  std::atomic<int64_t> pixels_done{0};
  const int threads = thread_count(options.threads);
  auto t0 = Clock::now();
  auto last_report = t0;
  // One row per chunk: whole rows keep the progress steady and the cache warm.
  parallel_for(pixels, rp.width, threads, [&](int64_t begin, int64_t end, int tid) {
    uint32_t local_rays = 0;
    for (int64_t p = begin; p < end; ++p) {
      vec3 sum(0.0f);
      for (int s = 0; s < rp.spp; ++s) {
        sum += trace_path(view, rp, static_cast<uint32_t>(p), static_cast<uint32_t>(s), local_rays);
      }
      out.rgb[3 * p + 0] = sum.x;
      out.rgb[3 * p + 1] = sum.y;
      out.rgb[3 * p + 2] = sum.z;
    }
    uint64_t total = rays.fetch_add(local_rays) + local_rays;
    int64_t done = pixels_done.fetch_add(end - begin) + (end - begin);
    if (options.progress && tid == 0) {  // only this thread touches last_report
      auto now = Clock::now();
      if (now - last_report > std::chrono::milliseconds(250)) {
        last_report = now;
        options.progress(static_cast<double>(done) / pixels, total, seconds_since(t0));
      }
    }
  });
  out.seconds = seconds_since(t0);
  out.rays = rays.load();
  out.radiance = Radiance::SumOfSamples;
  return out;
}

}  // namespace

RenderResult render(const Scene& scene, const RenderOptions& options) {
  const RenderParams& rp = options.params;
  if (!kernel_runs_on(options.kernel, Backend::Cpu)) {
    throw SceneError(std::string("kernel: ") + kernel_name(options.kernel) +
                     " needs the cuda backend (constant memory is a GPU memory)");
  }
  std::vector<ImageView> images;
  const SceneView view = host_view(scene, rp.width, rp.height, images);

  RenderResult out;
  if (options.kernel == Kernel::Megakernel) {
    // Warm-up renders, as on the GPU, so that timings compare like with like.
    RenderOptions silent = options;
    silent.progress = nullptr;
    for (int i = 0; i < options.warmup; ++i) render_megakernel(view, rp, silent);
    out = render_megakernel(view, rp, options);
  } else {
    out = render_wavefront(view, scene.sort_key_bits(), options, choose_wave_size(options.wave_size, rp));
  }
  out.paths = static_cast<uint64_t>(rp.width) * rp.height * rp.spp;
  out.device = "CPU (" + std::to_string(thread_count(options.threads)) + " threads)";
  if (options.progress) options.progress(1.0, out.rays, out.seconds);
  return out;
}

}  // namespace wt::cpu

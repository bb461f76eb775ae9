// The CPU backend: the same per-path code as the GPU, on every core.
#include "cpu/cpu_backend.hpp"

#include <atomic>
#include <chrono>
#include <thread>

#include "cpu/cpu_wavefront.hpp"
#include "cpu/parallel.hpp"
#include "errors/errors.hpp"
#include "render/passes.hpp"
#include "render/settings.hpp"
#include "wavetrace/aov.hpp"
#include "wavetrace/path.hpp"

namespace wt::cpu {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Pass after pass of samples, each over rows of pixels on every core.
RenderResult render_megakernel(const SceneView& view, const RenderParams& rp, const RenderOptions& options,
                               bool last) {
  RenderResult out;
  const int64_t pixels = static_cast<int64_t>(rp.width) * rp.height;
  if (options.initial_film) {
    out.rgb = *options.initial_film;
  } else {
    out.rgb.assign(pixels * 3, 0.0f);
  }
  out.samples = options.first_sample;
  const std::vector<SamplePass> passes = plan_passes(options, 1);
  std::atomic<uint64_t> rays{0}, shadow_rays{0};
  std::atomic<int64_t> pixels_done{0};
  const int threads = thread_count(options.threads);
  auto t0 = Clock::now();
  auto last_report = t0;
  // The pixels a sample visits: those listed, or every one.
  const std::vector<uint32_t>* active = options.active_pixels;
  const int64_t rendered = static_cast<int64_t>(rendered_pixels(options));
  const int64_t all_pixels = rendered * static_cast<int64_t>(passes.size());
  for (size_t p = 0; p < passes.size(); ++p) {
    const SamplePass& pass = passes[p];
    // One row per chunk: whole rows keep the progress steady and the cache warm.
    parallel_for(rendered, rp.width, threads, [&](int64_t begin, int64_t end, int tid) {
      uint32_t path_rays = 0, path_shadow_rays = 0;
      uint64_t local_rays = 0, local_shadow_rays = 0;
      for (int64_t i = begin; i < end; ++i) {
        const int64_t px = active ? (*active)[i] : i;
        vec3 sum(0.0f);
        for (int32_t s = pass.first; s < pass.first + pass.count; ++s) {
          path_rays = 0;
          path_shadow_rays = 0;
          sum += trace_path(view, rp, static_cast<uint32_t>(px), static_cast<uint32_t>(s), path_rays, path_shadow_rays);
          local_rays += path_rays;
          local_shadow_rays += path_shadow_rays;
        }
        out.rgb[3 * px + 0] += sum.x;
        out.rgb[3 * px + 1] += sum.y;
        out.rgb[3 * px + 2] += sum.z;
      }
      const uint64_t total = rays.fetch_add(local_rays) + local_rays;
      shadow_rays.fetch_add(local_shadow_rays);
      const int64_t done = pixels_done.fetch_add(end - begin) + (end - begin);
      if (last && options.progress && tid == 0) {  // only this thread touches last_report
        auto now = Clock::now();
        if (now - last_report > std::chrono::milliseconds(250)) {
          last_report = now;
          options.progress(static_cast<double>(done) / all_pixels, total, seconds_since(t0));
        }
      }
    });
    out.samples = pass.first + pass.count;
    out.paths += static_cast<uint64_t>(rendered) * pass.count;
    if (last && options.after_pass && !options.after_pass(out.samples, [&] { return out.rgb; })) {
      out.interrupted = p + 1 < passes.size();
      break;
    }
  }
  out.seconds = seconds_since(t0);
  out.rays = rays.load();
  out.shadow_rays = shadow_rays.load();
  out.radiance = Radiance::SumOfSamples;
  return out;
}

}  // namespace

DeviceRenderer device_renderer(const Scene& scene, const RenderOptions& options, size_t) {
  const int each = std::max(1, thread_count(options.threads) / static_cast<int>(options.devices.size()));
  return {[&scene, each](const RenderOptions& chunk) {
            RenderOptions one = chunk;
            one.devices.clear();
            one.threads = each;
            return render(scene, one);
          },
          {}, {}};
}

RenderResult render(const Scene& scene, const RenderOptions& options) {
  const RenderParams& rp = options.params;
  std::vector<ImageView> images;
  const SceneView view = host_view(scene, rp.width, rp.height, images);

  RenderResult out;
  if (options.kernel == Kernel::Megakernel) {
    // Warm-up renders, as on the GPU, so that timings compare like with like.
    for (int i = 0; i < options.warmup; ++i) render_megakernel(view, rp, options, false);
    out = render_megakernel(view, rp, options, true);
  } else {
    out = render_wavefront(view, scene.sort_key_bits(), options, choose_wave_size(options.wave_size, rp));
  }
  out.device = "CPU (" + std::to_string(thread_count(options.threads)) + " threads)";
  if (options.progress) options.progress(1.0, out.rays, out.seconds);
  return out;
}

AovSums render_aov_sums(const Scene& scene, const RenderOptions& options,
                        const std::vector<int32_t>* pixel_samples) {
  const RenderParams& rp = options.params;
  std::vector<ImageView> images;
  const SceneView view = host_view(scene, rp.width, rp.height, images);
  const int64_t pixels = static_cast<int64_t>(rp.width) * rp.height;
  AovSums out;
  out.samples = rp.spp;
  out.sums.assign(static_cast<size_t>(pixels) * kAovFloats, 0.0f);
  const auto t0 = Clock::now();
  parallel_for(pixels, rp.width, thread_count(options.threads), [&](int64_t begin, int64_t end, int) {
    for (int64_t px = begin; px < end; ++px) {
      float* sums = out.sums.data() + px * kAovFloats;
      const int32_t samples = pixel_samples ? (*pixel_samples)[px] : rp.spp;
      for (int32_t s = 0; s < samples; ++s) {
        add_first_surface(sums, first_surface(view, rp, static_cast<uint32_t>(px), static_cast<uint32_t>(s)));
      }
    }
  });
  out.seconds = seconds_since(t0);
  return out;
}

}  // namespace wt::cpu

// The CUDA backend: uploads the scene, checks that the render fits the device,
// runs the chosen kernel with CUDA-event timing and reads the film back.
#include "cuda/cuda_backend.hpp"

#include <algorithm>
#include <chrono>
#include <string>

#include "cuda/buffer.hpp"
#include "cuda/device_scene.hpp"
#include "cuda/event.hpp"
#include "megakernel/megakernel.hpp"
#include "cuda/cuda_wavefront.hpp"
#include "render/passes.hpp"

namespace wt::cuda {

namespace {

constexpr const char* kStage = "render";

std::string mib(size_t bytes) { return std::to_string((bytes + (1 << 20) - 1) >> 20) + " MiB"; }

// The megakernel renders in passes of samples (at least ten, so that progress can
// be shown between them); the next pass is queued before the host waits on the
// last one, unless after_pass must see each pass's film.
RenderResult render_megakernel(const Scene& scene, const DeviceScene& ds, const RenderOptions& options) {
  const RenderParams& rp = options.params;
  const bool constant = options.kernel == Kernel::MegakernelConstant;
  if (constant) upload_constant_scene(scene, ds.view(), ds.image_views());
  const size_t pixels = static_cast<size_t>(rp.width) * rp.height;
  DeviceBuffer<float> film(pixels * 3, kStage);
  DeviceBuffer<unsigned long long> rays(2, kStage);  // path rays, shadow rays
  const std::vector<SamplePass> passes = plan_passes(options, 10);

  RenderResult out;
  auto run = [&](bool last) {
    if (options.initial_film) {
      film.upload(*options.initial_film, kStage);
    } else {
      film.zero(kStage);
    }
    rays.zero(kStage);
    out.samples = options.first_sample;
    out.interrupted = false;
    out.paths = 0;
    EventTimer timer("megakernel");
    timer.start();
    std::vector<Event> pass_done(passes.size());
    for (size_t p = 0; p < passes.size(); ++p) {
      const SamplePass& pass = passes[p];
      if (constant) {
        launch_megakernel_constant(rp, pass.first, pass.count, film.get(), rays.get(), nullptr);
      } else {
        launch_megakernel(ds.view(), rp, pass.first, pass.count, film.get(), rays.get(), nullptr);
      }
      pass_done[p].record("megakernel");
      out.samples = pass.first + pass.count;
      out.paths += pixels * static_cast<uint64_t>(pass.count);
      if (last && options.after_pass) {
        pass_done[p].synchronize("megakernel");
        if (!options.after_pass(out.samples, [&] { return film.download(kStage); })) {
          out.interrupted = p + 1 < passes.size();
          break;
        }
      }
      if (last && options.progress && p > 0) {
        pass_done[p - 1].synchronize("megakernel");
        unsigned long long so_far = 0;
        WT_CUDA(cudaMemcpy(&so_far, rays.get(), sizeof(so_far), cudaMemcpyDeviceToHost), "megakernel");
        options.progress(static_cast<double>(p) / passes.size(), so_far, timer.elapsed_host());
      }
    }
    return timer.stop();
  };
  for (int i = 0; i < options.warmup; ++i) run(false);
  out.seconds = run(true);
  unsigned long long counted[2] = {0, 0};
  WT_CUDA(cudaMemcpy(counted, rays.get(), sizeof(counted), cudaMemcpyDeviceToHost), kStage);
  out.rays = counted[0];
  out.shadow_rays = counted[1];
  out.rgb = film.download(kStage);
  out.radiance = Radiance::SumOfSamples;
  return out;
}

}  // namespace

size_t render_state_bytes(const RenderParams& rp, Kernel kernel, int64_t wave_size) {
  size_t film = static_cast<size_t>(rp.width) * rp.height * 3 * sizeof(float);
  if (is_wavefront(kernel)) {
    return film + wavefront_bytes(wave_size);
  }
  return film;
}

void require_device_memory(const RenderParams& rp, size_t need, size_t free_bytes, const std::string& device) {
  const size_t usable = free_bytes - std::min(free_bytes, size_t(256) << 20);  // headroom for the runtime
  if (need > usable) {
    throw SceneError("width x height: " + std::to_string(rp.width) + " x " + std::to_string(rp.height) +
                     " with this kernel needs " + mib(need) + " of device memory; " + device + " has " +
                     mib(free_bytes) + " free");
  }
}

RenderResult render(const Scene& scene, const RenderOptions& options) {
  if (device_count() == 0) throw DeviceError("backend: cuda was asked for, but no CUDA device is present");
  const RenderParams& rp = options.params;
  DeviceInfo info = device_info();

  const bool wavefront = is_wavefront(options.kernel);
  int64_t wave = wavefront ? choose_wave_size(options.wave_size, rp, info.free_memory) : 0;
  // Checked before allocating anything: a render that cannot fit fails with a
  // message rather than with an allocation error halfway through.
  require_device_memory(rp, render_state_bytes(rp, options.kernel, wave) + scene.device_bytes(), info.free_memory,
                        info.name);

  auto t0 = std::chrono::steady_clock::now();
  DeviceScene ds(scene, rp.width, rp.height);
  WT_CUDA(cudaDeviceSynchronize(), "scene upload");
  double upload = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  RenderResult out = wavefront ? render_wavefront(ds.view(), scene.sort_key_bits(), options, wave) : render_megakernel(scene, ds, options);
  out.upload_seconds = upload;
  out.device = info.name;
  if (options.progress) options.progress(1.0, out.rays, out.seconds);
  return out;
}

}  // namespace wt::cuda

// The CUDA backend: uploads the scene, checks that the render fits the device,
// runs the chosen kernel with CUDA-event timing and reads the film back.
#include "cuda/cuda_backend.hpp"

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "cuda/buffer.hpp"
#include "cuda/cuda_aovs.hpp"
#include "cuda/cuda_wavefront.hpp"
#include "cuda/device_scene.hpp"
#include "cuda/event.hpp"
#include "errors/errors.hpp"
#include "megakernel/megakernel.hpp"
#include "render/passes.hpp"
#include "wavetrace/aov.hpp"

namespace wt::cuda {

namespace {

constexpr const char* kStage = "render";

std::string mib(size_t bytes) { return std::to_string((bytes + (1 << 20) - 1) >> 20) + " MiB"; }

// The megakernel renders in passes of samples (at least ten, so that progress can
// be shown between them); the next pass is queued before the host waits on the
// last one, unless after_pass must see each pass's film. `rays`: two counters on the
// device (path rays, shadow rays), and `rays_told`, one value of page-locked host
// memory that progress reads them into, which the caller keeps from one render to
// the next.
RenderResult render_megakernel(const Scene& scene, const DeviceScene& ds, const SceneView& view,
                               const RenderOptions& options, int sm_count, unsigned long long* rays,
                               unsigned long long* rays_told) {
  const RenderParams& rp = options.params;
  const bool constant = options.kernel == Kernel::MegakernelConstant;
  if (constant) {
    upload_constant_scene(scene, view, ds.image_views());
    load_megakernel_constant(rp);
  } else {
    load_megakernel(view, rp);
  }
  // The pixels a sample visits: options.active_pixels, on the device, or every one.
  const size_t pixels = rendered_pixels(options);
  DeviceBuffer<uint32_t> active(options.active_pixels ? pixels : 0, kStage);
  if (options.active_pixels && pixels > 0) active.upload(*options.active_pixels, kStage);
  const size_t film_floats = static_cast<size_t>(rp.width) * rp.height * 3;
  // The render's own film, or the one it adds into (options.device_film).
  DeviceBuffer<float> own_film(options.device_film ? 0 : film_floats, kStage);
  float* const film = options.device_film ? options.device_film : own_film.get();
  const std::vector<SamplePass> passes = plan_passes(options, 10);
  // A small image's passes run in batches of samples (megakernel_batch), each
  // sample's radiance stored, then folded into running sums in sample order.
  int largest_pass = 0;
  for (const SamplePass& pass : passes) largest_pass = std::max(largest_pass, pass.count);
  const int batch = options.megakernel_batch > 0
                        ? std::min(options.megakernel_batch, std::max(largest_pass, 1))
                        : megakernel_batch(static_cast<int64_t>(pixels), sm_count, largest_pass);
  if (batch > 1) load_megakernel_fold();
  DeviceBuffer<float> radiance(batch > 1 ? pixels * 3 * batch : 0, kStage);
  DeviceBuffer<float> running(batch > 1 ? pixels * 3 : 0, kStage);
  // The work of a launch over the render's pixels: samples into `to_film`, or stored
  // in `to_radiance`.
  auto work = [&](float* to_film, float* to_radiance) {
    MegakernelWork w{to_film, to_radiance};
    if (options.active_pixels) {
      w.active = active.get();
      w.count = static_cast<uint32_t>(pixels);
    }
    return w;
  };
  auto launch = [&](int first, int count, const MegakernelWork& out) {
    if (constant) {
      launch_megakernel_constant(rp, first, count, out, rays, nullptr);
    } else {
      launch_megakernel(view, rp, first, count, out, rays, nullptr);
    }
  };

  RenderResult out;
  auto run = [&](bool last) {
    if (options.initial_film) {
      own_film.upload(*options.initial_film, kStage);
    } else {
      own_film.zero(kStage);  // nothing for a film of the caller's
    }
    WT_CUDA(cudaMemsetAsync(rays, 0, 2 * sizeof(unsigned long long)), kStage);
    out.samples = options.first_sample;
    out.interrupted = false;
    out.paths = 0;
    EventTimer timer("megakernel");
    timer.start();
    Event pass_done, told;
    for (size_t p = 0; p < passes.size(); ++p) {
      const SamplePass& pass = passes[p];
      // The rays of the passes before, copied to the host ahead of this pass: the
      // host waits for that copy, while this pass stays queued behind it (a copy that
      // waited for this pass left the device idle between passes).
      const bool tell = last && options.progress && p > 0;
      if (tell) {
        WT_CUDA(cudaMemcpyAsync(rays_told, rays, sizeof(unsigned long long), cudaMemcpyDeviceToHost, nullptr),
                "megakernel");
        told.record("megakernel");
      }
      if (batch <= 1) {
        launch(pass.first, pass.count, work(film, nullptr));
      } else {
        for (int at = 0; at < pass.count; at += batch) {
          const int n = std::min(batch, pass.count - at);
          launch(pass.first + at, n, work(nullptr, radiance.get()));
          launch_megakernel_fold(rp, n, work(film, radiance.get()), running.get(), at == 0, at + n == pass.count,
                                 nullptr);
        }
      }
      out.samples = pass.first + pass.count;
      out.paths += pixels * static_cast<uint64_t>(pass.count);
      if (last && options.after_pass) {
        pass_done.record("megakernel");
        pass_done.synchronize("megakernel");
        if (!options.after_pass(out.samples, [&] { return own_film.download(kStage); })) {
          out.interrupted = p + 1 < passes.size();
          break;
        }
      }
      if (tell) {
        told.synchronize("megakernel");
        options.progress(static_cast<double>(p) / passes.size(), *rays_told, timer.elapsed_host());
      }
    }
    return timer.stop();
  };
  for (int i = 0; i < options.warmup; ++i) run(false);
  out.seconds = run(true);
  unsigned long long counted[2] = {0, 0};
  WT_CUDA(cudaMemcpy(counted, rays, sizeof(counted), cudaMemcpyDeviceToHost), kStage);
  out.rays = counted[0];
  out.shadow_rays = counted[1];
  if (!options.device_film) out.rgb = own_film.download(kStage);
  out.radiance = Radiance::SumOfSamples;
  return out;
}

}  // namespace

size_t render_state_bytes(const RenderParams& rp, Kernel kernel, int64_t wave_size) {
  const size_t pixels = static_cast<size_t>(rp.width) * rp.height;
  const size_t film = pixels * 3 * sizeof(float);
  if (is_wavefront(kernel)) {
    return film + wavefront_bytes(wave_size);
  }
  // A small image's batches: each sample's radiance and the running sums, as large as
  // on a device of 256 SMs.
  const int batch = megakernel_batch(static_cast<int64_t>(pixels), 256, rp.spp);
  return film + (batch > 1 ? film * (batch + 1) : 0);
}

void require_device_memory(const RenderParams& rp, size_t need, size_t free_bytes, const std::string& device) {
  const size_t usable = free_bytes - std::min(free_bytes, size_t(256) << 20);  // headroom for the runtime
  if (need > usable) {
    throw InputError("width x height: " + std::to_string(rp.width) + " x " + std::to_string(rp.height) +
                     " with this kernel needs " + mib(need) + " of device memory; " + device + " has " +
                     mib(free_bytes) + " free");
  }
}

namespace {

// The scene on one device, uploaded once: with the device as it was read before the
// upload (its free memory, which the wave size is chosen from, so that a kept copy's
// renders choose what a fresh upload's would) and what its renders set up, kept from
// one to the next: the wavefront's (pinned counters, the wave's memory), the
// megakernels' ray counters, and render_image's film, image memory and finisher.
// (Device memory made and freed per render costs a free that waits for the device.)
struct DeviceCopy {
  DeviceCopy(const Scene& scene, const DeviceInfo& read_before)
      : info(read_before), rays(2, kStage), rays_told(1, kStage),
        images(ImageBlocks::Memory::Device) {
    const auto t0 = std::chrono::steady_clock::now();
    ds = std::make_unique<DeviceScene>(scene, scene.render.width, scene.render.height);
    WT_CUDA(cudaDeviceSynchronize(), "scene upload");
    upload_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  DeviceInfo info;
  std::unique_ptr<DeviceScene> ds;
  double upload_seconds = 0;
  WaveRenderer waves;
  DeviceBuffer<unsigned long long> rays;       // the megakernels' path and shadow rays
  PinnedBuffer<unsigned long long> rays_told;  // and their path rays so far, as progress reads them
  DeviceBuffer<float> film;                    // render_image's, kept for the next render of its size
  ImageFinisher finisher;                      // render_image's finishing of its images
  ImageBlocks images;                          // render_image's images wanted in device memory
};

}  // namespace
}  // namespace wt::cuda

namespace wt {

// Each device's copies of one scene, and whether a render holds each (two renders on
// one device at once, a split that names it twice, take a copy each).
struct ResidentScenes {
  struct Slot {
    std::shared_ptr<cuda::DeviceCopy> copy;
    bool held = false;
  };
  const Scene* scene = nullptr;
  mutable std::mutex mutex;
  std::map<int, std::vector<Slot>> by_device;
  int64_t uploads = 0;
};

}  // namespace wt

namespace wt::cuda {

namespace {

// The scene on the current device for one render, checked to fit with the render's
// state (`state_bytes` of it, given the device as the copy read it): a free copy the
// options' resident scenes keep there, or a new upload (kept there for the next
// render where they are given). Given back when the render is done. On a kept copy,
// `made_on` gives the part of that state the render makes anew, beside what the copy
// keeps for it (all of it where null).
class DeviceLease {
 public:
  DeviceLease(const Scene& scene, const RenderOptions& options,
              const std::function<size_t(const DeviceInfo&)>& state_bytes,
              const std::function<size_t(const DeviceCopy&)>& made_on = nullptr)
      : resident_(options.resident) {
    if (resident_ && resident_->scene != &scene) {
      throw std::logic_error("cuda: resident copies of another scene");
    }
    const RenderParams& rp = options.params;
    if (resident_) {
      WT_CUDA(cudaGetDevice(&device_), "device selection");
      std::lock_guard<std::mutex> lock(resident_->mutex);
      std::vector<ResidentScenes::Slot>& slots = resident_->by_device[device_];
      for (size_t i = 0; i < slots.size() && !copy_; ++i) {
        if (slots[i].held) continue;
        // The scene is there: only the state the render makes anew must fit beside it,
        // not what the copy keeps for it, which the free memory no longer counts (the
        // free memory read alone, and only where some is made: the device's properties
        // are the copy's).
        const DeviceCopy& kept = *slots[i].copy;
        const size_t made = made_on ? made_on(kept) : state_bytes(kept.info);
        if (made > 0) {
          size_t free_now = 0, total = 0;
          WT_CUDA(cudaMemGetInfo(&free_now, &total), "device query");
          require_device_memory(rp, made, free_now, kept.info.name);
        }
        slots[i].held = true;
        copy_ = slots[i].copy;
        slot_ = i;
      }
      if (!copy_) {
        copy_ = upload(scene, rp, state_bytes);
        slots.push_back({copy_, true});
        ++resident_->uploads;
        slot_ = slots.size() - 1;
        uploaded_ = true;
      }
    } else {
      copy_ = upload(scene, rp, state_bytes);
      uploaded_ = true;
    }
  }
  ~DeviceLease() {
    if (!resident_) return;
    std::lock_guard<std::mutex> lock(resident_->mutex);
    resident_->by_device[device_][slot_].held = false;
  }
  DeviceLease(const DeviceLease&) = delete;
  DeviceLease& operator=(const DeviceLease&) = delete;

  DeviceCopy& copy() const { return *copy_; }
  // The upload's time where this render made it; 0 where the copy was kept.
  double upload_seconds() const { return uploaded_ ? copy_->upload_seconds : 0; }

 private:
  static std::shared_ptr<DeviceCopy> upload(const Scene& scene, const RenderParams& rp,
                                            const std::function<size_t(const DeviceInfo&)>& state_bytes) {
    const DeviceInfo info = device_info();
    // Checked before allocating anything: a render that cannot fit fails with a
    // message rather than with an allocation error halfway through.
    require_device_memory(rp, state_bytes(info) + scene.device_bytes(), info.free_memory, info.name);
    return std::make_shared<DeviceCopy>(scene, info);
  }

  std::shared_ptr<ResidentScenes> resident_;
  std::shared_ptr<DeviceCopy> copy_;
  int device_ = 0;
  size_t slot_ = 0;
  bool uploaded_ = false;
};

// The wave size of a render on a device as the copy read it.
int64_t wave_size_on(const RenderOptions& options, const DeviceInfo& info) {
  return is_wavefront(options.kernel) ? choose_wave_size(options.wave_size, options.params, info.free_memory) : 0;
}

// Of a render's state (render_state_bytes) on a kept copy, the bytes the render makes
// anew: its wave's memory grows where it must (the old block freed first), and
// render_image's film (`image`), which the copy keeps, is made again (freed first)
// where its size changes, so each counts only what it needs beyond what the copy
// keeps of it; the rest (the render's own film, the megakernels' batches) is made
// per render.
size_t state_made_on(const DeviceCopy& copy, const RenderOptions& options, int64_t wave, bool image) {
  const RenderParams& rp = options.params;
  const size_t film = static_cast<size_t>(rp.width) * rp.height * 3 * sizeof(float);
  const size_t wave_need = is_wavefront(options.kernel) ? wavefront_bytes(wave) : 0;
  const size_t rest = render_state_bytes(rp, options.kernel, wave) - wave_need - (image ? film : 0);
  auto beyond = [](size_t need, size_t kept) { return need - std::min(need, kept); };
  return rest + beyond(wave_need, copy.waves.kept_bytes()) +
         (image ? beyond(film, copy.film.size() * sizeof(float)) : 0);
}

// The scene on the current device (DeviceLease), and renders of any of the render's
// samples over it. `image`: render_image's, whose film the copy keeps, where render's
// film is the render's own.
class Uploaded {
 public:
  Uploaded(const Scene& scene, const RenderOptions& options, bool image = false)
      : scene_(scene),
        lease_(
            scene, options,
            [&options](const DeviceInfo& info) {
              return render_state_bytes(options.params, options.kernel, wave_size_on(options, info));
            },
            [&options, image](const DeviceCopy& copy) {
              return state_made_on(copy, options, wave_size_on(options, copy.info), image);
            }),
        wave_(wave_size_on(options, lease_.copy().info)),
        view_(lease_.copy().ds->view_at(scene, options.params.width, options.params.height)) {}

  // The sums the chunks of render_kept add to, cleared, and the host memory collect()
  // brings them back to: made before the render's clock starts (or at the first chunk).
  void prepare_kept(const RenderOptions& options) {
    if (kept_) return;
    const RenderParams& rp = options.params;
    const size_t floats = static_cast<size_t>(rp.width) * rp.height * 3;
    kept_ = std::make_unique<DeviceBuffer<float>>(floats, "split");
    kept_->zero("split");
    kept_host_ = std::make_unique<PinnedBuffer<float>>(floats, "split");
    WT_CUDA(cudaDeviceSynchronize(), "split");  // cleared before any stream adds to it
  }

  // A chunk whose sums are added to this device's kept sums, which collect() brings
  // back once.
  RenderResult render_kept(const RenderOptions& options) {
    prepare_kept(options);
    RenderOptions into = options;
    into.device_film = kept_->get();
    return render(into);
  }

  FilmSums collect() const {
    if (!kept_) return {};
    WT_CUDA(cudaDeviceSynchronize(), "split");  // every chunk's additions are in
    kept_host_->download(kept_->get(), "split");
    return FilmSums{kept_host_->get(), kept_host_->size()};
  }

  DeviceCopy& copy() const { return lease_.copy(); }

  RenderResult render(const RenderOptions& options) const {
    DeviceCopy& copy = lease_.copy();
    RenderResult out = is_wavefront(options.kernel)
                           ? copy.waves.render(view_, scene_.sort_key_bits(), options, wave_)
                           : render_megakernel(scene_, *copy.ds, view_, options, copy.info.sm_count, copy.rays.get(),
                                               copy.rays_told.get());
    out.upload_seconds = lease_.upload_seconds();
    out.device = copy.info.name;
    return out;
  }

 private:
  const Scene& scene_;
  DeviceLease lease_;
  int64_t wave_ = 0;
  SceneView view_;
  std::unique_ptr<DeviceBuffer<float>> kept_;
  std::unique_ptr<PinnedBuffer<float>> kept_host_;
};

}  // namespace

void check_devices(const RenderOptions& options) {
  const int present = device_count();
  if (present == 0) throw DeviceError("backend: cuda was asked for, but no CUDA device is present");
  require_cuda_devices(options.devices, present);
}

DeviceRenderer device_renderer(const Scene& scene, const RenderOptions& options, size_t i) {
  // The current device is the calling thread's: the split's thread for it from here on.
  WT_CUDA(cudaSetDevice(options.devices[i]), "device selection");
  auto uploaded = std::make_shared<Uploaded>(scene, options);
  return {[uploaded](const RenderOptions& chunk) { return uploaded->render(chunk); },
          [uploaded](const RenderOptions& chunk) { return uploaded->render_kept(chunk); },
          [uploaded] { return uploaded->collect(); },
          [uploaded](const RenderOptions& chunk) { uploaded->prepare_kept(chunk); }};
}

RenderResult render(const Scene& scene, const RenderOptions& options) {
  if (options.devices.size() == 1) WT_CUDA(cudaSetDevice(options.devices[0]), "device selection");
  const Uploaded uploaded(scene, options);
  RenderResult out = uploaded.render(options);
  if (options.progress) options.progress(1.0, out.rays, out.seconds);
  return out;
}

RenderResult render_image(const Scene& scene, const RenderOptions& options, DeviceImage& image) {
  if (options.initial_film || options.after_pass || options.path_feed || options.device_film ||
      options.active_pixels || options.devices.size() > 1) {
    throw std::logic_error("cuda: render_image renders a whole film from sample 0 on one device");
  }
  if (options.devices.size() == 1) WT_CUDA(cudaSetDevice(options.devices[0]), "device selection");
  const Uploaded uploaded(scene, options, true);
  const RenderParams& rp = options.params;
  const size_t pixels = static_cast<size_t>(rp.width) * rp.height;
  // The render adds into a film the copy keeps, which it neither clears nor brings
  // back; its warm-ups render into it first, untimed, as they do into their own.
  DeviceCopy& copy = uploaded.copy();
  DeviceBuffer<float>& film = copy.film;
  if (film.size() != pixels * 3) film.allocate(pixels * 3, kStage);
  RenderOptions into = options;
  into.device_film = film.get();
  into.warmup = 0;
  for (int i = 0; i < options.warmup; ++i) {
    RenderOptions warm = into;
    warm.progress = nullptr;
    film.zero(kStage);
    uploaded.render(warm);
  }
  film.zero(kStage);
  RenderResult out = uploaded.render(into);
  if (!image.rgba) image.rgba = copy.images.take(pixels * 4);
  copy.finisher.finish(film.get(), pixels, out.samples, image);
  out.radiance = Radiance::MeanOfSamples;
  if (options.progress) options.progress(1.0, out.rays, out.seconds);
  return out;
}

AovSums render_aov_sums(const Scene& scene, const RenderOptions& options,
                        const std::vector<int32_t>* pixel_samples) {
  constexpr const char* kAovStage = "aovs";
  if (!options.devices.empty()) WT_CUDA(cudaSetDevice(options.devices[0]), "device selection");
  const RenderParams& rp = options.params;
  const size_t floats = static_cast<size_t>(rp.width) * rp.height * kAovFloats;
  const DeviceLease lease(scene, options, [floats](const DeviceInfo&) { return floats * sizeof(float); });
  const SceneView view = lease.copy().ds->view_at(scene, rp.width, rp.height);
  DeviceBuffer<float> sums(floats, kAovStage);
  DeviceBuffer<int32_t> counts(pixel_samples ? pixel_samples->size() : 0, kAovStage);
  if (pixel_samples) counts.upload(*pixel_samples, kAovStage);
  AovSums out;
  out.samples = rp.spp;
  EventTimer timer(kAovStage);
  timer.start();
  launch_first_surface(view, rp, pixel_samples ? counts.get() : nullptr, sums.get(), nullptr);
  out.seconds = timer.stop();
  out.sums = sums.download(kAovStage);
  return out;
}

std::shared_ptr<ResidentScenes> keep_scene(const Scene& scene) {
  auto out = std::make_shared<ResidentScenes>();
  out->scene = &scene;
  return out;
}

float* copy_to_device(const float* host, size_t n, int device) {
  constexpr const char* kHandOff = "image hand-off";
  WT_CUDA(cudaSetDevice(device), kHandOff);
  void* p = nullptr;
  check_allocation(static_cast<int>(cudaMalloc(&p, n * sizeof(float))), n * sizeof(float), kHandOff);
  const cudaError_t copied = cudaMemcpy(p, host, n * sizeof(float), cudaMemcpyHostToDevice);
  if (copied != cudaSuccess) {
    cudaFree(p);
    check(static_cast<int>(copied), "cudaMemcpy(p, host, n * sizeof(float), cudaMemcpyHostToDevice)", kHandOff);
  }
  return static_cast<float*>(p);
}

void free_on_device(void* p) noexcept { cudaFree(p); }

void copy_to_host(const float* on_device, size_t n, float* host) {
  WT_CUDA(cudaMemcpy(host, on_device, n * sizeof(float), cudaMemcpyDeviceToHost), "image hand-off");
}

int64_t uploads(const ResidentScenes& resident) {
  std::lock_guard<std::mutex> lock(resident.mutex);
  return resident.uploads;
}

}  // namespace wt::cuda

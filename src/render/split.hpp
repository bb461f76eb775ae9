// One render over several devices (the GPUs of a host, or host "devices" of the CPU
// backend): its samples are cut into chunks (the passes the render would make on one
// device), handed to the devices as they free up, so that a faster or less busy
// device takes more of them. Each device keeps its chunks' sums and the devices'
// sums are added in device order; where after_pass must see the film after every
// chunk, the chunks are folded into the film in their order instead. The wavefront
// kernels, where no after_pass watches, share the render's paths instead: each
// device renders all the samples but traces only the blocks of paths it takes from
// one PathFeed, so that its wave refills across blocks and drains once, at the end,
// rather than once a chunk. The counter-based random numbers make a path's value
// independent of where it runs, so the image is the one-device image up to the
// order of float additions.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cpu/parallel.hpp"
#include "cuda/device.hpp"
#include "errors/errors.hpp"
#include "render/passes.hpp"
#include "render/render_types.hpp"
#include "scene/scene.hpp"

namespace wt {

// Chunks a device gets at least, on average: enough for a faster device to take more.
constexpr int kChunksPerDevice = 4;
// At least as many chunks as the CUDA megakernel makes passes on one device: for two
// devices the chunks are its passes (progress then moves as often as on one device).
constexpr int kMinChunks = 10;

// Throws InputError naming the first index that is not one of the `present` CUDA
// devices (0..present-1): the one check of a device list, from the command line or
// from a caller's options.
inline void require_cuda_devices(const std::vector<int>& devices, int present) {
  for (int d : devices) {
    if (d < 0 || d >= present) {
      throw InputError("devices: " + std::to_string(d) + " is not a CUDA device (" + std::to_string(present) +
                       " present)");
    }
  }
}

// What renders one device's chunks: made on that device's own thread (where it may
// upload the scene), then called on it with each chunk's options. `render` returns
// the chunk's pixel sums (Radiance::SumOfSamples) and its counts. A device that can
// keep sums of its own (a GPU, in its memory) also has `render_kept`, which adds the
// chunk's sums to them and returns its counts alone, `collect`, which brings them
// back once at the end, and may have `prepare`, which sets up both the kept sums and
// the host memory they come back to before the render's clock starts.
using ChunkRenderer = std::function<RenderResult(const RenderOptions& chunk)>;
// A device's sums on the host: `size` floats, owned by the device's renderer and
// valid until it is destroyed.
struct FilmSums {
  const float* data = nullptr;
  size_t size = 0;
};
struct DeviceRenderer {
  DeviceRenderer(ChunkRenderer r, ChunkRenderer kept = {}, std::function<FilmSums()> c = {},
                 std::function<void(const RenderOptions&)> p = {})
      : render(std::move(r)), render_kept(std::move(kept)), collect(std::move(c)), prepare(std::move(p)) {}
  ChunkRenderer render;
  ChunkRenderer render_kept;                        // may be empty
  std::function<FilmSums()> collect;               // with render_kept
  std::function<void(const RenderOptions&)> prepare;  // with render_kept; may be empty
};
using MakeChunkRenderer = std::function<DeviceRenderer(size_t device)>;

namespace split_detail {

// film += each device's sums, in device order for every value (so that the result
// does not depend on the threads), over the host's cores (at most 16), each its own
// range of values. Devices without sums are skipped.
inline void add_in_order(std::vector<float>& film, const std::vector<FilmSums>& sums) {
  const int parts = std::min(16, cpu::thread_count(0));
  const int64_t n = static_cast<int64_t>(film.size());
  cpu::parallel_for(n, (n + parts - 1) / parts, parts, [&](int64_t begin, int64_t end, int) {
    for (const FilmSums& s : sums) {
      if (s.data == nullptr) continue;
      for (int64_t i = begin; i < end; ++i) film[i] += s.data[i];
    }
  });
}

// Throws DeviceError unless `what` (a device's film) came back with `floats` values.
inline void require_film(size_t values, size_t floats, const char* what) {
  if (values != floats) {
    throw DeviceError(std::string(what) + " came back with " + std::to_string(values) + " film values, not " +
                      std::to_string(floats));
  }
}

// Adds `more` into `sums` (taking it where `sums` is still empty).
inline void add_into(std::vector<float>& sums, std::vector<float>&& more) {
  if (sums.empty()) {
    sums = std::move(more);
    return;
  }
  for (size_t i = 0; i < more.size(); ++i) sums[i] += more[i];
}

// The exception `e` again, of the same kind, its message led by the device's name.
[[noreturn]] inline void rethrow_naming(const std::exception_ptr& e, const std::string& device) {
  try {
    std::rethrow_exception(e);
  } catch (const InputError& x) {
    throw InputError(device + ": " + x.what());
  } catch (const cuda::CudaError& x) {
    throw cuda::CudaError(device + ": " + x.what());
  } catch (const DeviceError& x) {
    throw DeviceError(device + ": " + x.what());
  }
}

}  // namespace split_detail

// Renders `options` over the devices `labels` names (one worker thread each). The
// result's shares say what each device did; its seconds run from when every device
// has its scene, its warm-up renders and the memory its sums need, to the film that
// adds every device's sums (as one device's seconds end with its sums in its memory,
// before the film comes back; freeing each device's memory comes after). A device
// that fails stops the others after their current chunk, and the render throws its
// error, named after the device; no partial result is returned.
inline RenderResult render_split(const RenderOptions& options, const std::vector<std::string>& labels,
                                 const MakeChunkRenderer& make) {
  const size_t devices = labels.size();
  const RenderParams& rp = options.params;
  const std::vector<SamplePass> chunks =
      plan_passes(options, std::max<int>(kMinChunks, kChunksPerDevice * static_cast<int>(devices)));
  const size_t floats = static_cast<size_t>(rp.width) * rp.height * 3;

  RenderResult out;
  out.rgb = options.initial_film ? *options.initial_film : std::vector<float>(floats, 0.0f);
  out.radiance = Radiance::SumOfSamples;
  out.samples = options.first_sample;
  out.shares.resize(devices);
  for (size_t d = 0; d < devices; ++d) out.shares[d].device = labels[d];

  std::mutex m;
  std::condition_variable ready_cv, chunk_cv;
  size_t ready = 0, next = 0, folded = 0, working = devices;
  std::vector<std::vector<float>> waiting(chunks.size());  // chunk sums not yet folded
  std::vector<char> finished(chunks.size(), 0);
  // Without after_pass, which must see the film after each chunk, every device keeps
  // the sums of its chunks (on a GPU, in its own memory: nothing comes back until the
  // end) and the devices' sums are added in device order at the end. Which chunks a
  // device summed depends on timing, so the image then equals the chunk-order one
  // within float rounding rather than to the bit.
  const bool keep = !options.after_pass;
  // The wavefront's devices share the paths of one render of every sample.
  const bool fed = keep && is_wavefront(options.kernel);
  PathFeed feed(devices);
  // A fed device's rays so far, for progress lines.
  std::vector<std::atomic<uint64_t>> fed_rays(devices);
  std::vector<std::vector<float>> kept(devices);  // sums a device returned to the host
  std::vector<FilmSums> sums_of(devices);          // every device's sums, at the end
  bool stop = false, released = false;
  std::condition_variable release_cv;
  std::exception_ptr error;
  std::string failed_device;
  std::chrono::steady_clock::time_point start;

  auto work = [&](size_t d) {
    std::optional<DeviceRenderer> made;
    try {
      made.emplace(make(d));
      DeviceRenderer& renderer = *made;
      const ChunkRenderer& render_chunk = renderer.render;
      const bool device_keeps = keep && renderer.render_kept && renderer.collect;
      RenderOptions chunk = options;
      chunk.initial_film = nullptr;
      chunk.after_pass = {};
      chunk.progress = {};
      chunk.samples_per_pass = 0;
      if (options.warmup > 0 && !chunks.empty()) {
        chunk.first_sample = chunks[0].first;
        chunk.sample_count = chunks[0].count;
        render_chunk(chunk);  // the warm-ups, untimed, before the start
      }
      chunk.warmup = 0;
      if (device_keeps && renderer.prepare) renderer.prepare(chunk);
      {
        std::unique_lock<std::mutex> lock(m);
        if (++ready == devices) {
          start = std::chrono::steady_clock::now();
          ready_cv.notify_all();
        }
        ready_cv.wait(lock, [&] { return ready == devices || stop; });
      }
      // Counts one of this device's renders (`pieces` chunks or blocks) into its share; under m.
      auto count = [&](const RenderResult& r, int32_t samples, uint64_t paths, uint64_t pieces) {
        DeviceShare& share = out.shares[d];
        share.samples += samples;
        share.paths += paths;
        share.chunks += static_cast<int32_t>(std::min<uint64_t>(INT32_MAX, pieces));
        share.seconds += r.seconds;
        share.rays += r.rays;
        share.shadow_rays += r.shadow_rays;
        if (share.name.empty()) share.name = r.device;
        out.upload_seconds = std::max(out.upload_seconds, r.upload_seconds);
      };
      if (fed) {
        // One render of every sample, of the paths this device takes from the feed.
        chunk.first_sample = options.first_sample;
        chunk.sample_count = options.sample_count;
        chunk.path_feed = &feed;
        if (options.progress) chunk.progress = [&, d](double, uint64_t rays, double) { fed_rays[d] = rays; };
        RenderResult r = device_keeps ? renderer.render_kept(chunk) : render_chunk(chunk);
        if (!device_keeps) {
          split_detail::require_film(r.rgb.size(), floats, "its paths");
          split_detail::add_into(kept[d], std::move(r.rgb));
        }
        std::lock_guard<std::mutex> lock(m);
        count(r, 0, r.paths, r.blocks);
      } else {
        for (;;) {
          size_t c;
          {
            std::lock_guard<std::mutex> lock(m);
            if (stop || next >= chunks.size()) break;
            c = next++;
          }
          chunk.first_sample = chunks[c].first;
          chunk.sample_count = chunks[c].count;
          RenderResult r = device_keeps ? renderer.render_kept(chunk) : render_chunk(chunk);
          if (!device_keeps) split_detail::require_film(r.rgb.size(), floats, "a chunk");
          if (keep && !device_keeps) split_detail::add_into(kept[d], std::move(r.rgb));
          std::lock_guard<std::mutex> lock(m);
          count(r, chunks[c].count, static_cast<uint64_t>(chunks[c].count) * rp.width * rp.height, 1);
          if (!keep) waiting[c] = std::move(r.rgb);
          finished[c] = 1;
          chunk_cv.notify_all();
        }
      }
      if (device_keeps) {
        const FilmSums sums = renderer.collect();  // none (size 0) where it took no chunk
        if (sums.size != 0) {
          split_detail::require_film(sums.size, floats, "its sums");
          sums_of[d] = sums;
        }
      } else if (!kept[d].empty()) {
        sums_of[d] = FilmSums{kept[d].data(), kept[d].size()};
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(m);
      if (!error) {
        error = std::current_exception();
        failed_device = labels[d];
      }
      stop = true;
      feed.stop();
      ready_cv.notify_all();
    }
    std::unique_lock<std::mutex> lock(m);
    --working;
    chunk_cv.notify_all();
    // The device's memory, its sums among it, is freed once they are added.
    release_cv.wait(lock, [&] { return released; });
    lock.unlock();
    made.reset();
  };
  std::vector<std::thread> threads;
  // Lets the devices free their memory, and waits until they have.
  auto release_devices = [&] {
    {
      std::lock_guard<std::mutex> lock(m);
      released = true;
    }
    release_cv.notify_all();
    for (std::thread& t : threads) t.join();
  };

  for (size_t d = 0; d < devices; ++d) threads.emplace_back(work, d);
  // Waits until every device has ended (each still holds its memory, sums and all).
  auto wait_for_devices = [&] {
    std::unique_lock<std::mutex> lock(m);
    chunk_cv.wait(lock, [&] { return working == 0; });
  };
  // The same, then lets them free their memory: the way out of a failed render.
  auto wind_down = [&] {
    wait_for_devices();
    release_devices();
  };
  try {
    // This thread folds the finished chunks into the film in their order while the
    // devices render the next ones; after_pass may stop the render after any chunk.
    if (fed && options.progress) {
      // Fed devices fold nothing until the end: progress is the paths handed out.
      double all_paths = 0;
      for (const SamplePass& c : chunks) all_paths += static_cast<double>(rp.width) * rp.height * c.count;
      std::unique_lock<std::mutex> lock(m);
      while (!chunk_cv.wait_for(lock, std::chrono::milliseconds(250), [&] { return stop || working == 0; })) {
        if (ready < devices) continue;
        lock.unlock();
        uint64_t rays = 0;
        for (const std::atomic<uint64_t>& r : fed_rays) rays += r;
        options.progress(std::min(1.0, static_cast<double>(feed.given()) / all_paths), rays,
                         std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        lock.lock();
      }
    }
    {
      std::unique_lock<std::mutex> lock(m);
      for (;;) {
        chunk_cv.wait(lock, [&] { return stop || working == 0 || (folded < chunks.size() && finished[folded]); });
        if (stop || folded == chunks.size() || !finished[folded]) break;
        std::vector<float> sums = std::move(waiting[folded]);
        lock.unlock();
        if (!keep) {
          for (size_t i = 0; i < floats; ++i) out.rgb[i] += sums[i];
        }
        sums = {};
        lock.lock();
        out.samples = chunks[folded].first + chunks[folded].count;
        ++folded;
        if (options.after_pass || options.progress) {
          uint64_t rays = 0;
          for (const DeviceShare& s : out.shares) rays += s.rays;
          const int32_t samples = out.samples;
          lock.unlock();
          const bool go_on = !options.after_pass || options.after_pass(samples, [&] { return out.rgb; });
          if (go_on && options.progress) {
            options.progress(static_cast<double>(folded) / chunks.size(), rays,
                             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
          }
          lock.lock();
          if (!go_on) stop = true;
        }
      }
    }
  } catch (...) {
    // after_pass or progress failed (a checkpoint that could not be written): the
    // devices stop after their current chunk, and the render throws that error.
    {
      std::lock_guard<std::mutex> lock(m);
      stop = true;
    }
    ready_cv.notify_all();
    feed.stop();
    wind_down();
    throw;
  }
  if (error) {
    wind_down();
    split_detail::rethrow_naming(error, failed_device);
  }
  wait_for_devices();
  // In device order, onto zeros (the first device's sums are then the film itself:
  // x + 0 is x) or onto the resumed film.
  if (keep) split_detail::add_in_order(out.rgb, sums_of);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  release_devices();
  if (fed) {
    // Every path was traced (a device that fails throws above): the whole render.
    folded = chunks.size();
    out.samples = chunks.empty() ? options.first_sample : chunks.back().first + chunks.back().count;
  }
  out.interrupted = folded < chunks.size();
  for (const DeviceShare& s : out.shares) {
    out.rays += s.rays;
    out.shadow_rays += s.shadow_rays;
  }
  out.paths = static_cast<uint64_t>(out.samples - options.first_sample) * rp.width * rp.height;
  out.device = std::to_string(devices) + " devices";
  return out;
}

}  // namespace wt

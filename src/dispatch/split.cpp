#include "dispatch/split.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include "cpu/parallel.hpp"
#include "device/device.hpp"
#include "errors/errors.hpp"
#include "render/passes.hpp"

namespace wt {

namespace {

using Clock = std::chrono::steady_clock;

// film += each device's sums, in device order for every value (so that the result
// does not depend on the threads), over the host's cores (at most 16), each its own
// range of values. Devices without sums are skipped.
void add_in_order(std::vector<float>& film, const std::vector<FilmSums>& sums) {
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
void require_film(size_t values, size_t floats, const char* what) {
  if (values != floats) {
    throw DeviceError(std::string(what) + " came back with " + std::to_string(values) + " film values, not " +
                      std::to_string(floats));
  }
}

// Adds `more` into `sums` (taking it where `sums` is still empty).
void add_into(std::vector<float>& sums, std::vector<float>&& more) {
  if (sums.empty()) {
    sums = std::move(more);
    return;
  }
  for (size_t i = 0; i < more.size(); ++i) sums[i] += more[i];
}

// The exception `e` again, of the same kind, its message led by the device's name.
[[noreturn]] void rethrow_naming(const std::exception_ptr& e, const std::string& device) {
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

// One render split over devices: what the devices' threads and the calling thread
// share. Each device's thread makes its renderer, gets ready (warm-ups, the memory
// for its sums), renders its share (chunks of samples, or the paths it takes from
// the feed), hands its sums over and frees its memory once told to. The calling
// thread meanwhile folds the finished chunks into the film in their order (or draws
// the fed devices' progress), then adds the devices' kept sums in device order.
class SplitRender {
 public:
  SplitRender(const RenderOptions& options, const std::vector<std::string>& labels, const MakeChunkRenderer& make)
      : options_(options),
        labels_(labels),
        make_(make),
        devices_(labels.size()),
        chunks_(plan_passes(options, std::max<int>(kMinChunks, kChunksPerDevice * static_cast<int>(devices_)))),
        floats_(static_cast<size_t>(options.params.width) * options.params.height * 3),
        // Without after_pass, which must see the film after each chunk, every device
        // keeps the sums of its chunks (on a GPU, in its own memory: nothing comes
        // back until the end) and the devices' sums are added in device order at the
        // end. Which chunks a device summed depends on timing, so the image then
        // equals the chunk-order one within float rounding rather than to the bit.
        keep_(!options.after_pass),
        // The wavefront's devices share the paths of one render of every sample.
        fed_(keep_ && is_wavefront(options.kernel)),
        working_(devices_),
        waiting_(chunks_.size()),
        finished_(chunks_.size(), 0),
        feed_(devices_),
        fed_rays_(devices_),
        kept_(devices_),
        sums_of_(devices_) {
    out_.rgb = options.initial_film ? *options.initial_film : std::vector<float>(floats_, 0.0f);
    out_.radiance = Radiance::SumOfSamples;
    out_.samples = options.first_sample;
    out_.shares.resize(devices_);
    for (size_t d = 0; d < devices_; ++d) out_.shares[d].device = labels[d];
  }

  RenderResult run() {
    for (size_t d = 0; d < devices_; ++d) threads_.emplace_back(&SplitRender::device, this, d);
    try {
      if (fed_ && options_.progress) draw_fed_progress();
      fold_chunks();
    } catch (...) {
      // after_pass or progress failed (a checkpoint that could not be written): the
      // devices stop after their current chunk, and the render throws that error.
      stop_devices();
      wind_down();
      throw;
    }
    if (error_) {
      wind_down();
      rethrow_naming(error_, failed_device_);
    }
    wait_for_devices();
    // In device order, onto zeros (the first device's sums are then the film itself:
    // x + 0 is x) or onto the resumed film.
    if (keep_) add_in_order(out_.rgb, sums_of_);
    out_.seconds = seconds_since_start();
    release_devices();
    return finish();
  }

 private:
  // ---- a device's thread ----

  void device(size_t d) {
    std::optional<DeviceRenderer> made;
    try {
      made.emplace(make_(d));
      DeviceRenderer& renderer = *made;
      const bool device_keeps = keep_ && renderer.render_kept && renderer.collect;
      RenderOptions chunk = options_;
      chunk.initial_film = nullptr;
      chunk.after_pass = {};
      chunk.progress = {};
      chunk.samples_per_pass = 0;
      get_ready(renderer, chunk, device_keeps);
      if (fed_) {
        render_fed(d, renderer, chunk, device_keeps);
      } else {
        render_chunks(d, renderer, chunk, device_keeps);
      }
      hand_over_sums(d, renderer, device_keeps);
    } catch (...) {
      fail(d);
    }
    std::unique_lock<std::mutex> lock(m_);
    --working_;
    chunk_cv_.notify_all();
    // The device's memory, its sums among it, is freed once they are added.
    release_cv_.wait(lock, [&] { return released_; });
    lock.unlock();
    made.reset();
  }

  // The untimed warm-ups and the memory for the kept sums, then the wait for every
  // device to be as far: the render's clock starts with the last one.
  void get_ready(DeviceRenderer& renderer, RenderOptions& chunk, bool device_keeps) {
    if (options_.warmup > 0 && !chunks_.empty()) {
      chunk.first_sample = chunks_[0].first;
      chunk.sample_count = chunks_[0].count;
      renderer.render(chunk);
    }
    chunk.warmup = 0;
    if (device_keeps && renderer.prepare) renderer.prepare(chunk);
    std::unique_lock<std::mutex> lock(m_);
    if (++ready_ == devices_) {
      start_ = Clock::now();
      ready_cv_.notify_all();
    }
    ready_cv_.wait(lock, [&] { return ready_ == devices_ || stop_; });
  }

  // One render of every sample, of the paths this device takes from the feed.
  void render_fed(size_t d, DeviceRenderer& renderer, RenderOptions& chunk, bool device_keeps) {
    chunk.first_sample = options_.first_sample;
    chunk.sample_count = options_.sample_count;
    chunk.path_feed = &feed_;
    if (options_.progress) chunk.progress = [this, d](double, uint64_t rays, double) { fed_rays_[d] = rays; };
    RenderResult r = device_keeps ? renderer.render_kept(chunk) : renderer.render(chunk);
    if (!device_keeps) {
      require_film(r.rgb.size(), floats_, "its paths");
      add_into(kept_[d], std::move(r.rgb));
    }
    std::lock_guard<std::mutex> lock(m_);
    count(d, r, 0, r.paths, r.blocks);
  }

  // Chunks of samples, taken from the shared counter as the device frees up.
  void render_chunks(size_t d, DeviceRenderer& renderer, RenderOptions& chunk, bool device_keeps) {
    const RenderParams& rp = options_.params;
    for (;;) {
      size_t c;
      {
        std::lock_guard<std::mutex> lock(m_);
        if (stop_ || next_ >= chunks_.size()) break;
        c = next_++;
      }
      chunk.first_sample = chunks_[c].first;
      chunk.sample_count = chunks_[c].count;
      RenderResult r = device_keeps ? renderer.render_kept(chunk) : renderer.render(chunk);
      if (!device_keeps) require_film(r.rgb.size(), floats_, "a chunk");
      if (keep_ && !device_keeps) add_into(kept_[d], std::move(r.rgb));
      std::lock_guard<std::mutex> lock(m_);
      count(d, r, chunks_[c].count, static_cast<uint64_t>(chunks_[c].count) * rp.width * rp.height, 1);
      if (!keep_) waiting_[c] = std::move(r.rgb);
      finished_[c] = 1;
      chunk_cv_.notify_all();
    }
  }

  // Counts one of device d's renders (`pieces` chunks or blocks) into its share; under m_.
  void count(size_t d, const RenderResult& r, int32_t samples, uint64_t paths, uint64_t pieces) {
    DeviceShare& share = out_.shares[d];
    share.samples += samples;
    share.paths += paths;
    share.chunks += static_cast<int32_t>(std::min<uint64_t>(INT32_MAX, pieces));
    share.seconds += r.seconds;
    share.rays += r.rays;
    share.shadow_rays += r.shadow_rays;
    if (share.name.empty()) share.name = r.device;
    out_.upload_seconds = std::max(out_.upload_seconds, r.upload_seconds);
  }

  // The device's sums, where the calling thread adds them: its kept sums, brought
  // back, or those it returned chunk by chunk.
  void hand_over_sums(size_t d, DeviceRenderer& renderer, bool device_keeps) {
    if (device_keeps) {
      const FilmSums sums = renderer.collect();  // none (size 0) where it took no chunk
      if (sums.size != 0) {
        require_film(sums.size, floats_, "its sums");
        sums_of_[d] = sums;
      }
    } else if (!kept_[d].empty()) {
      sums_of_[d] = FilmSums{kept_[d].data(), kept_[d].size()};
    }
  }

  // The first device to fail stops the others; its error is the render's.
  void fail(size_t d) {
    std::lock_guard<std::mutex> lock(m_);
    if (!error_) {
      error_ = std::current_exception();
      failed_device_ = labels_[d];
    }
    stop_ = true;
    feed_.stop();
    ready_cv_.notify_all();
  }

  // ---- the calling thread ----

  // Fed devices fold nothing until the end: progress is the paths handed out.
  void draw_fed_progress() {
    const RenderParams& rp = options_.params;
    double all_paths = 0;
    for (const SamplePass& c : chunks_) all_paths += static_cast<double>(rp.width) * rp.height * c.count;
    std::unique_lock<std::mutex> lock(m_);
    while (!chunk_cv_.wait_for(lock, std::chrono::milliseconds(250), [&] { return stop_ || working_ == 0; })) {
      if (ready_ < devices_) continue;
      lock.unlock();
      uint64_t rays = 0;
      for (const std::atomic<uint64_t>& r : fed_rays_) rays += r;
      options_.progress(std::min(1.0, static_cast<double>(feed_.given()) / all_paths), rays, seconds_since_start());
      lock.lock();
    }
  }

  // Folds the finished chunks into the film in their order while the devices render
  // the next ones; after_pass may stop the render after any chunk.
  void fold_chunks() {
    std::unique_lock<std::mutex> lock(m_);
    for (;;) {
      chunk_cv_.wait(lock, [&] { return stop_ || working_ == 0 || (folded_ < chunks_.size() && finished_[folded_]); });
      if (stop_ || folded_ == chunks_.size() || !finished_[folded_]) break;
      std::vector<float> sums = std::move(waiting_[folded_]);
      lock.unlock();
      if (!keep_) {
        for (size_t i = 0; i < floats_; ++i) out_.rgb[i] += sums[i];
      }
      sums = {};
      lock.lock();
      out_.samples = chunks_[folded_].first + chunks_[folded_].count;
      ++folded_;
      if (options_.after_pass || options_.progress) {
        uint64_t rays = 0;
        for (const DeviceShare& s : out_.shares) rays += s.rays;
        const int32_t samples = out_.samples;
        lock.unlock();
        const bool go_on = !options_.after_pass || options_.after_pass(samples, [&] { return out_.rgb; });
        if (go_on && options_.progress) {
          options_.progress(static_cast<double>(folded_) / chunks_.size(), rays, seconds_since_start());
        }
        lock.lock();
        if (!go_on) stop_ = true;
      }
    }
  }

  void stop_devices() {
    {
      std::lock_guard<std::mutex> lock(m_);
      stop_ = true;
    }
    ready_cv_.notify_all();
    feed_.stop();
  }

  // Waits until every device has ended (each still holds its memory, sums and all).
  void wait_for_devices() {
    std::unique_lock<std::mutex> lock(m_);
    chunk_cv_.wait(lock, [&] { return working_ == 0; });
  }

  // Lets the devices free their memory, and waits until they have.
  void release_devices() {
    {
      std::lock_guard<std::mutex> lock(m_);
      released_ = true;
    }
    release_cv_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

  // The way out of a failed render.
  void wind_down() {
    wait_for_devices();
    release_devices();
  }

  double seconds_since_start() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

  // The result's counts, once every device has ended.
  RenderResult finish() {
    const RenderParams& rp = options_.params;
    if (fed_) {
      // Every path was traced (a device that fails throws above): the whole render.
      folded_ = chunks_.size();
      out_.samples = chunks_.empty() ? options_.first_sample : chunks_.back().first + chunks_.back().count;
    }
    out_.interrupted = folded_ < chunks_.size();
    for (const DeviceShare& s : out_.shares) {
      out_.rays += s.rays;
      out_.shadow_rays += s.shadow_rays;
    }
    out_.paths = static_cast<uint64_t>(out_.samples - options_.first_sample) * rp.width * rp.height;
    out_.device = std::to_string(devices_) + " devices";
    return std::move(out_);
  }

  const RenderOptions& options_;
  const std::vector<std::string>& labels_;
  const MakeChunkRenderer& make_;
  const size_t devices_;
  const std::vector<SamplePass> chunks_;
  const size_t floats_;
  const bool keep_, fed_;
  RenderResult out_;
  std::mutex m_;
  std::condition_variable ready_cv_, chunk_cv_, release_cv_;
  size_t ready_ = 0, next_ = 0, folded_ = 0, working_;
  std::vector<std::vector<float>> waiting_;  // chunk sums not yet folded
  std::vector<char> finished_;
  PathFeed feed_;
  std::vector<std::atomic<uint64_t>> fed_rays_;  // a fed device's rays so far, for progress lines
  std::vector<std::vector<float>> kept_;         // sums a device returned to the host
  std::vector<FilmSums> sums_of_;                // every device's sums, at the end
  bool stop_ = false, released_ = false;
  std::exception_ptr error_;
  std::string failed_device_;
  Clock::time_point start_;
  std::vector<std::thread> threads_;
};

}  // namespace

RenderResult render_split(const RenderOptions& options, const std::vector<std::string>& labels,
                          const MakeChunkRenderer& make) {
  return SplitRender(options, labels, make).run();
}

std::vector<SamplePass> weighted_ranges(int32_t first, int32_t count, const std::vector<double>& weights) {
  std::vector<SamplePass> out;
  double total = 0;
  for (double w : weights) total += w;
  // Cumulative rounding: each boundary is the rounded share of the weights before it,
  // so the ranges tile [first, first + count) exactly.
  double before = 0;
  int32_t at = first;
  for (size_t r = 0; r < weights.size(); ++r) {
    before += weights[r];
    const int32_t end =
        r + 1 == weights.size() ? first + count : first + static_cast<int32_t>(std::llround(count * (before / total)));
    out.push_back(SamplePass{at, end - at});
    at = end;
  }
  return out;
}

std::vector<uint32_t> pixel_run(const std::vector<uint32_t>* listed, const SamplePass& cut) {
  std::vector<uint32_t> run(static_cast<size_t>(cut.count));
  for (size_t i = 0; i < run.size(); ++i) {
    const size_t at = static_cast<size_t>(cut.first) + i;
    run[i] = listed ? (*listed)[at] : static_cast<uint32_t>(at);
  }
  return run;
}

// The devices' threads: each makes its renderer, then waits for a round (a new
// `generation`), renders its run of pixels and reports back; the calling thread
// hands the rounds out and waits for every device.
struct PixelSplit::Workers {
  const RenderOptions options;
  const std::vector<std::string> labels;
  std::vector<std::thread> threads;
  std::mutex mutex;
  std::condition_variable wake, done;
  uint64_t generation = 0;
  size_t finished = 0;
  bool stop = false;
  // The round's options and each device's run of pixels and result.
  const RenderOptions* round = nullptr;
  std::vector<std::vector<uint32_t>> runs;
  std::vector<RenderResult> results;
  std::vector<std::exception_ptr> errors;
  std::vector<double> speeds;  // pixel-samples a second, of the round before

  Workers(const RenderOptions& o, const std::vector<std::string>& l, const MakeChunkRenderer& make)
      : options(o), labels(l), runs(l.size()), results(l.size()), errors(l.size()), speeds(l.size(), 1.0) {
    for (size_t d = 0; d < labels.size(); ++d) threads.emplace_back([this, d, &make] { device(d, make); });
    // Every device's renderer made (or failed) before the first round.
    std::unique_lock<std::mutex> lock(mutex);
    done.wait(lock, [&] { return finished == labels.size(); });
    finished = 0;
  }

  ~Workers() {
    {
      std::lock_guard<std::mutex> lock(mutex);
      stop = true;
    }
    wake.notify_all();
    for (std::thread& t : threads) t.join();
  }

  void report() {
    {
      std::lock_guard<std::mutex> lock(mutex);
      ++finished;
    }
    done.notify_all();
  }

  void device(size_t d, const MakeChunkRenderer& make) {
    std::optional<DeviceRenderer> renderer;
    try {
      renderer.emplace(make(d));
    } catch (...) {
      errors[d] = std::current_exception();
    }
    report();
    uint64_t seen = 0;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex);
        wake.wait(lock, [&] { return stop || generation != seen; });
        if (stop) return;
        seen = generation;
      }
      if (renderer && !runs[d].empty()) {
        try {
          RenderOptions o = *round;
          o.active_pixels = &runs[d];
          o.devices.clear();
          results[d] = renderer->render(o);
        } catch (...) {
          errors[d] = std::current_exception();
        }
      }
      report();
    }
  }

  void rethrow_first_error() {
    for (size_t d = 0; d < errors.size(); ++d) {
      if (errors[d]) rethrow_naming(errors[d], labels[d]);
    }
  }
};

PixelSplit::PixelSplit(const RenderOptions& options, const std::vector<std::string>& labels,
                       const MakeChunkRenderer& make)
    : workers_(std::make_unique<Workers>(options, labels, make)) {
  workers_->rethrow_first_error();
}

PixelSplit::~PixelSplit() = default;

RenderResult PixelSplit::render(const RenderOptions& round) {
  Workers& w = *workers_;
  const size_t pixels = static_cast<size_t>(round.params.width) * round.params.height;
  const size_t listed = round.active_pixels ? round.active_pixels->size() : pixels;
  const std::vector<SamplePass> cut = weighted_ranges(0, static_cast<int32_t>(listed), w.speeds);
  for (size_t d = 0; d < cut.size(); ++d) {
    w.runs[d] = pixel_run(round.active_pixels, cut[d]);
    w.results[d] = RenderResult();
  }
  const auto start = Clock::now();
  {
    std::lock_guard<std::mutex> lock(w.mutex);
    w.round = &round;
    ++w.generation;
  }
  w.wake.notify_all();
  {
    std::unique_lock<std::mutex> lock(w.mutex);
    w.done.wait(lock, [&] { return w.finished == w.labels.size(); });
    w.finished = 0;
  }
  w.rethrow_first_error();
  RenderResult out;
  out.rgb.assign(pixels * 3, 0.0f);
  out.radiance = Radiance::SumOfSamples;
  out.samples = round.first_sample + round.sample_count;
  out.shares.resize(w.labels.size());
  const uint64_t samples = static_cast<uint64_t>(round.sample_count);
  for (size_t d = 0; d < w.labels.size(); ++d) {
    const RenderResult& r = w.results[d];
    DeviceShare& share = out.shares[d];
    share.device = w.labels[d];
    if (w.runs[d].empty()) continue;
    require_film(r.rgb.size(), pixels * 3, w.labels[d].c_str());
    // Its pixels' sums, each pixel's whole (no other device rendered it).
    for (uint32_t p : w.runs[d]) {
      for (int c = 0; c < 3; ++c) out.rgb[3 * p + c] = r.rgb[3 * p + c];
    }
    share.name = r.device;
    share.chunks = 1;
    share.paths = r.paths;
    share.seconds = r.seconds;
    share.rays = r.rays;
    share.shadow_rays = r.shadow_rays;
    out.rays += r.rays;
    out.shadow_rays += r.shadow_rays;
    out.paths += r.paths;
    out.upload_seconds = std::max(out.upload_seconds, r.upload_seconds);
    if (r.seconds > 0) w.speeds[d] = static_cast<double>(w.runs[d].size()) * static_cast<double>(samples) / r.seconds;
  }
  out.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  out.device = std::to_string(w.labels.size()) + " devices";
  return out;
}

}  // namespace wt

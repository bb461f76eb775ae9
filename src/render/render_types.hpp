// What the dispatcher (dispatch/renderer.hpp) and the backends (cpu/, cuda/) exchange:
// the options of one render and its result. A leaf header, so that the backends
// stand on it without depending on the dispatcher that calls them.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "wavetrace/scene_view.hpp"

namespace wt {

enum class Backend { Cpu, Cuda };
// Wavefront sorts a bounce's hits by material where they hold enough kinds of
// shading (stages/wavefront.hpp); WavefrontSorted and WavefrontUnsorted always and
// never do.
enum class Kernel { Megakernel, MegakernelConstant, Wavefront, WavefrontSorted, WavefrontUnsorted };

inline bool is_wavefront(Kernel k) {
  return k == Kernel::Wavefront || k == Kernel::WavefrontSorted || k == Kernel::WavefrontUnsorted;
}

// Progress of a render: fraction of paths done, rays so far, seconds since start.
using ProgressFn = std::function<void(double done, uint64_t rays, double seconds)>;

// Reads the film's running sums back (linear RGB per pixel, row 0 = top).
using FilmReader = std::function<std::vector<float>()>;

// Called after each pass of samples with the samples of every pixel the film now
// sums (from sample 0); returning false stops the render there.
using PassFn = std::function<bool(int32_t samples_done, const FilmReader& film)>;

// The paths of one render that several devices' wavefronts share (dispatch/split.hpp):
// each pass's paths [0, total) handed out in blocks, each path once, as the devices
// ask; a device renders the blocks it took and nothing else, so the devices' films
// add up to the whole render however the blocks fell. Thread-safe.
class PathFeed {
 public:
  // `devices` share it: a block is at most a 1/(8 x devices) share of a pass, so
  // that each device gets several even of a small render.
  explicit PathFeed(size_t devices) : devices_(devices == 0 ? 1 : devices) {}

  struct Block {
    uint32_t first = 0, end = 0;  // paths [first, end) of the pass; empty: none left
    bool empty() const { return first == end; }
  };
  // The next block of pass `pass` (of `total` paths), of at most `want` paths; empty
  // once stopped.
  Block take(size_t pass, uint32_t total, uint32_t want) {
    std::lock_guard<std::mutex> lock(m_);
    if (stopped_) return Block{total, total};
    if (next_.size() <= pass) next_.resize(pass + 1, 0);
    const uint64_t share = std::max<uint64_t>(1, total / (8 * devices_));
    const uint64_t first = std::min<uint64_t>(next_[pass], total);
    const uint64_t end = std::min<uint64_t>(total, first + std::min<uint64_t>(std::max<uint32_t>(want, 1), share));
    next_[pass] = end;
    return Block{static_cast<uint32_t>(first), static_cast<uint32_t>(end)};
  }
  // Paths handed out so far, over every pass.
  uint64_t given() {
    std::lock_guard<std::mutex> lock(m_);
    uint64_t n = 0;
    for (uint64_t p : next_) n += p;
    return n;
  }
  // Hands out nothing more (a device failed: the others end after their blocks).
  void stop() {
    std::lock_guard<std::mutex> lock(m_);
    stopped_ = true;
  }

 private:
  const size_t devices_;
  bool stopped_ = false;
  std::mutex m_;
  std::vector<uint64_t> next_;  // per pass, the first path not yet handed out
};

// Within a pass a path is a 32-bit index (pixel + pixels x sample within the pass):
// no pass holds more paths than this, so any number of paths can be rendered.
constexpr uint64_t kMaxPathsPerPass = 0xffffffffull;

// A scene's copies kept on the devices from one render to the next (made by
// dispatch/renderer.hpp's keep_scene; the CUDA backend's own).
struct ResidentScenes;

struct RenderOptions {
  RenderParams params{};
  Backend backend = Backend::Cpu;
  Kernel kernel = Kernel::Megakernel;
  int warmup = 0;         // untimed renders before the timed one, on every backend
  int64_t wave_size = 0;  // wavefront path slots; 0 chooses (queues/wave.hpp)
  int threads = 0;        // CPU threads; 0 uses every core
  // The devices to split the render over (dispatch/split.hpp): CUDA device indices,
  // or on the CPU backend host "devices" (each a share of the threads). None or
  // one: one device (the current CUDA device where none is named).
  std::vector<int> devices;
  ProgressFn progress;    // may be empty

  // The samples of every pixel this render adds: [first_sample, first_sample +
  // sample_count); 0 samples: up to params.spp. The film starts from
  // `initial_film`, the sums of samples [0, first_sample), when it is given (a
  // resumed render), else from zero.
  int32_t first_sample = 0;
  int32_t sample_count = 0;
  const std::vector<float>* initial_film = nullptr;
  // Passes of at most this many samples (0: as few passes as the limits allow),
  // each followed by `after_pass` when it is given.
  int32_t samples_per_pass = 0;
  uint64_t max_paths_per_pass = kMaxPathsPerPass;  // lowered only by tests
  PassFn after_pass;
  // A film on the device to add this render's sums into (render_split keeps each
  // device's sums there across its chunks): neither cleared nor brought back, so the
  // result's rgb is empty. Null: the render's own film. CUDA kernels only; no
  // warm-ups, no initial film and no after_pass with it.
  float* device_film = nullptr;
  // Paths shared with other devices (wavefront kernels): this render traces only the
  // blocks it takes from the feed, of each pass of its samples, and its result's
  // paths counts them. Not with warm-ups (which render without it) or after_pass.
  PathFeed* path_feed = nullptr;
  // The wavefront shades each sorted bounce one launch per material kind, timed as
  // a stage each ("shade <kind>", added to the result's stages after the others;
  // --profile). The image is the same; the shade stage's own time is then theirs.
  bool shade_by_kind = false;
  // The CUDA megakernels' samples a thread-per-sample launch takes at once
  // (megakernel_batch): 0 chooses by the image's size and the device's; 1 is one
  // thread a pixel; tests set others. The image is the same bit for bit.
  int32_t megakernel_batch = 0;
  // Only these pixels (ascending indices; adaptive sampling's pixels still going,
  // render/adaptive.hpp): the render traces samples [first_sample, first_sample +
  // sample_count) of each and adds them to the film at their pixels, the others'
  // sums left as they are. Null: every pixel. One device, no path feed.
  const std::vector<uint32_t>* active_pixels = nullptr;
  // Adaptive sampling (render/adaptive.hpp; render() only): above 0, each pixel stops
  // once its neighbourhood's relative error is at most this, after at least
  // `min_spp` samples (0: 16, or spp where less) and at most params.spp. Below 0:
  // the same rounds with no pixel stopping (for the variance they estimate). 0: off.
  double noise_threshold = 0;
  int32_t min_spp = 0;
  // The scene's copies kept on the devices (a session's, app/session.hpp): a render
  // uploads the scene only to a device that holds no free copy of it, and leaves its
  // copy there for the next. Null: each render uploads its own and frees it. The
  // image is the same either way.
  std::shared_ptr<ResidentScenes> resident;
};

// The pixels a render's samples visit: those listed, or every one.
inline uint64_t rendered_pixels(const RenderOptions& o) {
  return o.active_pixels ? o.active_pixels->size() : static_cast<uint64_t>(o.params.width) * o.params.height;
}

// What one device did in a render split over several (dispatch/split.hpp).
struct DeviceShare {
  std::string device;  // "cuda:1", "cpu:0"
  std::string name;    // what the backend calls it ("NVIDIA H200", "CPU (8 threads)")
  int32_t samples = 0;  // samples per pixel it rendered (0 where it took paths from a feed)
  int32_t chunks = 0;   // chunks of samples, or blocks of paths, it took
  uint64_t paths = 0;   // the paths it traced
  double seconds = 0;   // its renders' own time
  uint64_t rays = 0, shadow_rays = 0;
};

struct StageTime {
  std::string name;
  double ms = 0;
  bool part = false;  // a share of the stage before it (shade's per material kind), not a stage of its own
};

// What `RenderResult::rgb` holds: a backend adds every sample into its pixel;
// render() divides by the samples per pixel once, for every backend.
enum class Radiance { SumOfSamples, MeanOfSamples };

struct RenderResult {
  std::vector<float> rgb;  // linear RGB per pixel, row 0 = top; what it holds: `radiance`
  Radiance radiance = Radiance::SumOfSamples;
  int32_t samples = 0;       // samples per pixel the film sums (from sample 0)
  bool interrupted = false;  // after_pass stopped the render before its last sample
  uint64_t rays = 0;   // every ray this render intersected, counted once
  uint64_t shadow_rays = 0;  // the shadow rays of light sampling, apart from `rays`
  uint64_t paths = 0;  // pixels x samples this render traced
  double seconds = 0;  // the render alone: CUDA events on the GPU, wall clock on the CPU
  double upload_seconds = 0;
  std::string device;
  std::vector<StageTime> stages;          // wavefront: each stage's time, summed over bounces
  std::vector<uint64_t> live_per_bounce;  // wavefront: paths alive entering each bounce
  // wavefront: the bounces (wave steps) with hits, and those whose hits were sorted
  uint64_t bounces_shaded = 0, bounces_sorted = 0;
  uint64_t blocks = 0;  // wavefront with a path feed: the blocks of paths it took
  std::vector<DeviceShare> shares;  // a render split over several devices: each one's part
  // An adaptive render (render/adaptive.hpp): each pixel's samples, the variance of
  // each pixel's mean (3 floats a pixel), and the pixels that converged; `samples` is
  // then the most any pixel took.
  std::vector<int32_t> pixel_samples;
  std::vector<float> variance;
  uint64_t converged = 0;
};

}  // namespace wt

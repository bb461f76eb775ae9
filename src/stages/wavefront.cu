// The wavefront loop. Per bounce: generate -> intersect -> compact -> sort -> shade.
// The host reads the counters back once per bounce (after compact), which tells it
// how many entries to sort and shade and when every path is done.
#include "stages/wavefront.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "cuda/event.hpp"
#include "stages/stages.hpp"

namespace wt::cuda {

namespace {

constexpr const char* kStage = "wavefront";
// Measured on an H100 (seed57, 1920x1080, 300 spp): 1, 2, 4, 8 and 16 Mi slots took
// 0.232, 0.173, 0.156, 0.144 and 0.141 s (bench/RESULTS.md). Bigger waves mean fewer bounces, so fewer
// launches and host round trips; 16 Mi slots take about 1.8 GB.
constexpr int64_t kDefaultMaxWave = int64_t(1) << 24;

// "readback" is the gap while the host reads the counters: the one sync per bounce.
enum StageIndex { kGenerate, kIntersect, kCompact, kReadback, kSort, kShade, kStageCount };
constexpr std::array<const char*, kStageCount> kStageNames = {"generate", "intersect", "compact",
                                                              "readback", "sort",      "shade"};

// Events between the stages of one bounce: marks[s] .. marks[s + 1] is stage s.
struct BounceMarks {
  std::array<Event, kStageCount + 1> marks;
  void add_to(std::array<double, kStageCount>& ms, int first, int last) const {
    for (int s = first; s < last; ++s) ms[s] += marks[s + 1].ms_since(marks[s], kStage);
  }
};

}  // namespace

size_t wavefront_bytes(int64_t wave_size) { return WaveMemory::bytes_for(static_cast<size_t>(wave_size)); }

int64_t choose_wave_size(int64_t requested, const RenderParams& rp, size_t free_memory) {
  const int64_t total = static_cast<int64_t>(rp.width) * rp.height * rp.spp;
  if (requested > 0) {
    if (requested > static_cast<int64_t>(kMaxWaveSize)) {
      throw SceneError("wave-size: at most " + std::to_string(kMaxWaveSize) + " path slots (got " +
                       std::to_string(requested) + ")");
    }
    return std::min(requested, total);
  }
  // A quarter of free memory at most: the film, the scene and the runtime need the rest.
  const int64_t per_slot = static_cast<int64_t>(wavefront_bytes(1 << 20) >> 20) + 1;
  const int64_t by_memory = static_cast<int64_t>(free_memory / 4) / per_slot;
  return std::max<int64_t>(std::min({total, kDefaultMaxWave, by_memory}), std::min<int64_t>(total, kMinWaveSlots));
}

RenderResult render_wavefront(const SceneView& scene, int key_bits, const RenderOptions& options, int64_t wave_size) {
  const RenderParams& rp = options.params;
  const bool sorted = options.kernel == Kernel::Wavefront;
  const uint32_t total = static_cast<uint32_t>(static_cast<uint64_t>(rp.width) * rp.height * rp.spp);
  WaveMemory wave(static_cast<size_t>(wave_size));
  DeviceBuffer<float> film(static_cast<size_t>(rp.width) * rp.height * 3, kStage);
  WaveCounters* host_counters = nullptr;
  WT_CUDA(cudaMallocHost(&host_counters, sizeof(WaveCounters)), kStage);
  struct PinnedFree {
    WaveCounters* p;
    ~PinnedFree() { cudaFreeHost(p); }
  } pinned_free{host_counters};

  RenderResult out;
  auto run = [&](bool report) {
    film.zero(kStage);
    WT_CUDA(cudaMemsetAsync(wave.counters(), 0, sizeof(WaveCounters)), kStage);
    std::array<double, kStageCount> stage_ms{};
    std::vector<uint64_t> live_per_bounce;
    std::array<BounceMarks, 2> marks;  // this bounce's, and the last one's (sort and shade still to read)
    EventTimer timer(kStage);
    timer.start();
    int cur = 0;
    bool last_pending = false;
    for (int iteration = 0;; ++iteration) {
      BounceMarks& m = marks[iteration & 1];
      m.marks[kGenerate].record(kStage);
      launch_generate(scene, rp, wave, cur, total, nullptr);
      m.marks[kIntersect].record(kStage);
      launch_intersect(scene, rp, wave, cur, total, film.get(), nullptr);
      m.marks[kCompact].record(kStage);
      compact_entries(wave, nullptr);
      m.marks[kReadback].record(kStage);
      WT_CUDA(cudaMemcpyAsync(host_counters, wave.counters(), sizeof(WaveCounters), cudaMemcpyDeviceToHost), kStage);
      WT_CUDA(cudaStreamSynchronize(nullptr), kStage);
      const WaveCounters c = *host_counters;
      live_per_bounce.push_back(c.queued[cur]);

      m.marks[kSort].record(kStage);
      const uint32_t* list = wave.selected();
      if (sorted && c.hits > 0) {
        sort_entries(wave, c.hits, key_bits, nullptr);
        list = wave.sorted();
      }
      m.marks[kShade].record(kStage);
      launch_shade(scene, rp, wave, cur, list, c.hits, film.get(), nullptr);
      m.marks[kStageCount].record(kStage);

      // While the GPU sorts and shades, collect the times that are complete.
      m.add_to(stage_ms, kGenerate, kReadback);
      if (last_pending) marks[(iteration + 1) & 1].add_to(stage_ms, kReadback, kStageCount);
      last_pending = true;
      if (report) {
        options.progress(static_cast<double>(c.next_path - c.queued[cur]) / total, c.rays, timer.elapsed_host());
      }
      if (c.hits == 0 && c.next_path >= total) break;
      cur = 1 - cur;
    }
    out.seconds = timer.stop();
    // The final bounce's readback, sort and shade, now complete.
    int last = static_cast<int>(live_per_bounce.size() - 1);
    marks[last & 1].add_to(stage_ms, kReadback, kStageCount);
    out.stages.clear();
    for (int s = 0; s < kStageCount; ++s) out.stages.push_back(StageTime{kStageNames[s], stage_ms[s]});
    out.live_per_bounce = std::move(live_per_bounce);
  };
  for (int i = 0; i < options.warmup; ++i) run(false);
  run(static_cast<bool>(options.progress));

  WaveCounters final_counters{};
  WT_CUDA(cudaMemcpy(&final_counters, wave.counters(), sizeof(WaveCounters), cudaMemcpyDeviceToHost), kStage);
  out.rays = final_counters.rays;
  out.rgb = film.download(kStage);
  return out;
}

}  // namespace wt::cuda

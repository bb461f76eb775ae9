#include "cpu/cpu_wavefront.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <vector>

#include "cpu/cpu_stages.hpp"
#include "cpu/parallel.hpp"
#include "stages/stage_items.hpp"

namespace wt::cpu {

namespace {

// Host arrays behind one PathQueue.
struct HostQueue {
  explicit HostQueue(size_t capacity) : memory(capacity * PathQueue::kBytesPerSlot / sizeof(float)) {
    view = PathQueue::over(memory.data(), capacity);
  }
  std::vector<float> memory;
  PathQueue view;
};

constexpr int64_t kChunk = 1024;
constexpr int64_t kDefaultWave = int64_t(1) << 18;

}  // namespace

RenderResult render_wavefront(const SceneView& scene, const RenderOptions& options) {
  const RenderParams& rp = options.params;
  const bool sorted = options.kernel == Kernel::Wavefront;
  const uint32_t total = static_cast<uint32_t>(static_cast<uint64_t>(rp.width) * rp.height * rp.spp);
  const uint32_t capacity = static_cast<uint32_t>(
      std::min<int64_t>(total, options.wave_size > 0 ? std::min<int64_t>(options.wave_size, kMaxWaveSize) : kDefaultWave));
  const int threads = thread_count(options.threads);

  HostQueue queues[2] = {HostQueue(capacity), HostQueue(capacity)};
  std::vector<float> hit_t(capacity);
  std::vector<int32_t> hit_sphere(capacity);
  const HitQueue hits{hit_t.data(), hit_sphere.data()};
  std::vector<uint32_t> entries(capacity), selected;
  selected.reserve(capacity);
  RenderResult out;
  out.rgb.assign(static_cast<size_t>(rp.width) * rp.height * 3, 0.0f);
  float* film = out.rgb.data();

  auto t0 = std::chrono::steady_clock::now();
  uint32_t queued = 0, next_path = 0;
  int cur = 0;
  for (;;) {
    const uint32_t live = live_paths(queued, next_path, total, capacity);
    const PathQueue& q = queues[cur].view;
    parallel_for(live - queued, kChunk, threads, [&](int64_t b, int64_t e, int) {
      for (int64_t i = b; i < e; ++i) generate_one(queued + static_cast<uint32_t>(i), queued, next_path, scene, rp, q);
    });
    next_path += live - queued;
    out.rays += live;
    out.live_per_bounce.push_back(live);
    parallel_for(live, kChunk, threads, [&](int64_t b, int64_t e, int) {
      for (int64_t i = b; i < e; ++i) entries[i] = intersect_one(static_cast<uint32_t>(i), scene, rp, q, hits, film);
    });
    compact_entries(entries.data(), live, selected);
    if (sorted) sort_entries(selected);

    std::atomic<uint32_t> pushed{0};
    const PathQueue& next_queue = queues[1 - cur].view;
    parallel_for(static_cast<int64_t>(selected.size()), kChunk, threads, [&](int64_t b, int64_t e, int) {
      for (int64_t i = b; i < e; ++i) {
        PathState next;
        if (shade_one(entry_slot(selected[i]), scene, rp, q, hits, film, next)) {
          next_queue.store(pushed.fetch_add(1, std::memory_order_relaxed), next);
        }
      }
    });
    queued = pushed.load();
    cur = 1 - cur;
    if (options.progress) {
      options.progress(static_cast<double>(next_path - queued) / total, out.rays,
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    if (queued == 0 && next_path >= total) break;
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace wt::cpu

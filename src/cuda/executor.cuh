// The GPU's executor for the wavefront (stages/wavefront.hpp): a stage is one
// launch of a generic kernel around the stage's per-item function, with the block
// size the occupancy API picks for it; compact and sort are CUB's. Every launch is
// checked and named after its stage, and timed with a pair of CUDA events whose
// times are collected at the host's next wait. Include from .cu files only.
#pragma once

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_select.cuh>
#include <algorithm>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <type_traits>
#include <vector>

#include "cuda/buffer.hpp"
#include "cuda/event.hpp"
#include "device/kernel_bodies.hpp"
#include "stages/compact.hpp"
#include "stages/sort.hpp"
#include "stages/stage.hpp"

namespace wt::cuda {

// An item may bound its kernel's registers with `static constexpr int
// kMinBlocksPerSm`: the kernel is then compiled for blocks of at most kBoundedBlock
// threads of which that many fit on an SM at once, so the compiler keeps each
// thread within 65536 / (kBoundedBlock * kMinBlocksPerSm) registers. Worth it where
// a kernel waits on memory more than it computes (intersect; bench/RESULTS.md).
constexpr int kBoundedBlock = 256;
template <class Item, class = void>
struct MinBlocksPerSm {
  static constexpr int value = 0;  // unbounded
};
template <class Item>
struct MinBlocksPerSm<Item, std::void_t<decltype(Item::kMinBlocksPerSm)>> {
  static constexpr int value = Item::kMinBlocksPerSm;
};

template <class Item>
__global__ void for_each_kernel(Item item, uint32_t n) {
#if WT_KERNEL_BODIES
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) item(i);
#endif
}

template <class Item>
__global__ void __launch_bounds__(kBoundedBlock, MinBlocksPerSm<Item>::value)
    for_each_bounded_kernel(Item item, uint32_t n) {
#if WT_KERNEL_BODIES
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) item(i);
#endif
}

// The kernel that runs Item over a range.
template <class Item>
constexpr auto stage_kernel() {
  if constexpr (MinBlocksPerSm<Item>::value > 0) {
    return for_each_bounded_kernel<Item>;
  } else {
    return for_each_kernel<Item>;
  }
}

// The block size for stage_kernel<Item>(), asked of the occupancy API once per
// item type: the smallest block that reaches the highest occupancy the kernel can
// have, in steps of four warps, one for each of an SM's four schedulers. Smaller
// blocks at the same occupancy leave less of the device idle while the last blocks
// of a launch finish; blocks of fewer than four warps leave schedulers without
// work. Measured on the H100 against the occupancy API's own pick (the largest
// block at the highest occupancy) and against one warp steps: bench/RESULTS.md.
template <class Item>
int block_size_for(const Stage& s) {
  static const int block = [&] {
    cudaFuncAttributes attributes{};
    WT_CUDA(cudaFuncGetAttributes(&attributes, stage_kernel<Item>()), s.name);
    int device = 0, warp = 0;
    WT_CUDA(cudaGetDevice(&device), s.name);
    WT_CUDA(cudaDeviceGetAttribute(&warp, cudaDevAttrWarpSize, device), s.name);
    const int step = 4 * warp;
    int best = step, best_threads = 0;
    for (int size = step; size <= attributes.maxThreadsPerBlock; size += step) {
      int blocks = 0;
      WT_CUDA(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&blocks, stage_kernel<Item>(), size, 0), s.name);
      if (blocks * size > best_threads) {
        best_threads = blocks * size;
        best = size;
      }
    }
    return best;
  }();
  return block;
}

class Executor {
 public:
  explicit Executor(cudaStream_t stream = nullptr) : stream_(stream), timer_("wavefront") {
    WT_CUDA(cudaMallocHost(&pinned_, kPinnedBytes), "pinned host memory for the wave's counters");
  }
  ~Executor() { cudaFreeHost(pinned_); }
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  DeviceBuffer<unsigned char> alloc(size_t bytes, const char* stage) { return DeviceBuffer<unsigned char>(bytes, stage); }
  unsigned char* wave_memory(size_t bytes) {
    if (wave_.size() < bytes) wave_.allocate(bytes, "wave allocation");  // frees the old block first
    return wave_.get();
  }
  // The bytes of the block wave_memory keeps, which serve (or, freed first, make room
  // for) the next wave.
  size_t wave_bytes() const { return wave_.size(); }

  // The most temporary storage compact (over `capacity` entries) and sort need on the
  // current device: CUB's answer, asked once for each device and capacity (a render
  // asks for its wave's, and for the sizing's, at every call).
  static size_t temp_bytes(size_t capacity) {
    int device = 0;
    WT_CUDA(cudaGetDevice(&device), "compact");
    static std::mutex mutex;
    static std::map<std::pair<int, size_t>, size_t> known;
    const std::pair<int, size_t> key(device, capacity);
    {
      std::lock_guard<std::mutex> lock(mutex);
      const auto it = known.find(key);
      if (it != known.end()) return it->second;
    }
    size_t select = 0, sort = 0;
    const int64_t n = static_cast<int64_t>(capacity);
    WT_CUDA(cub::DeviceSelect::If(nullptr, select, static_cast<const uint32_t*>(nullptr),
                                  static_cast<uint32_t*>(nullptr), static_cast<uint32_t*>(nullptr), n,
                                  HitSomething{}),
            "compact");
    cub::DoubleBuffer<uint32_t> keys(nullptr, nullptr);
    WT_CUDA(cub::DeviceRadixSort::SortKeys(nullptr, sort, keys, n, 0, 32), "sort");
    std::lock_guard<std::mutex> lock(mutex);
    return known.emplace(key, std::max(select, sort)).first->second;
  }

  template <class Item>
  void launch(const Stage& s, uint32_t n, const Item& item) {
    if (n == 0) return;
    const int block = block_size_for<Item>(s);
    timed(s, [&] {
      stage_kernel<Item>()<<<(n + block - 1) / block, block, 0, stream_>>>(item, n);
      check(static_cast<int>(cudaGetLastError()), "kernel launch", s.name);
    });
  }

  template <class Pred>
  void select(const Stage& s, const uint32_t* in, uint32_t* out, uint32_t* count, uint32_t n, Pred pred, void* temp,
              size_t temp_bytes) {
    timed(s, [&] {
      size_t bytes = temp_bytes;
      WT_CUDA(cub::DeviceSelect::If(temp, bytes, in, out, count, static_cast<int64_t>(n), pred, stream_), s.name);
    });
  }

  // The sorted entries end in `keys` or `alternate`, whichever CUB's double buffer says.
  const uint32_t* sort(const Stage& s, uint32_t* keys, uint32_t* alternate, uint32_t n, SortBits bits, void* temp,
                       size_t temp_bytes) {
    cub::DoubleBuffer<uint32_t> buffers(keys, alternate);
    timed(s, [&] {
      size_t bytes = temp_bytes;
      WT_CUDA(cub::DeviceRadixSort::SortKeys(temp, bytes, buffers, static_cast<int64_t>(n), bits.begin, bits.end,
                                             stream_),
              s.name);
    });
    return buffers.Current();
  }

  // Copies *p to the host and waits for it: the one wait per bounce. The stage's
  // time runs until the host is back, and the waiting lets every earlier stage's
  // events be read.
  template <class T>
  T read(const Stage& s, const T* p) {
    static_assert(sizeof(T) <= kPinnedBytes, "read() reads small values");
    Event& begin = next_event();
    begin.record(s.name, stream_);
    WT_CUDA(cudaMemcpyAsync(pinned_, p, sizeof(T), cudaMemcpyDeviceToHost, stream_), s.name);
    WT_CUDA(cudaStreamSynchronize(stream_), s.name);
    collect();
    Event& end = next_event();
    end.record(s.name, stream_);
    pending_.push_back(Pending{s.index, &begin, &end});
    T value;
    std::memcpy(&value, pinned_, sizeof(T));
    return value;
  }

  void zero(void* p, size_t bytes) { WT_CUDA(cudaMemsetAsync(p, 0, bytes, stream_), "wavefront"); }

  template <class T>
  void upload(T* p, const std::vector<T>& v) {
    WT_CUDA(cudaMemcpyAsync(p, v.data(), v.size() * sizeof(T), cudaMemcpyHostToDevice, stream_), "wavefront");
  }

  std::vector<float> download(const float* p, size_t n) {
    std::vector<float> host(n);
    WT_CUDA(cudaMemcpyAsync(host.data(), p, n * sizeof(float), cudaMemcpyDeviceToHost, stream_), "wavefront");
    WT_CUDA(cudaStreamSynchronize(stream_), "wavefront");
    return host;
  }

  void start_timer() { timer_.start(stream_); }
  double stop_timer() {
    const double seconds = timer_.stop(stream_);
    collect();
    return seconds;
  }
  double elapsed_host() const { return timer_.elapsed_host(); }

  // Each stage's milliseconds since the last call, by stage index. Call after stop_timer().
  std::vector<double> take_stage_ms(size_t stages) { return times_.take(stages); }

 private:
  static constexpr size_t kPinnedBytes = 256;

  struct Pending {
    int stage;
    Event* begin;
    Event* end;
  };

  template <class F>
  void timed(const Stage& s, F&& f) {
    Event& begin = next_event();
    begin.record(s.name, stream_);
    f();
    Event& end = next_event();
    end.record(s.name, stream_);
    pending_.push_back(Pending{s.index, &begin, &end});
  }

  Event& next_event() {
    if (free_.empty()) {
      events_.push_back(std::make_unique<Event>());
      return *events_.back();
    }
    Event* e = free_.back();
    free_.pop_back();
    return *e;
  }

  // Adds the times of every pending stage (all complete: the stream was waited on).
  void collect() {
    for (const Pending& p : pending_) {
      times_.add(p.stage, p.end->ms_since(*p.begin, "wavefront timing"));
      free_.push_back(p.begin);
      free_.push_back(p.end);
    }
    pending_.clear();
  }

  cudaStream_t stream_;
  EventTimer timer_;
  void* pinned_ = nullptr;
  DeviceBuffer<unsigned char> wave_;
  std::vector<std::unique_ptr<Event>> events_;
  std::vector<Event*> free_;
  std::vector<Pending> pending_;
  StageTimes times_;
};

}  // namespace wt::cuda

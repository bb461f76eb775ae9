// The CPU's executor for the wavefront (stages/wavefront.hpp): stages run as
// parallel loops on host threads, compact and sort with the standard library, and
// every stage is timed by the wall clock under its name.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <vector>

#include "cpu/parallel.hpp"
#include "queues/soa.hpp"
#include "stages/sort.hpp"
#include "stages/stage.hpp"

namespace wt::cpu {

// An aligned block of host memory.
class HostMemory {
 public:
  explicit HostMemory(size_t bytes) {
    const size_t rounded = std::max<size_t>((bytes + Arena::kAlign - 1) / Arena::kAlign * Arena::kAlign, Arena::kAlign);
    p_.reset(static_cast<unsigned char*>(std::aligned_alloc(Arena::kAlign, rounded)));
    if (!p_) throw std::bad_alloc();
  }
  unsigned char* get() const { return p_.get(); }

 private:
  struct Free {
    void operator()(unsigned char* p) const { std::free(p); }
  };
  std::unique_ptr<unsigned char, Free> p_;
};

class Executor {
 public:
  using Clock = std::chrono::steady_clock;

  explicit Executor(int threads) : threads_(thread_count(threads)) {}

  int threads() const { return threads_; }

  HostMemory alloc(size_t bytes, const char*) { return HostMemory(bytes); }
  unsigned char* wave_memory(size_t bytes) {
    if (!wave_ || wave_bytes_ < bytes) {
      wave_.reset();  // the old block first: never both at once
      wave_ = std::make_unique<HostMemory>(bytes);
      wave_bytes_ = bytes;
    }
    return wave_->get();
  }
  static size_t temp_bytes(size_t) { return 0; }

  template <class Item>
  void launch(const Stage& s, uint32_t n, const Item& item) {
    timed(s, [&] {
      parallel_for(n, kChunk, threads_, [&](int64_t begin, int64_t end, int) {
        for (int64_t i = begin; i < end; ++i) item(static_cast<uint32_t>(i));
      });
    });
  }

  template <class Pred>
  void select(const Stage& s, const uint32_t* in, uint32_t* out, uint32_t* count, uint32_t n, Pred pred, void*, size_t) {
    timed(s, [&] { *count = static_cast<uint32_t>(std::copy_if(in, in + n, out, pred) - out); });
  }

  // Stable by the key bits alone, as CUB's radix sort: the result is in `keys`.
  const uint32_t* sort(const Stage& s, uint32_t* keys, uint32_t*, uint32_t n, SortBits bits, void*, size_t) {
    timed(s, [&] {
      const uint32_t mask = bits.end - bits.begin >= 32 ? ~0u : (1u << (bits.end - bits.begin)) - 1u;
      std::stable_sort(keys, keys + n, [&](uint32_t a, uint32_t b) {
        return ((a >> bits.begin) & mask) < ((b >> bits.begin) & mask);
      });
    });
    return keys;
  }

  template <class T>
  T read(const Stage& s, const T* p) {
    T value;
    timed(s, [&] { value = *p; });
    return value;
  }

  void zero(void* p, size_t bytes) { std::memset(p, 0, bytes); }
  template <class T>
  void upload(T* p, const std::vector<T>& v) {
    std::copy(v.begin(), v.end(), p);
  }
  std::vector<float> download(const float* p, size_t n) { return std::vector<float>(p, p + n); }

  void start_timer() { start_ = Clock::now(); }
  double stop_timer() { return elapsed_host(); }
  double elapsed_host() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

  // Each stage's milliseconds since the last call, by stage index.
  std::vector<double> take_stage_ms(size_t stages) { return times_.take(stages); }

 private:
  static constexpr int64_t kChunk = 1024;

  template <class F>
  void timed(const Stage& s, F&& f) {
    const auto t0 = Clock::now();
    f();
    times_.add(s.index, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }

  int threads_;
  Clock::time_point start_ = Clock::now();
  StageTimes times_;
  std::unique_ptr<HostMemory> wave_;
  size_t wave_bytes_ = 0;
};

}  // namespace wt::cpu

// Runs fn(begin, end) over [0, n) in chunks on a set of host threads, chunks
// handed out dynamically so that uneven work (long paths) balances.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace wt::cpu {

inline int thread_count(int requested) {
  if (requested > 0) return requested;
  return std::max(1u, std::thread::hardware_concurrency());
}

// An exception on any thread (std::bad_alloc, say) stops the loop's remaining
// chunks and is rethrown on the calling thread once every thread has stopped.
template <class Fn>
void parallel_for(int64_t n, int64_t chunk, int threads, Fn&& fn) {
  std::atomic<int64_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_lock;
  auto worker = [&](int tid) {
    try {
      for (;;) {
        int64_t begin = next.fetch_add(chunk);
        if (begin >= n) return;
        fn(begin, std::min(n, begin + chunk), tid);
      }
    } catch (...) {
      next.store(n);
      std::lock_guard<std::mutex> hold(failure_lock);
      if (!failure) failure = std::current_exception();
    }
  };
  int t = static_cast<int>(std::min<int64_t>(threads, (n + chunk - 1) / chunk));
  std::vector<std::thread> pool;
  if (t > 1) {
    pool.reserve(t - 1);
    for (int i = 1; i < t; ++i) pool.emplace_back(worker, i);
  }
  worker(0);
  for (auto& th : pool) th.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace wt::cpu

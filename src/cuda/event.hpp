// CUDA events (GPU-side timing, and points the host can wait on) and streams.
#pragma once

#include <cuda_runtime.h>

#include <chrono>

#include "device/device.hpp"

namespace wt::cuda {

class Event {
 public:
  Event() { WT_CUDA(cudaEventCreate(&event_), "event"); }
  ~Event() { cudaEventDestroy(event_); }
  Event(const Event&) = delete;
  Event& operator=(const Event&) = delete;
  Event(Event&& o) noexcept : event_(o.event_) { o.event_ = nullptr; }

  void record(const char* stage, cudaStream_t stream = nullptr) { WT_CUDA(cudaEventRecord(event_, stream), stage); }
  void synchronize(const char* stage) { WT_CUDA(cudaEventSynchronize(event_), stage); }
  // Milliseconds from `earlier` to this event; both must have completed.
  float ms_since(const Event& earlier, const char* stage) const {
    float ms = 0;
    WT_CUDA(cudaEventElapsedTime(&ms, earlier.event_, event_), stage);
    return ms;
  }
  cudaEvent_t get() const { return event_; }

 private:
  cudaEvent_t event_ = nullptr;
};

// A stream of the current device that runs beside the default stream (non-blocking:
// work on the default stream neither waits for it nor is waited for by it; events
// order the two), at the device's highest priority, so that its blocks go ahead of
// work queued before them on the default stream.
class Stream {
 public:
  explicit Stream(const char* stage) {
    int least = 0, greatest = 0;
    WT_CUDA(cudaDeviceGetStreamPriorityRange(&least, &greatest), stage);
    WT_CUDA(cudaStreamCreateWithPriority(&stream_, cudaStreamNonBlocking, greatest), stage);
  }
  ~Stream() { cudaStreamDestroy(stream_); }  // as Event's: errors surface at the next call
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;

  void wait_for(const Event& event, const char* stage) { WT_CUDA(cudaStreamWaitEvent(stream_, event.get(), 0), stage); }
  void synchronize(const char* stage) { WT_CUDA(cudaStreamSynchronize(stream_), stage); }
  cudaStream_t get() const { return stream_; }

 private:
  cudaStream_t stream_ = nullptr;
};

// Times a region of GPU work with events; also tracks host time for progress lines.
class EventTimer {
 public:
  explicit EventTimer(const char* stage) : stage_(stage) {}
  void start(cudaStream_t stream = nullptr) {
    host_start_ = std::chrono::steady_clock::now();
    begin_.record(stage_, stream);
  }
  // Seconds of GPU time from start() to now, after waiting for the work.
  double stop(cudaStream_t stream = nullptr) {
    end_.record(stage_, stream);
    end_.synchronize(stage_);
    return end_.ms_since(begin_, stage_) / 1000.0;
  }
  double elapsed_host() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - host_start_).count();
  }

 private:
  const char* stage_;
  Event begin_, end_;
  std::chrono::steady_clock::time_point host_start_;
};

}  // namespace wt::cuda

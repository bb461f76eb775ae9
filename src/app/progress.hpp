// The progress line on stderr: shown once a render has run for a second, redrawn
// a few times a second, with paths done, rays per second and the time left; of an
// adaptive render, the pixels converged too.
#pragma once

#include <cstdint>
#include <functional>

#include "dispatch/renderer.hpp"

namespace wt::app {

class ProgressLine {
 public:
  explicit ProgressLine(uint64_t total_paths) : total_paths_(total_paths) {}
  ~ProgressLine();
  ProgressFn callback();
  // An adaptive render's pixels converged so far, of `pixels`: on the line from now on.
  void converged(uint64_t converged, uint64_t pixels);
  // That, as the callback an adaptive render calls with its count (AdaptiveHooks).
  std::function<void(uint64_t)> converged_callback(uint64_t pixels) {
    return [this, pixels](uint64_t c) { converged(c, pixels); };
  }

 private:
  void update(double done, uint64_t rays, double seconds);
  uint64_t total_paths_;
  uint64_t converged_ = 0, pixels_ = 0;
  double last_draw_ = -1.0;
  bool drawn_ = false;
};

}  // namespace wt::app

// The progress line on stderr: shown once a render has run for a second, redrawn
// a few times a second, with paths done, rays per second and the time left.
#pragma once

#include <cstdint>

#include "dispatch/renderer.hpp"

namespace wt::app {

class ProgressLine {
 public:
  explicit ProgressLine(uint64_t total_paths) : total_paths_(total_paths) {}
  ~ProgressLine();
  ProgressFn callback();

 private:
  void update(double done, uint64_t rays, double seconds);
  uint64_t total_paths_;
  double last_draw_ = -1.0;
  bool drawn_ = false;
};

}  // namespace wt::app

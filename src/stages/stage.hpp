// A named stage of the wavefront: executors time every launch under its stage's
// name and index, and name the stage in errors.
#pragma once

#include <cstddef>
#include <vector>

namespace wt {

struct Stage {
  int index;
  const char* name;
};

// Each stage's milliseconds, summed by stage index until taken.
class StageTimes {
 public:
  void add(int stage, double ms) {
    if (ms_.size() <= static_cast<size_t>(stage)) ms_.resize(stage + 1, 0.0);
    ms_[stage] += ms;
  }

  // The sums of stages 0 .. stages - 1 (0 for a stage that never ran); starts afresh.
  std::vector<double> take(size_t stages) {
    std::vector<double> out(stages, 0.0);
    for (size_t i = 0; i < stages && i < ms_.size(); ++i) out[i] = ms_[i];
    ms_.clear();
    return out;
  }

 private:
  std::vector<double> ms_;
};

}  // namespace wt

// `wavetrace bench`: a grid of scenes x configurations x kernels on one device.
// Each kernel's image is checked against the megakernel's (same seed) before it is
// timed; a kernel that renders a different image is a failure, not a result.
#pragma once

#include <string>
#include <vector>

#include "dispatch/renderer.hpp"

namespace wt::app {

// The most timed runs per point (the spec's `repeats`, --repeats).
constexpr int kMaxRepeats = 100;

struct BenchOptions {
  std::string spec;        // the grid (JSON), see bench/README.md
  std::string out_dir;     // results.json and results.csv go here
  std::string backend = "auto";
  std::string only;        // run one group of the spec
  int repeats = 0;         // 0: the spec's
  std::string commit;      // recorded as given
};

// One point of the grid: a scene at one configuration, and the kernels to time there.
struct BenchPoint {
  std::string group, scene;
  RenderParams params{};
  std::vector<std::string> kernels;
  // Adaptive sampling (render/adaptive.hpp): a threshold above 0 times the kernels'
  // adaptive renders (params.spp the most a pixel takes); min_spp 0 chooses.
  double noise_threshold = 0;
  int32_t min_spp = 0;
};

struct BenchSpec {
  int warmup = 1, repeats = 3, check_spp = 2;
  double check_bound = 3e-3;
  std::vector<BenchPoint> points;  // of the group `only` names, or of every group
};

// Reads a spec as scene files are read: unknown and repeated keys are errors, and
// every error is one line naming the file and the JSON path. Throws InputError.
BenchSpec read_bench_spec(const std::string& path, const std::string& only);

// Returns the exit code: 0 when every point ran and passed its image check.
int run_bench(const BenchOptions& options);

}  // namespace wt::app

// `wavetrace bench`: a grid of scenes x configurations x kernels on one device.
// Each kernel's image is checked against the megakernel's (same seed) before it is
// timed; a kernel that renders a different image is a failure, not a result.
#pragma once

#include <string>

namespace wt::app {

struct BenchOptions {
  std::string spec;        // the grid (JSON), see bench/README.md
  std::string out_dir;     // results.json and results.csv go here
  std::string backend = "auto";
  std::string only;        // run one group of the spec
  int repeats = 0;         // 0: the spec's
  std::string commit;      // recorded as given
};

// Returns the exit code: 0 when every point ran and passed its image check.
int run_bench(const BenchOptions& options);

}  // namespace wt::app

// Helpers shared by the tests: where the repository is, and whether a GPU is.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace wt::test {

// The repository root, found from WAVETRACE_ROOT or by walking up from the working
// directory to the folder that holds scenes/; test data is read relative to it, so
// the test binary runs from any copy of the tree.
std::string repo_root();

// Path of a file under the repository root.
std::string repo_path(const std::string& relative);

bool cuda_available();

// A PFM as the command writes it (linear RGB, row 0 = top, as renders return it);
// a failure is added to the test where the file is not a width x height PFM.
std::vector<float> read_pfm(const std::string& path, int width, int height);

}  // namespace wt::test

// GPU tests skip (and say so) where no CUDA device is present.
#define WT_REQUIRE_CUDA()                                              \
  do {                                                                 \
    if (!::wt::test::cuda_available()) GTEST_SKIP() << "no CUDA device"; \
  } while (0)

// Helpers shared by the tests: where the repository is, and whether a GPU is.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace wt::test {

// A fresh folder of the running test's own (named after it and the process),
// removed with it.
class TestFolder {
 public:
  TestFolder();
  ~TestFolder();
  TestFolder(const TestFolder&) = delete;
  TestFolder& operator=(const TestFolder&) = delete;
  const std::filesystem::path& root() const { return root_; }

 private:
  std::filesystem::path root_;
};

// The repository root, found from WAVETRACE_ROOT or by walking up from the working
// directory to the folder that holds scenes/; test data is read relative to it, so
// the test binary runs from any copy of the tree.
std::string repo_root();

// Path of a file under the repository root.
std::string repo_path(const std::string& relative);

// The shared real meshes (stanford-bunny.obj, teapot.obj, ...): WAVETRACE_MODELS
// where set (a machine whose copy of the tree has them elsewhere), else
// ../shared/models beside the repository root. Tests that use them skip without them.
std::string models_dir();

bool cuda_available();

// Whether this binary was built with AddressSanitizer (scripts/test-asan.sh): its
// shadow memory and its quarantine of freed blocks change what a process's memory
// figures mean, and it cannot run under an address-space limit.
constexpr bool kAddressSanitizer =
#if defined(__SANITIZE_ADDRESS__)
    true;
#else
    false;
#endif

// A PFM as the command writes it (linear RGB, row 0 = top, as renders return it);
// a failure is added to the test where the file is not a width x height PFM.
std::vector<float> read_pfm(const std::string& path, int width, int height);

// Runs fn in a child process (fork) and returns what it returned, so that a test can
// put limits on the child (RLIMIT_FSIZE, RLIMIT_AS) that the test process keeps
// clear of. A child that dies or exits otherwise gives "child process failed: ...".
std::string in_child_process(const std::function<std::string()>& fn);

// In such a child: a disk that fills up, for real and unprivileged. Files may not grow
// past `bytes` (RLIMIT_FSIZE) and SIGXFSZ is ignored, so a write past the limit fails
// with EFBIG, as a write to a full disk fails with ENOSPC. False if it cannot be set.
bool limit_file_size(unsigned long long bytes);

// A guard on a test that could hang (a read that blocks on a FIFO): unless it is
// destroyed within `limit`, its thread prints what hung and ends the process with
// exit code 124 (as timeout(1) does), so that a regression fails the test run
// instead of holding CI until its own time limit.
class Watchdog {
 public:
  Watchdog(std::chrono::seconds limit, std::string what);
  ~Watchdog();
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

 private:
  std::mutex m_;
  std::condition_variable cv_;
  bool done_ = false;
  std::thread thread_;
};

}  // namespace wt::test

// GPU tests skip (and say so) where no CUDA device is present.
#define WT_REQUIRE_CUDA()                                              \
  do {                                                                 \
    if (!::wt::test::cuda_available()) GTEST_SKIP() << "no CUDA device"; \
  } while (0)

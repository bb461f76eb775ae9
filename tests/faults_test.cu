// Faults during a job on the device: a kernel that faults (the tests' own, storing
// through a null pointer) poisons the context of its process for good; the job that
// meets it fails with one line, writes nothing, and says the context cannot be
// recovered; an in-process batch then fails its CUDA jobs at once and still runs its
// CPU jobs. Those tests fault in a fresh process of their own (a death test in the
// "threadsafe" style re-executes this binary for the statement), so that the test
// process keeps a clean context. An allocation larger than the device fails naming
// the allocation, frees what was allocated before it, and leaves the context usable.
// These tests skip without a device.
#include <gtest/gtest.h>

#include <cuda_runtime.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "app/batch.hpp"
#include "app/job.hpp"
#include "cuda/buffer.hpp"
#include "device/device.hpp"
#include "fault_injection.hpp"
#include "test_support.hpp"

namespace wt::test {

namespace {

__global__ void store_through(int* p) { *p = 1; }

}  // namespace

void poison_device() {
  store_through<<<1, 1>>>(nullptr);  // the pointer comes from the host: the compiler cannot see the fault
  WT_CUDA_LAUNCHED("store_through", "fault test");
  WT_CUDA(cudaDeviceSynchronize(), "fault test");
}

namespace {

namespace fs = std::filesystem;
using app::Job;
using app::JobOutcome;

class DeviceFaults : public testing::Test {
 protected:
  void SetUp() override {
    WT_REQUIRE_CUDA();
    dir_ = fs::temp_directory_path() / ("wavetrace_device_faults_" + std::to_string(::getpid()) + "_" +
                                        testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(path("s.json")) << R"({
      "camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
      "materials": [{"name": "m", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}],
      "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})";
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  Job cuda_job(const std::string& output, const std::string& kernel = "megakernel") const {
    Job j;
    j.scene = path("s.json");
    j.output = path(output);
    j.backend = "cuda";
    j.kernel = kernel;
    j.devices = "0";  // the device whose context the tests poison (a split would use the others too)
    j.width = 32;
    j.height = 16;
    j.spp = 4;
    j.progress = false;
    return j;
  }

  fs::path dir_;
};

std::string poison_message() {
  try {
    poison_device();
  } catch (const cuda::CudaError& e) {
    return e.what();
  }
  return "no error";
}

// In a death test's child: ends it, with 0 only if no check of the test failed (the
// child's failures are printed there and do not reach the parent's test result).
[[noreturn]] void exit_with_checks(const fs::path& dir) {
  fs::remove_all(dir);  // the child's own folder: its SetUp made it, its TearDown does not run
  std::fflush(stdout);
  std::fflush(stderr);
  std::_Exit(testing::Test::HasFailure() ? 1 : 0);
}

TEST_F(DeviceFaults, KernelFaultLosesTheContextOfItsProcessAndTheJobSaysSo) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const auto in_child = [&] {
    const std::string fault = poison_message();
    EXPECT_EQ(fault.rfind("fault test: cudaDeviceSynchronize() failed: cudaErrorIllegalAddress (", 0), 0u) << fault;
    // The poisoned context fails the job that meets it: one line naming the call
    // and the stage, exit 1, no image, and the context is lost.
    const JobOutcome failed = app::run_job(cuda_job("a.png"));
    EXPECT_EQ(failed.exit_code, app::kExitFailure);
    EXPECT_EQ(failed.message.rfind("CUDA error: ", 0), 0u) << failed.message;
    EXPECT_NE(failed.message.find(" failed: cudaErrorIllegalAddress ("), std::string::npos) << failed.message;
    EXPECT_NE(failed.message.find("; " + std::string(cuda::kContextLost)), std::string::npos) << failed.message;
    EXPECT_EQ(failed.message.find('\n'), std::string::npos) << failed.message;
    EXPECT_TRUE(failed.device_lost);
    EXPECT_FALSE(fs::exists(path("a.png")));
    // It stays lost: no later CUDA work of this process runs.
    EXPECT_EQ(cuda::recover_after_error(), cuda::Recovery::Lost);
    EXPECT_NE(app::run_job(cuda_job("b.png")).exit_code, 0);
    EXPECT_FALSE(fs::exists(path("b.png")));
    exit_with_checks(dir_);
  };
  EXPECT_EXIT(in_child(), testing::ExitedWithCode(0), "");
}

TEST_F(DeviceFaults, InProcessBatchFailsCudaJobsAtOnceAfterAStickyFaultAndRunsCpuJobs) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const auto in_child = [&] {
    Job cpu = cuda_job("cpu.png");
    cpu.backend = "cpu";
    Job before = cuda_job("before.png");
    const std::vector<app::PlannedJob> first = {{before, ""}};
    EXPECT_EQ(app::run_batch(first), 0);
    poison_message();
    const std::vector<app::PlannedJob> jobs = {
        {cuda_job("a.png"), ""}, {cuda_job("b.png", "wavefront"), ""}, {cpu, ""}, {cuda_job("c.png"), ""}};
    testing::internal::CaptureStderr();
    const int code = app::run_batch(jobs);
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_EQ(code, app::kExitFailure);
    EXPECT_TRUE(fs::exists(path("before.png")));
    EXPECT_FALSE(fs::exists(path("a.png")));
    EXPECT_FALSE(fs::exists(path("b.png")));
    EXPECT_TRUE(fs::exists(path("cpu.png")));
    EXPECT_FALSE(fs::exists(path("c.png")));
    // Job 1 meets the fault and says the context is lost; jobs 2 and 4 fail at once,
    // one line each, naming job 1.
    EXPECT_NE(err.find(cuda::kContextLost), std::string::npos) << err;
    const std::string lost = "wavetrace: CUDA device lost in this process: job 1 met a sticky error;";
    size_t count = 0;
    for (size_t at = err.find(lost); at != std::string::npos; at = err.find(lost, at + 1)) ++count;
    EXPECT_EQ(count, 2u) << err;
    exit_with_checks(dir_);
  };
  EXPECT_EXIT(in_child(), testing::ExitedWithCode(0), "");
}

TEST_F(DeviceFaults, RecoveryFindsAUsableContextClean) {
  // Nothing failed, or a failure that did not poison the context: the next job runs
  // with every kernel in this process.
  EXPECT_EQ(cuda::recover_after_error(), cuda::Recovery::Clean);
  for (const std::string& kernel : kernel_names(Backend::Cuda)) {
    const JobOutcome o = app::run_job(cuda_job(kernel + ".png", kernel));
    EXPECT_EQ(o.exit_code, 0) << kernel << ": " << o.message;
    EXPECT_TRUE(fs::exists(path(kernel + ".png"))) << kernel;
  }
}

TEST_F(DeviceFaults, OutOfDeviceMemoryNamesTheAllocationAndFreesWhatWasAllocated) {
  size_t free_before = 0, total = 0;
  WT_CUDA(cudaMemGetInfo(&free_before, &total), "fault test");
  std::string message = "no error";
  {
    cuda::DeviceBuffer<char> first(free_before / 2, "fault test: first buffer");
    try {
      cuda::DeviceBuffer<char> second(total, "fault test: second buffer");
    } catch (const cuda::CudaError& e) {
      message = e.what();
    }
  }
  const std::string expected = "fault test: second buffer: out of device memory: allocating " +
                               std::to_string((total + (1 << 20) - 1) >> 20) +
                               " MiB failed: cudaErrorMemoryAllocation (";
  EXPECT_EQ(message.rfind(expected, 0), 0u) << message;
  // Not sticky: no reset, and the first buffer is freed.
  EXPECT_EQ(cuda::recover_after_error(), cuda::Recovery::Clean);
  size_t free_after = 0;
  WT_CUDA(cudaMemGetInfo(&free_after, &total), "fault test");
  EXPECT_GE(free_after + (size_t(64) << 20), free_before);
  const JobOutcome next = app::run_job(cuda_job("next.png", "wavefront"));
  EXPECT_EQ(next.exit_code, 0) << next.message;
}

}  // namespace
}  // namespace wt::test

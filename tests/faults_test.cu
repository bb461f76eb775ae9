// Faults during a job on the device: a kernel that faults (the tests' own, storing
// through a null pointer) poisons the context; the job that meets it fails with one
// line, writes nothing, and the device is reset so that the next job runs. An
// allocation larger than the device fails naming the allocation, frees what was
// allocated before it, and needs no reset. These tests skip without a device.
#include <gtest/gtest.h>

#include <cuda_runtime.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "app/batch.hpp"
#include "app/job.hpp"
#include "cuda/buffer.hpp"
#include "cuda/device.hpp"
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

TEST_F(DeviceFaults, KernelFaultFailsTheNextJobAloneAndTheDeviceIsReset) {
  const std::string fault = poison_message();
  EXPECT_EQ(fault.rfind("fault test: cudaDeviceSynchronize() failed: cudaErrorIllegalAddress (", 0), 0u) << fault;

  // The poisoned context fails the job that meets it: one line, exit 1, no image.
  const JobOutcome failed = app::run_job(cuda_job("a.png"));
  EXPECT_EQ(failed.exit_code, app::kExitFailure);
  EXPECT_EQ(failed.message.rfind("CUDA error: ", 0), 0u) << failed.message;
  EXPECT_NE(failed.message.find("cudaErrorIllegalAddress"), std::string::npos) << failed.message;
  EXPECT_NE(failed.message.find("; the device was reset"), std::string::npos) << failed.message;
  EXPECT_EQ(failed.message.find('\n'), std::string::npos) << failed.message;
  EXPECT_TRUE(failed.device_reset);
  EXPECT_FALSE(fs::exists(path("a.png")));

  // And the next job runs on the reset device.
  const JobOutcome next = app::run_job(cuda_job("b.png"));
  EXPECT_EQ(next.exit_code, 0) << next.message;
  EXPECT_TRUE(fs::exists(path("b.png")));
}

TEST_F(DeviceFaults, BatchGoesOnPastAKernelFault) {
  poison_message();
  const std::vector<app::PlannedJob> jobs = {{cuda_job("a.png"), ""}, {cuda_job("b.png", "wavefront"), ""}};
  EXPECT_EQ(app::run_batch(jobs), app::kExitFailure);
  EXPECT_FALSE(fs::exists(path("a.png")));
  EXPECT_TRUE(fs::exists(path("b.png")));
}

TEST_F(DeviceFaults, RecoveryResetsOnlyAPoisonedContextAndEveryKernelRunsAfterIt) {
  EXPECT_EQ(cuda::recover_after_error(), cuda::Recovery::Clean);
  poison_message();
  EXPECT_EQ(cuda::recover_after_error(), cuda::Recovery::Reset);
  EXPECT_EQ(cuda::recover_after_error(), cuda::Recovery::Clean);
  // A fresh context: constant memory, kernel modules and cached block sizes all work.
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

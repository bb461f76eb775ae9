// The command's jobs as a user meets them: bad input is one line, exit code 2 and
// no output file; a good job writes its image and stats; a batch goes on past a
// failing job and says so in its exit code.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/batch.hpp"
#include "app/job.hpp"
#include "test_support.hpp"

namespace wt::app {
namespace {

namespace fs = std::filesystem;

class JobTest : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("wavetrace_job_test_" + std::to_string(::getpid()) + "_" +
                                        testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
    return path(name);
  }

  Job small_job(const std::string& scene, const std::string& output) const {
    Job j;
    j.scene = scene;
    j.output = output;
    j.backend = "cpu";
    j.width = 16;
    j.height = 9;
    j.spp = 2;
    j.progress = false;
    return j;
  }

  bool only_expected_files(std::initializer_list<std::string> names) const {
    size_t n = 0;
    for (const auto& e : fs::directory_iterator(dir_)) {
      ++n;
      if (std::find(names.begin(), names.end(), e.path().filename().string()) == names.end()) return false;
    }
    return n == names.size();
  }

  fs::path dir_;
};

const char* kTinyScene = R"({
  "camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
  "materials": [{"name": "m", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}],
  "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]
})";

TEST_F(JobTest, GoodJobWritesImageAndStats) {
  Job j = small_job(write("s.json", kTinyScene), path("out.png"));
  j.stats = path("stats.json");
  JobOutcome o = run_job(j);
  ASSERT_EQ(o.exit_code, 0) << o.message;
  EXPECT_TRUE(fs::exists(path("out.png")));
  nlohmann::json stats = nlohmann::json::parse(std::ifstream(path("stats.json")));
  EXPECT_EQ(stats["paths"], 16 * 9 * 2);
  EXPECT_GE(stats["rays"].get<uint64_t>(), 16u * 9 * 2);
  for (const char* key : {"scene", "settings", "backend", "kernel", "device", "seconds", "m_rays_per_s", "m_paths_per_s"}) {
    EXPECT_TRUE(stats.contains(key)) << key;
  }
  EXPECT_TRUE(only_expected_files({"s.json", "out.png", "stats.json"}));
}

TEST_F(JobTest, PfmOutputHoldsLinearFloats) {
  Job j = small_job(write("s.json", kTinyScene), path("out.pfm"));
  ASSERT_EQ(run_job(j).exit_code, 0);
  std::ifstream f(path("out.pfm"), std::ios::binary);
  std::string magic;
  int w = 0, h = 0;
  float scale = 0;
  f >> magic >> w >> h >> scale;
  EXPECT_EQ(magic, "PF");
  EXPECT_EQ(w, 16);
  EXPECT_EQ(h, 9);
  EXPECT_LT(scale, 0.0f);  // little-endian
  f.get();
  std::vector<float> data(16 * 9 * 3);
  f.read(reinterpret_cast<char*>(data.data()), data.size() * sizeof(float));
  EXPECT_TRUE(f.good());
}

void expect_bad_input(const JobOutcome& o, const std::string& must_contain) {
  EXPECT_EQ(o.exit_code, kExitBadInput);
  EXPECT_NE(o.message.find(must_contain), std::string::npos) << o.message;
  EXPECT_EQ(o.message.find('\n'), std::string::npos) << "one line: " << o.message;
}

TEST_F(JobTest, MissingSceneFileIsBadInputAndWritesNothing) {
  expect_bad_input(run_job(small_job(path("nope.json"), path("out.png"))), "nope.json");
  EXPECT_TRUE(only_expected_files({}));
}

TEST_F(JobTest, UnknownMaterialIsBadInputAndWritesNothing) {
  std::string scene = write("s.json", R"({
    "camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
    "materials": [{"name": "m", "type": "plastic"}],
    "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})");
  expect_bad_input(run_job(small_job(scene, path("out.png"))), "/materials/0/type");
  EXPECT_TRUE(only_expected_files({"s.json"}));
}

TEST_F(JobTest, ZeroSamplesIsBadInputAndWritesNothing) {
  Job j = small_job(write("s.json", kTinyScene), path("out.png"));
  j.spp = 0;
  expect_bad_input(run_job(j), "spp");
  EXPECT_TRUE(only_expected_files({"s.json"}));
}

TEST_F(JobTest, UnwritableOutputPathIsBadInputBeforeRendering) {
  Job j = small_job(write("s.json", kTinyScene), path("missing-folder/out.png"));
  expect_bad_input(run_job(j), "missing-folder");
  j.output = path("out.jpg");
  expect_bad_input(run_job(j), "out.jpg");
  EXPECT_TRUE(only_expected_files({"s.json"}));
}

TEST_F(JobTest, ConstantMegakernelOnCpuIsBadInput) {
  Job j = small_job(write("s.json", kTinyScene), path("out.png"));
  j.kernel = "megakernel-constant";
  expect_bad_input(run_job(j), "megakernel-constant");
}

TEST_F(JobTest, BatchGoesOnPastAFailingJobAndFailsOverall) {
  write("s.json", kTinyScene);
  std::string jobs = write("jobs.json", R"({
    "defaults": {"backend": "cpu", "width": 8, "height": 8, "spp": 1},
    "jobs": [
      {"scene": "missing.json", "output": "a.png"},
      {"scene": "s.json", "output": "b.png", "spelling": 1},
      {"scene": "s.json", "output": "c.png", "stats": "c.json"}
    ]})");
  Job base;
  base.progress = false;
  std::vector<PlannedJob> planned = read_jobs_file(jobs, base);
  ASSERT_EQ(planned.size(), 3u);
  EXPECT_NE(planned[1].error.find("/jobs/1/spelling"), std::string::npos) << planned[1].error;
  EXPECT_EQ(run_batch(planned), kExitFailure);
  EXPECT_FALSE(fs::exists(path("a.png")));
  EXPECT_FALSE(fs::exists(path("b.png")));
  EXPECT_TRUE(fs::exists(path("c.png")));
  EXPECT_TRUE(fs::exists(path("c.json")));
}

TEST_F(JobTest, BatchOfGoodJobsSucceeds) {
  write("s.json", kTinyScene);
  std::string jobs = write("jobs.json", R"({"defaults": {"backend": "cpu", "width": 8, "height": 8, "spp": 1},
    "jobs": [{"scene": "s.json", "output": "a.png"}, {"scene": "s.json", "output": "b.pfm", "seed": 3}]})");
  Job base;
  base.progress = false;
  EXPECT_EQ(run_batch(read_jobs_file(jobs, base)), 0);
  EXPECT_TRUE(fs::exists(path("a.png")));
  EXPECT_TRUE(fs::exists(path("b.pfm")));
}

TEST_F(JobTest, MalformedJobsFileIsRejected) {
  std::string jobs = write("jobs.json", R"({"jobs": [)");
  EXPECT_THROW(read_jobs_file(jobs, Job{}), SceneError);
}

}  // namespace
}  // namespace wt::app

// `wavetrace batch` through the built program (its path is this binary's first
// argument; see CMakeLists.txt): good and bad jobs, in the lane's worker process and
// each in a process of its own, on the CPU, and on CUDA where a device is present.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "../test_support.hpp"

namespace {

namespace fs = std::filesystem;

std::string g_wavetrace;

class BatchCommand : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(g_wavetrace.empty()) << "usage: wavetrace_command_tests PATH/TO/wavetrace";
    dir_ = fs::temp_directory_path() / ("wavetrace_batch_command_" + std::to_string(::getpid()) + "_" +
                                        testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "s.json") << R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
      "materials": [{"name": "m", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}],
      "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})";
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // Runs `wavetrace batch ARGS` with its temporary files in dir_/tmp; its exit code.
  int batch(const std::string& args) {
    fs::create_directories(dir_ / "tmp");
    const std::string command = "TMPDIR='" + path("tmp") + "' '" + g_wavetrace + "' batch " + args + " >'" +
                                path("out.txt") + "' 2>'" + path("err.txt") + "'";
    const int status = std::system(command.c_str());
    out_ = read(path("out.txt"));
    err_ = read(path("err.txt"));
    fs::remove(path("out.txt"));
    fs::remove(path("err.txt"));
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  static std::string read(const std::string& p) {
    std::ostringstream s;
    s << std::ifstream(p).rdbuf();
    return s.str();
  }

  static size_t count(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
  }

  // Good and bad jobs on `backend`, the batch run with `flags`; checks what it did.
  void good_and_bad_jobs(const std::string& backend, const std::string& flags = "") {
    std::ofstream(path("jobs.json")) << R"({"defaults": {"backend": ")" << backend
                                     << R"(", "width": 32, "height": 16, "spp": 2},
      "jobs": [{"scene": "s.json", "output": "a.png", "stats": "a.json"},
               {"scene": "missing.json", "output": "b.png"},
               {"scene": "s.json", "output": "c.pfm", "kernel": "wavefront", "seed": 7, "depth": 4},
               {"scene": "s.json", "output": "no-such-folder/d.png"},
               {"scene": "s.json", "output": "e.png", "spelling": 1}]})";
    EXPECT_EQ(batch("'" + path("jobs.json") + "'" + flags), 1) << err_;
    EXPECT_TRUE(fs::exists(path("a.png")));
    EXPECT_TRUE(fs::exists(path("a.json")));
    EXPECT_TRUE(fs::exists(path("c.pfm")));
    EXPECT_FALSE(fs::exists(path("b.png")));
    EXPECT_FALSE(fs::exists(path("e.png")));
    EXPECT_TRUE(fs::is_empty(path("tmp")));  // the temporary stats files are gone
    // The summary: figures from each good job's stats, each failure's line.
    EXPECT_NE(out_.find("32x16 2spp d10         " + backend + "/megakernel"), std::string::npos) << out_;
    EXPECT_NE(out_.find("32x16 2spp d4          " + backend + "/wavefront"), std::string::npos) << out_;
    EXPECT_EQ(count(out_, "ok -> " + path("a.png")), 1u) << out_;
    EXPECT_EQ(count(out_, "ok -> " + path("c.pfm")), 1u) << out_;
    const std::string missing = path("missing.json") + ": cannot open scene file";
    const std::string folder = path("no-such-folder/d.png") + ": cannot write: folder '" + path("no-such-folder") + "' does not exist";
    const std::string key = path("jobs.json") + ": /jobs/4/spelling: unknown key";
    for (const std::string& line : {missing, folder, key}) {
      EXPECT_EQ(count(out_, "FAILED: " + line), 1u) << out_;
      EXPECT_EQ(count(err_, "wavetrace: " + line), 1u) << err_;  // once: the child's line is not repeated
    }
    EXPECT_NE(out_.find("\n5 jobs: 2 ok, 3 failed\n"), std::string::npos) << out_;

    // Resumed: the done jobs are skipped, the bad ones fail again.
    EXPECT_EQ(batch("'" + path("jobs.json") + "' --resume" + flags), 1) << err_;
    EXPECT_EQ(count(out_, "skipped: " + path("a.png") + " exists"), 1u) << out_;
    EXPECT_EQ(count(out_, "skipped: " + path("c.pfm") + " exists"), 1u) << out_;
    EXPECT_NE(out_.find("\n5 jobs: 2 ok, 3 failed\n"), std::string::npos) << out_;

    // Scene files given directly, with render options.
    fs::create_directories(dir_ / "renders");
    EXPECT_EQ(batch("'" + path("s.json") + "' --output-dir '" + path("renders") + "' --backend " + backend +
                    " --width 8 --height 8 --spp 1" + flags),
              0)
        << err_;
    EXPECT_TRUE(fs::exists(dir_ / "renders" / "s.png"));
    EXPECT_NE(out_.find("8x8 1spp"), std::string::npos) << out_;
  }

  fs::path dir_;
  std::string out_, err_;
};

// The jobs in the lane's worker process, and each in a process of its own.
TEST_F(BatchCommand, GoodAndBadJobsOnTheCpuInAWorker) { good_and_bad_jobs("cpu"); }
TEST_F(BatchCommand, GoodAndBadJobsOnTheCpuEachInAProcessOfItsOwn) { good_and_bad_jobs("cpu", " --process-per-job"); }

TEST_F(BatchCommand, GoodAndBadJobsOnCudaInAWorker) {
  WT_REQUIRE_CUDA();
  good_and_bad_jobs("cuda");
}

TEST_F(BatchCommand, GoodAndBadJobsOnCudaEachInAProcessOfItsOwn) {
  WT_REQUIRE_CUDA();
  good_and_bad_jobs("cuda", " --process-per-job");
}

// The worker is the batch's: started by hand, without its answer descriptor, it says so.
TEST_F(BatchCommand, AWorkerStartedByHandSaysWhatItIs) {
  const std::string command = "'" + g_wavetrace + "' worker </dev/null 3>&- 2>'" + path("err.txt") + "'";
  const int status = std::system(command.c_str());
  EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 1);
  EXPECT_NE(read(path("err.txt")).find("wavetrace: worker: descriptor 3 is not open for answers"), std::string::npos)
      << read(path("err.txt"));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  if (argc > 1) g_wavetrace = argv[1];
  return RUN_ALL_TESTS();
}

// `mpirun -n N wavetrace render|batch` through the built program (its path is this
// binary's first argument; see CMakeLists.txt), with CPU ranks oversubscribing the
// machine's cores: the N-rank image against the one-process image, a failing rank,
// ranks that disagree, a batch handed out to ranks. Skipped, saying why, where mpirun
// is absent or the program was built without MPI.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "../test_support.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string g_wavetrace;

// The bound of an N-rank image against the one-process image: the same samples' sums
// added in another grouping (a rank's range, then the ranks in order), as for the
// split over devices (tests/split_test.cpp).
constexpr float kRelativeBound = 1e-5f;

class MpiCommand : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(g_wavetrace.empty()) << "usage: wavetrace_mpi_tests PATH/TO/wavetrace";
    if (std::system("command -v mpirun >/dev/null 2>&1") != 0) {
      GTEST_SKIP() << "mpirun is not installed (Debian: openmpi-bin): the MPI ranks are not tested here";
    }
#if !WT_BUILT_WITH_MPI
    GTEST_SKIP() << "this wavetrace was built without MPI (libopenmpi-dev absent): its ranks are not tested here";
#endif
    dir_ = fs::temp_directory_path() / ("wavetrace_mpi_" + std::to_string(::getpid()) + "_" +
                                        testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // Runs a shell command line (its {W} replaced by the program) in dir_; its exit code.
  int shell(std::string line) {
    for (size_t at; (at = line.find("{W}")) != std::string::npos;) line.replace(at, 3, "'" + g_wavetrace + "'");
    // Containers run tests as root, which Open MPI refuses unless told. Under
    // AddressSanitizer the leak check of processes that start MPI is off: Open MPI
    // leaves its own allocations at MPI_Finalize, some made by components it has
    // unloaded by then, which no suppression can name; the code the ranks run is the
    // one the rest of the suite checks for leaks in a single process.
    const bool mpi = line.rfind("mpirun", 0) == 0 || line.find("SLURM_STEP_NUM_TASKS") != std::string::npos;
    const std::string leaks = mpi && wt::test::kAddressSanitizer ? "ASAN_OPTIONS=\"$ASAN_OPTIONS:detect_leaks=0\" " : "";
    const std::string command = "cd '" + dir_.string() +
                                "' && OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
                                "OMPI_MCA_rmaps_base_oversubscribe=1 " +
                                leaks + "timeout 120 " + line + " >out.txt 2>err.txt";
    const int status = std::system(command.c_str());
    out_ = read(path("out.txt"));
    err_ = read(path("err.txt"));
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  static std::string read(const std::string& p) {
    std::ostringstream s;
    s << std::ifstream(p).rdbuf();
    return s.str();
  }

  // The render options of these tests: a small image of the reference scene, one
  // thread a rank (the ranks share CI's two cores).
  static std::string scene_and_options(int width = 48) {
    return "'" + (fs::current_path() / "scenes" / "seed57.json").string() + "' --backend cpu --width " +
           std::to_string(width) + " --height 27 --spp 12 --threads 1 -q";
  }

  void expect_same_image(const std::string& a, const std::string& b) {
    const std::vector<float> x = wt::test::read_pfm(path(a), 48, 27), y = wt::test::read_pfm(path(b), 48, 27);
    ASSERT_EQ(x.size(), y.size());
    ASSERT_FALSE(x.empty());
    for (size_t i = 0; i < x.size(); ++i) {
      ASSERT_NEAR(x[i], y[i], kRelativeBound * std::max(1.0f, std::abs(x[i]))) << a << " vs " << b << " at " << i;
    }
  }

  fs::path dir_;
  std::string out_, err_;
};

TEST_F(MpiCommand, RanksOnTheCpuRenderTheOneProcessImage) {
  for (const std::string kernel : {"megakernel", "wavefront"}) {
    SCOPED_TRACE(kernel);
    const std::string options = scene_and_options() + " --kernel " + kernel;
    ASSERT_EQ(shell("{W} render " + options + " -o one.pfm --stats one.json"), 0) << err_;
    ASSERT_EQ(shell("mpirun -n 3 {W} render " + options + " -o three.pfm --stats three.json"), 0) << err_;
    // Two ranks, each splitting its samples over two host "devices".
    ASSERT_EQ(shell("mpirun -n 2 {W} render " + options + " --devices 0,1 -o two.pfm"), 0) << err_;
    expect_same_image("one.pfm", "three.pfm");
    expect_same_image("one.pfm", "two.pfm");

    // Every path traced once, by one of the ranks, each its share of the samples.
    const json one = json::parse(read(path("one.json"))), three = json::parse(read(path("three.json")));
    EXPECT_EQ(three["rays"], one["rays"]);
    EXPECT_EQ(three["device"], "3 ranks");
    EXPECT_EQ(three["ranks"], 3);
    EXPECT_GE(three["wall_seconds"].get<double>(), three["seconds"].get<double>());  // it holds the slowest render
    ASSERT_EQ(three["devices"].size(), 3u) << three.dump(2);
    int samples = 0;
    for (size_t r = 0; r < 3; ++r) {
      const json& d = three["devices"][r];
      EXPECT_EQ(d["device"].get<std::string>().rfind("rank " + std::to_string(r) + " (", 0), 0u) << d.dump();
      EXPECT_EQ(d["samples"], 4);
      samples += d["samples"].get<int>();
    }
    EXPECT_EQ(samples, 12);
  }
}

// An adaptive render over ranks: rank 0 decides each round, every rank renders its
// run of the pixels still going, each pixel's samples on one rank alone: the image,
// each pixel's samples and the rays are the one process's, bit for bit.
TEST_F(MpiCommand, AnAdaptiveRenderOverRanksIsTheOneProcessRender) {
  const std::string options = "'" + (fs::current_path() / "scenes" / "seed57.json").string() +
                              "' --backend cpu --width 48 --height 27 --spp 128 --threads 1 -q --noise-threshold 0.05"
                              " --min-spp 8 --aov spp";
  ASSERT_EQ(shell("{W} render " + options + " -o one.pfm --stats one.json"), 0) << err_;
  ASSERT_EQ(shell("mpirun -n 3 {W} render " + options + " -o three.pfm --stats three.json"), 0) << err_;
  EXPECT_EQ(read(path("one.pfm")), read(path("three.pfm")));
  EXPECT_EQ(read(path("one.spp.pfm")), read(path("three.spp.pfm")));
  const json one = json::parse(read(path("one.json"))), three = json::parse(read(path("three.json")));
  EXPECT_EQ(three["rays"], one["rays"]);
  EXPECT_EQ(three["adaptive"]["converged_pixels"], one["adaptive"]["converged_pixels"]);
  EXPECT_GT(one["adaptive"]["converged_pixels"].get<int>(), 0);
  EXPECT_EQ(three["ranks"], 3);
  ASSERT_EQ(three["devices"].size(), 3u) << three.dump(2);
  for (size_t r = 0; r < 3; ++r) EXPECT_GT(three["devices"][r]["paths"].get<uint64_t>(), 0u) << three.dump(2);
}

TEST_F(MpiCommand, AFailingRankFailsTheRunSayingWhichAndWhyAndNoImageIsWritten) {
  const std::string options = scene_and_options() + " -o out.png";
  // Rank 2's scene is missing (as on a host without the file).
  EXPECT_EQ(shell("mpirun -n 2 {W} render " + options + " : -n 1 {W} render missing.json --backend cpu -o out.png"),
            2)
      << err_;
  EXPECT_NE(err_.find("wavetrace: rank 2 of 3 ("), std::string::npos) << err_;
  EXPECT_NE(err_.find("missing.json: cannot open scene file"), std::string::npos) << err_;
  EXPECT_FALSE(fs::exists(path("out.png")));

  // Rank 2 disagrees on the resolution: refused before anything is rendered.
  EXPECT_EQ(shell("mpirun -n 2 {W} render " + options + " : -n 1 {W} render " + scene_and_options(40) + " -o out.png"),
            2)
      << err_;
  EXPECT_NE(err_.find("wavetrace: rank 2 of 3 ("), std::string::npos) << err_;
  EXPECT_NE(err_.find("renders 40x27"), std::string::npos) << err_;
  EXPECT_FALSE(fs::exists(path("out.png")));

  // Rank 2 is killed while the others render: the run fails, with no image.
  EXPECT_NE(shell("mpirun -n 2 {W} render " + options + " : -n 1 sh -c 'kill -KILL $$'"), 0) << err_;
  EXPECT_FALSE(fs::exists(path("out.png")));

  // Tasks a launcher started without MPI's wiring (Slurm's srun without --mpi) each
  // see one rank: refused, rather than each rendering and writing the whole image.
  EXPECT_EQ(shell("env SLURM_STEP_NUM_TASKS=2 {W} render " + options), 1) << err_;
  EXPECT_NE(err_.find("started as one of 2 tasks, but MPI sees 1 rank"), std::string::npos) << err_;
  EXPECT_FALSE(fs::exists(path("out.png")));

  // Checkpoints are one process's: refused, by rank 0 for every rank.
  EXPECT_EQ(shell("mpirun -n 2 {W} render " + options + " --checkpoint c.ckpt"), 2) << err_;
  EXPECT_NE(err_.find("wavetrace: ranks 0, 1 of 2 ("), std::string::npos) << err_;
  EXPECT_NE(err_.find("checkpoint: checkpoints are kept by one process"), std::string::npos) << err_;
  EXPECT_FALSE(fs::exists(path("out.png")));
  EXPECT_FALSE(fs::exists(path("c.ckpt")));
}

TEST_F(MpiCommand, ABatchHandsItsJobsToTheRanksAsTheyFreeUp) {
  const std::string scene = (fs::current_path() / "scenes" / "seed57.json").string();
  std::ofstream(path("jobs.json")) << R"({"defaults": {"backend": "cpu", "width": 32, "height": 18, "spp": 4,
      "threads": 1, "scene": ")" << scene
                                   << R"("}, "jobs": [{"output": "a.png"}, {"output": "b.png", "seed": 2},
      {"scene": "missing.json", "output": "c.png"}, {"output": "d.pfm", "kernel": "wavefront"},
      {"output": "e.png", "seed": 3}, {"output": "f.png", "seed": 4}]})";
  EXPECT_EQ(shell("mpirun -n 3 {W} batch jobs.json"), 1) << err_;
  for (const char* image : {"a.png", "b.png", "d.pfm", "e.png", "f.png"}) EXPECT_TRUE(fs::exists(path(image))) << image;
  EXPECT_FALSE(fs::exists(path("c.png")));
  // One summary, by rank 0, of every job once.
  const auto count = [](const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count(out_, "jobs: "), 1u) << out_;
  EXPECT_NE(out_.find("\n6 jobs: 5 ok, 1 failed\n"), std::string::npos) << out_;
  EXPECT_EQ(count(out_, "FAILED: missing.json: cannot open scene file"), 1u) << out_;
  for (int job = 1; job <= 6; ++job) {
    EXPECT_EQ(count(err_, "[" + std::to_string(job) + "/6] "), 1u) << err_;  // taken once
  }
  // The other ranks took jobs: rank 0's own lane runs one at a time, each a process.
  EXPECT_NE(err_.find(" on rank "), std::string::npos) << err_;

  // A jobs file rank 0 refuses: said once, and every rank ends.
  std::ofstream(path("bad.json")) << R"({"jobs": 3})";
  EXPECT_EQ(shell("mpirun -n 3 {W} batch bad.json"), 2) << err_;
  EXPECT_EQ(count(err_, "bad.json: /jobs: must be an array"), 1u) << err_;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  if (argc > 1) g_wavetrace = fs::absolute(argv[1]).string();
  return RUN_ALL_TESTS();
}

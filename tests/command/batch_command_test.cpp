// `wavetrace batch` through the built program (its path is this binary's first
// argument; see CMakeLists.txt): good and bad jobs, in the lane's worker process and
// each in a process of its own, on the CPU, and on CUDA where a device is present;
// jobs that would write one file, inputs that are no jobs file, and (through
// `wavetrace render`) a FIFO for a scene and a disk that fills up.
#include <algorithm>
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>

#include "../test_support.hpp"
#include "image/denoise.hpp"

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
  int batch(const std::string& args) { return wavetrace("batch " + args); }

  // Runs `wavetrace WORDS` with its temporary files in dir_/tmp, after `setup` (shell
  // commands, such as a ulimit, in the same subshell) and through `wrapper` (a command
  // that runs it, such as timeout): its exit code, its output and errors in out_ and err_.
  int wavetrace(const std::string& words, const std::string& setup = "", const std::string& wrapper = "") {
    fs::create_directories(dir_ / "tmp");
    const std::string command = "(export TMPDIR='" + path("tmp") + "'; " + setup + "exec " + wrapper + "'" +
                                g_wavetrace + "' " + words + ") >'" + path("out.txt") + "' 2>'" + path("err.txt") + "'";
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

// ---- Files that collide, inputs that are no jobs file ----

const std::string kPrecious = "bytes that were here before the batch";

// Two jobs writing one image: the second would overwrite the first's. Refused before
// either runs, naming both.
// One worker renders job A (an image texture and an environment), then B, then A
// again: nothing of a job stays behind in the worker for the next (images, tables,
// settings), so each image is bit for bit the one its job renders alone.
TEST_F(BatchCommand, AWorkersJobsEachRenderTheImageTheyRenderAlone) {
  const std::string textures = wt::test::repo_path("scenes/textures");
  std::ofstream(path("a.json")) << R"({"camera": {"look_from": [0, 0.5, 4], "look_at": [0, 0, 0]},
      "sky": {"type": "environment", "file": ")" << textures << R"(/sky_sun.hdr"},
      "textures": [{"name": "t", "type": "image", "file": ")" << textures << R"(/planet.png"}],
      "materials": [{"name": "m", "type": "lambertian", "texture": "t"}, {"name": "c", "type": "metal", "fuzz": 0.3}],
      "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}, {"center": [1.6, 0, 0], "radius": 0.5, "material": "c"}]})";
  std::ofstream(path("jobs.json")) << R"({"defaults": {"backend": "cpu", "width": 40, "height": 24, "spp": 3},
      "jobs": [{"scene": "a.json", "output": "a1.pfm"}, {"scene": "s.json", "output": "b1.pfm", "seed": 9},
               {"scene": "a.json", "output": "a2.pfm"}]})";
  ASSERT_EQ(batch("'" + path("jobs.json") + "'"), 0) << err_;
  const std::string settings = " --backend=cpu --width=40 --height=24 --spp=3 --quiet ";
  ASSERT_EQ(wavetrace("render --output='" + path("a.pfm") + "'" + settings + "'" + path("a.json") + "'"), 0) << err_;
  ASSERT_EQ(wavetrace("render --output='" + path("b.pfm") + "' --seed=9" + settings + "'" + path("s.json") + "'"), 0)
      << err_;
  const std::string a = read(path("a.pfm")), b = read(path("b.pfm"));
  ASSERT_GT(a.size(), 40u * 24 * 12);
  EXPECT_NE(a, b);
  EXPECT_TRUE(read(path("a1.pfm")) == a) << "job A first in the worker";
  EXPECT_TRUE(read(path("b1.pfm")) == b) << "job B after A";
  EXPECT_TRUE(read(path("a2.pfm")) == a) << "job A after B";
}

TEST_F(BatchCommand, TwoJobsWritingOneImageAreRefusedBeforeAnyRuns) {
  std::ofstream(path("jobs.json")) << R"({"defaults": {"backend": "cpu", "width": 32, "height": 16, "spp": 2},
    "jobs": [{"scene": "s.json", "output": "a.png"}, {"scene": "s.json", "output": "b.png"},
             {"scene": "s.json", "output": "alias/a.png", "seed": 2}]})";
  fs::create_directory_symlink(dir_, path("alias"));  // another name for the folder
  EXPECT_EQ(batch("'" + path("jobs.json") + "'"), 2) << err_;
  EXPECT_NE(err_.find("wavetrace: jobs 1 and 3 would write the same file " + path("alias/a.png") +
                      " (the output of job 1, the output of job 3); the batch is refused before any job runs"),
            std::string::npos)
      << err_;
  EXPECT_FALSE(fs::exists(path("a.png")));
  EXPECT_FALSE(fs::exists(path("b.png")));  // no job ran, not even the good one
}

// Scene files given directly are rendered to --output-dir by their stems: two of one stem collide.
TEST_F(BatchCommand, ScenesOfOneStemIntoOneFolderAreRefused) {
  for (const char* sub : {"a", "b", "out"}) fs::create_directories(dir_ / sub);
  fs::copy_file(path("s.json"), path("a/x.json"));
  fs::copy_file(path("s.json"), path("b/x.json"));
  EXPECT_EQ(batch("'" + path("a/x.json") + "' '" + path("b/x.json") + "' --output-dir '" + path("out") +
                  "' --backend cpu --width 32 --height 16 --spp 2"),
            2)
      << err_;
  EXPECT_NE(err_.find("jobs 1 and 2 would write the same file " + path("out/x.png")), std::string::npos) << err_;
  EXPECT_TRUE(fs::is_empty(path("out")));
}

// A key given twice in one job: that job fails (which of the two was meant is not
// known), the others run.
TEST_F(BatchCommand, ARepeatedKeyFailsItsJobAlone) {
  std::ofstream(path("jobs.json")) << R"({"defaults": {"backend": "cpu", "width": 32, "height": 16, "spp": 2},
    "jobs": [{"scene": "s.json", "output": "a.png", "seed": 1, "seed": 2}, {"scene": "s.json", "output": "b.png"}]})";
  EXPECT_EQ(batch("'" + path("jobs.json") + "'"), 1) << err_;
  EXPECT_FALSE(fs::exists(path("a.png")));
  EXPECT_TRUE(fs::exists(path("b.png")));
  EXPECT_EQ(count(out_, "FAILED: " + path("jobs.json") + ": /jobs/0/seed: duplicate key"), 1u) << out_;
  EXPECT_EQ(count(out_, "ok -> " + path("b.png")), 1u) << out_;
  EXPECT_NE(out_.find("\n2 jobs: 1 ok, 1 failed\n"), std::string::npos) << out_;
}

// A job whose checkpoint is its own image fails alone (the batch's other jobs do not
// share its files), and the file that was there is kept.
TEST_F(BatchCommand, AJobWhoseCheckpointIsItsImageFailsAlone) {
  std::ofstream(path("b.pfm")) << kPrecious;
  std::ofstream(path("jobs.json")) << R"({"defaults": {"backend": "cpu", "width": 32, "height": 16, "spp": 2},
    "jobs": [{"scene": "s.json", "output": "b.pfm", "checkpoint": "b.pfm"}, {"scene": "s.json", "output": "c.png"}]})";
  EXPECT_EQ(batch("'" + path("jobs.json") + "'"), 1) << err_;
  EXPECT_TRUE(fs::exists(path("c.png")));
  EXPECT_EQ(read(path("b.pfm")), kPrecious);
  EXPECT_EQ(count(out_, "FAILED: " + path("b.pfm") + ": output and checkpoint name the same file"), 1u) << out_;
  EXPECT_FALSE(fs::exists(path("b.pfm.lock")));
}

TEST_F(BatchCommand, AFolderOrAMissingFileAsItsInputIsBadInput) {
  fs::create_directories(dir_ / "jobs");
  EXPECT_EQ(batch("'" + path("jobs") + "'"), 2) << err_;
  EXPECT_EQ(err_, "wavetrace: " + path("jobs") + ": cannot read jobs file or scene file: it is a directory, not a file\n");
  EXPECT_EQ(batch("'" + path("missing.json") + "'"), 2) << err_;
  EXPECT_EQ(err_, "wavetrace: " + path("missing.json") + ": cannot open jobs file or scene file (No such file or "
                                                         "directory)\n");
}

// Not a hang: the FIFO is refused without waiting for a writer (timeout(1) ends the
// command should it wait, and the watchdog this test).
TEST_F(BatchCommand, AFifoAsItsInputIsBadInputAtOnce) {
  wt::test::Watchdog watchdog(std::chrono::seconds(60), "wavetrace batch FIFO");
  ASSERT_EQ(::mkfifo(path("jobs.json").c_str(), 0600), 0);
  EXPECT_EQ(wavetrace("batch '" + path("jobs.json") + "'", "", "timeout 30 "), 2) << err_;
  EXPECT_NE(err_.find(path("jobs.json") + ": cannot read jobs file or scene file: it is a FIFO (named pipe)"),
            std::string::npos)
      << err_;
}

TEST_F(BatchCommand, ARenderOfAFifoSceneIsBadInputAtOnce) {
  wt::test::Watchdog watchdog(std::chrono::seconds(60), "wavetrace render FIFO");
  ASSERT_EQ(::mkfifo(path("fifo.json").c_str(), 0600), 0);
  EXPECT_EQ(wavetrace("render '" + path("fifo.json") + "' -o '" + path("x.png") + "' --backend cpu -q", "",
                      "timeout 30 "),
            2)
      << err_;
  EXPECT_EQ(err_, "wavetrace: " + path("fifo.json") + ": cannot read scene file: it is a FIFO (named pipe), not a "
                                                      "regular file\n");
  EXPECT_FALSE(fs::exists(path("x.png")));
}

TEST_F(BatchCommand, AJobsFileWithDefaultsButNoJobsIsBadInput) {
  std::ofstream(path("jobs.json")) << R"({"defaults": {"backend": "cpu", "spp": 2}})";
  EXPECT_EQ(batch("'" + path("jobs.json") + "'"), 2) << err_;
  EXPECT_EQ(err_, "wavetrace: " + path("jobs.json") +
                      ": /jobs: required key is missing (a jobs file lists its jobs under \"jobs\")\n");
  // Neither a jobs file nor a scene.
  std::ofstream(path("other.json")) << R"({"job": []})";
  EXPECT_EQ(batch("'" + path("other.json") + "'"), 2) << err_;
  EXPECT_NE(err_.find(path("other.json") + ": neither a jobs file nor a scene file"), std::string::npos) << err_;
}

TEST_F(BatchCommand, AnUnknownCommandIsNamedWithTheCommands) {
  EXPECT_EQ(wavetrace("frobnicate"), 2);
  EXPECT_EQ(err_, "wavetrace: unknown command 'frobnicate' (the commands: render, batch, bench, convert, kernels)\n");
  EXPECT_EQ(out_, "");
}

// Mitsuba scenes through the command: a parameter from -D, a batch of XML and JSON
// scenes, convert, and each kind of bad file one line, exit 2 and no image.
TEST_F(BatchCommand, MitsubaScenesRenderWithParametersAndEachBadOneIsOneLine) {
  const std::string head = R"(<scene version="3.0.0">
  <default name="r" value="0.5"/>
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="constant"/>
)";
  std::ofstream(path("m.xml")) << head << R"(<shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="$r"/></bsdf></shape></scene>)";
  EXPECT_EQ(wavetrace("render '" + path("m.xml") + "' -o '" + path("m.pfm") + "' -D r=0.25 --backend cpu --spp 2 -q"), 0) << err_;
  EXPECT_TRUE(fs::exists(path("m.pfm")));
  EXPECT_EQ(wavetrace("render '" + path("m.xml") + "' -o '" + path("n.pfm") + "' -D 'r 0.25' --backend cpu -q"), 2);
  EXPECT_NE(err_.find("-D: 'r 0.25' is not name=value"), std::string::npos) << err_;
  EXPECT_EQ(wavetrace("convert '" + path("m.xml") + "' -o '" + path("j.json") + "' -D r=0.25"), 0) << err_;
  EXPECT_TRUE(fs::exists(path("j.json")));
  EXPECT_EQ(batch("'" + path("m.xml") + "' '" + path("j.json") + "' --output-dir '" + path("") + "' --backend cpu --spp 2"), 0)
      << err_;
  EXPECT_TRUE(fs::exists(path("m.png")));
  EXPECT_TRUE(fs::exists(path("j.png")));

  const struct {
    std::string body, message;
  } bad[] = {
      {"<shape type=\"sphere\"></scene", "malformed XML"},
      {"<shape type=\"teapot\"/></scene>", "teapot: shape type 'teapot' is not supported"},
      {"<shape type=\"obj\"><string name=\"filename\" value=\"none.obj\"/></shape></scene>", "obj: file 'none.obj' does not exist"},
      {"<shape type=\"sphere\"><transform name=\"to_world\"><shear/></transform></shape></scene>", "unknown operation <shear>"},
      {"<include filename=\"bad.xml\"/><shape type=\"sphere\"/></scene>", "includes itself"},
  };
  for (const auto& b : bad) {
    std::ofstream(path("bad.xml")) << head << b.body;
    EXPECT_EQ(wavetrace("render '" + path("bad.xml") + "' -o '" + path("bad.png") + "' --backend cpu -q"), 2) << b.body;
    EXPECT_NE(err_.find(path("bad.xml") + ":"), std::string::npos) << err_;
    EXPECT_NE(err_.find(b.message), std::string::npos) << err_;
    EXPECT_EQ(std::count(err_.begin(), err_.end(), '\n'), 1) << err_;
    EXPECT_FALSE(fs::exists(path("bad.png")));
  }
}

// A disk that fills up, for real: files of the command may not grow past one block
// (ulimit -f). The image's write fails with EFBIG, said in one line (SIGXFSZ, which
// would kill the process, is ignored), and no part of the image is left behind.
TEST_F(BatchCommand, ARenderPastTheFileSizeLimitFailsAndLeavesNoFile) {
  EXPECT_EQ(wavetrace("render '" + path("s.json") + "' -o '" + path("big.pfm") +
                          "' --backend cpu --width 32 --height 16 --spp 2 -q",
                      "ulimit -f 1; "),
            1)
      << err_;
  EXPECT_NE(err_.find(path("big.pfm") + ": cannot write (File too large)"), std::string::npos) << err_;
  EXPECT_FALSE(fs::exists(path("big.pfm")));
  for (const auto& e : fs::directory_iterator(dir_)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
  }
}

// --denoise: the output is Open Image Denoise's image of the render, closer to a
// converged render than the render itself, which --keep-noisy writes beside it as
// NAME.noisy.EXT (a 48 x 32 render of 4 samples a pixel against one of 1024: the
// squared error at least halved); the stats say so. Skipped where OIDN is absent.
TEST_F(BatchCommand, ADenoisedRenderIsCloserToTheConvergedImage) {
  std::string why;
  if (!wt::oidn_available(why)) GTEST_SKIP() << "Open Image Denoise absent: " << why;
  const std::string common = "' --backend cpu --width 48 --height 32 -q --seed 3";
  ASSERT_EQ(wavetrace("render '" + path("s.json") + "' -o '" + path("d.pfm") + common +
                      " --spp 4 --denoise --keep-noisy --stats '" + path("d.json") + "'"),
            0)
      << err_;
  ASSERT_EQ(wavetrace("render '" + path("s.json") + "' -o '" + path("ref.pfm") + common + " --spp 1024"), 0) << err_;
  const std::vector<float> denoised = wt::test::read_pfm(path("d.pfm"), 48, 32);
  const std::vector<float> noisy = wt::test::read_pfm(path("d.noisy.pfm"), 48, 32);
  const std::vector<float> ref = wt::test::read_pfm(path("ref.pfm"), 48, 32);
  ASSERT_EQ(denoised.size(), ref.size());
  ASSERT_EQ(noisy.size(), ref.size());
  double e_denoised = 0, e_noisy = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    e_denoised += (denoised[i] - ref[i]) * (denoised[i] - ref[i]);
    e_noisy += (noisy[i] - ref[i]) * (noisy[i] - ref[i]);
  }
  EXPECT_LT(e_denoised, 0.5 * e_noisy);
  const std::string stats = read(path("d.json"));
  EXPECT_NE(stats.find("\"denoise\""), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"device\": \"cpu\""), std::string::npos) << stats;
  EXPECT_NE(stats.find("d.noisy.pfm"), std::string::npos) << stats;
  // A jobs file's keys do the same.
  std::ofstream(path("jobs.json")) << R"({"jobs": [{"scene": "s.json", "output": "j.png", "backend": "cpu",
    "width": 16, "height": 8, "spp": 2, "denoise": true, "denoise_quality": "balanced", "keep_noisy": true}]})";
  EXPECT_EQ(batch("'" + path("jobs.json") + "'"), 0) << err_;
  EXPECT_TRUE(fs::exists(path("j.png")));
  EXPECT_TRUE(fs::exists(path("j.noisy.png")));
}

// Without Open Image Denoise (WAVETRACE_OIDN naming none), --denoise is one line and
// exit 2 before anything renders; --keep-noisy asks for --denoise; the noisy image is
// checked like every output (here: the checkpoint's name).
TEST_F(BatchCommand, DenoisingsBadInputIsOneLineAndNoFile) {
  const std::string render = "render '" + path("s.json") + "' -o '" + path("o.png") + "' --backend cpu --width 8 --height 8 --spp 1 -q";
  EXPECT_EQ(wavetrace(render + " --denoise", "export WAVETRACE_OIDN='" + path("no-such-oidn") + "'; "), 2) << err_;
  EXPECT_NE(err_.find("--denoise: Open Image Denoise is not installed"), std::string::npos) << err_;
  EXPECT_EQ(count(err_, "\n"), 1u) << err_;
  EXPECT_EQ(wavetrace(render + " --keep-noisy"), 2) << err_;
  EXPECT_NE(err_.find("--keep-noisy: keeps the render beside a denoised image: give --denoise too"), std::string::npos)
      << err_;
  std::string why;
  if (wt::oidn_available(why)) {
    EXPECT_EQ(wavetrace(render + " --denoise --keep-noisy --checkpoint '" + path("o.noisy.png") + "'"), 2) << err_;
    EXPECT_NE(err_.find("noisy output and checkpoint name the same file"), std::string::npos) << err_;
  }
  EXPECT_FALSE(fs::exists(path("o.png")));
  EXPECT_FALSE(fs::exists(path("o.noisy.png")));
}

// --aov: PFM files beside a PNG or PFM output, NAME.<aov>.pfm (the depth a
// one-channel "Pf"), and layers of an OpenEXR output that OpenEXR reads back under
// the names "<aov>.<channel>", holding the same values. Every kernel writes the same
// files (the pass follows the camera's rays, not a kernel's); the stats list them.
TEST_F(BatchCommand, AovsAreFilesBesideTheImageOrLayersOfItsExr) {
  const std::string aovs = " --aov albedo,normal,depth,position";
  const std::string common = "' --backend cpu --width 24 --height 16 --spp 4 -q --seed 5" + aovs;
  ASSERT_EQ(wavetrace("render '" + path("s.json") + "' -o '" + path("a.png") + common +
                      " --kernel megakernel --stats '" + path("a.json") + "'"),
            0)
      << err_;
  ASSERT_EQ(wavetrace("render '" + path("s.json") + "' -o '" + path("b.pfm") + common + " --kernel wavefront"), 0)
      << err_;
  for (const char* name : {"albedo", "normal", "depth", "position"}) {
    SCOPED_TRACE(name);
    const std::string a = read(path(std::string("a.") + name + ".pfm")), b = read(path(std::string("b.") + name + ".pfm"));
    EXPECT_FALSE(a.empty());
    EXPECT_EQ(a, b) << "the megakernel's and the wavefront's AOVs differ";
  }
  EXPECT_EQ(read(path("a.depth.pfm")).rfind("Pf\n24 16\n-1.0\n", 0), 0u);
  EXPECT_EQ(read(path("a.albedo.pfm")).rfind("PF\n24 16\n-1.0\n", 0), 0u);
  const std::string stats = read(path("a.json"));
  EXPECT_NE(stats.find("\"aovs\""), std::string::npos) << stats;
  EXPECT_NE(stats.find("a.position.pfm"), std::string::npos) << stats;

  ASSERT_EQ(wavetrace("render '" + path("s.json") + "' -o '" + path("c.exr") + common + " --exr-float"), 0) << err_;
  EXPECT_FALSE(fs::exists(path("c.albedo.pfm")));
  Imf::InputFile file(path("c.exr").c_str());
  std::vector<std::string> names;
  for (auto c = file.header().channels().begin(); c != file.header().channels().end(); ++c) names.push_back(c.name());
  EXPECT_EQ(names, (std::vector<std::string>{"A", "B", "G", "R", "albedo.B", "albedo.G", "albedo.R", "depth.Z",
                                             "normal.X", "normal.Y", "normal.Z", "position.X", "position.Y",
                                             "position.Z"}));
  // The layers hold what the PFMs hold (the same render: the same seed).
  const int w = 24, h = 16;
  std::vector<float> albedo(w * h * 3), depth(w * h);
  Imf::FrameBuffer frame;
  const char* rgb[] = {"albedo.R", "albedo.G", "albedo.B"};
  for (int c = 0; c < 3; ++c) {
    frame.insert(rgb[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(albedo.data() + c), 3 * sizeof(float),
                                    3 * sizeof(float) * w));
  }
  frame.insert("depth.Z", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(depth.data()), sizeof(float), sizeof(float) * w));
  file.setFrameBuffer(frame);
  file.readPixels(0, h - 1);
  EXPECT_EQ(albedo, wt::test::read_pfm(path("a.albedo.pfm"), w, h));
  // The depth PFM is one channel: read it as bytes after its header, bottom row first.
  const std::string d = read(path("a.depth.pfm"));
  const size_t header = std::string("Pf\n24 16\n-1.0\n").size();
  ASSERT_EQ(d.size(), header + depth.size() * sizeof(float));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float v;
      std::memcpy(&v, d.data() + header + (static_cast<size_t>(h - 1 - y) * w + x) * sizeof(float), sizeof v);
      EXPECT_EQ(v, depth[y * w + x]) << x << ", " << y;
    }
  }
  // The sphere fills the middle (about 3 units away), the corners see the sky.
  EXPECT_NEAR(depth[(h / 2) * w + w / 2], 3.0f, 0.1f);
  EXPECT_TRUE(std::isinf(depth[0]));

  // A jobs file's key does the same.
  std::ofstream(path("jobs.json")) << R"({"jobs": [{"scene": "s.json", "output": "j.png", "backend": "cpu",
    "width": 16, "height": 8, "spp": 2, "aov": "normal"}]})";
  EXPECT_EQ(batch("'" + path("jobs.json") + "'"), 0) << err_;
  EXPECT_TRUE(fs::exists(path("j.normal.pfm")));
}

// An unknown AOV, or a file an AOV would be written to that cannot be (a folder, or
// another of the job's files), is one line and exit 2 before anything renders; in a
// jobs file, the line names the file and the field.
TEST_F(BatchCommand, AovsBadInputIsOneLineAndNoFile) {
  const std::string render = "render '" + path("s.json") + "' -o '" + path("o.png") + "' --backend cpu --width 8 --height 8 --spp 1 -q";
  EXPECT_EQ(wavetrace(render + " --aov albedo,shadow"), 2) << err_;
  EXPECT_NE(err_.find("--aov: unknown AOV 'shadow' (known: albedo, normal, depth, position, variance, spp)"), std::string::npos) << err_;
  EXPECT_EQ(count(err_, "\n"), 1u) << err_;
  fs::create_directories(path("o.albedo.pfm"));
  EXPECT_EQ(wavetrace(render + " --aov albedo"), 2) << err_;
  EXPECT_NE(err_.find("o.albedo.pfm"), std::string::npos) << err_;
  EXPECT_EQ(count(err_, "\n"), 1u) << err_;
  EXPECT_EQ(wavetrace(render + " --aov normal --checkpoint '" + path("o.normal.pfm") + "'"), 2) << err_;
  EXPECT_NE(err_.find("normal AOV and checkpoint name the same file"), std::string::npos) << err_;
  EXPECT_FALSE(fs::exists(path("o.png")));
  EXPECT_FALSE(fs::exists(path("o.normal.pfm")));
  std::ofstream(path("jobs.json")) << R"({"jobs": [{"scene": "s.json", "output": "j.png", "backend": "cpu",
    "width": 8, "height": 8, "spp": 1, "aov": "depth,shadow"}]})";
  EXPECT_NE(batch("'" + path("jobs.json") + "'"), 0) << err_;
  EXPECT_NE(err_.find("/jobs/0/aov"), std::string::npos) << err_;
  EXPECT_NE(err_.find("unknown AOV 'shadow'"), std::string::npos) << err_;
  EXPECT_FALSE(fs::exists(path("j.png")));
  // A job whose image is another's AOV: the batch refuses both before either renders.
  std::ofstream(path("jobs2.json")) << R"({"jobs": [
    {"scene": "s.json", "output": "k.png", "backend": "cpu", "width": 8, "height": 8, "spp": 1, "aov": "depth"},
    {"scene": "s.json", "output": "k.depth.pfm", "backend": "cpu", "width": 8, "height": 8, "spp": 1}]})";
  EXPECT_EQ(batch("'" + path("jobs2.json") + "'"), 2) << err_;
  EXPECT_NE(err_.find("k.depth.pfm"), std::string::npos) << err_;
  EXPECT_FALSE(fs::exists(path("k.png")));
  EXPECT_FALSE(fs::exists(path("k.depth.pfm")));
}

// --noise-threshold: an adaptive render; its stats say how it ended, its spp AOV
// is each pixel's samples, the same whichever kernel renders it; a jobs file's
// noise_threshold and min_spp do the same.
TEST_F(BatchCommand, AnAdaptiveRenderSaysHowItEnded) {
  const std::string common = "' --backend cpu --width 24 --height 16 --spp 256 -q --seed 5 --noise-threshold 0.05"
                             " --min-spp 8 --aov spp,variance";
  ASSERT_EQ(wavetrace("render '" + path("s.json") + "' -o '" + path("a.pfm") + common + " --stats '" + path("a.json") +
                      "'"),
            0)
      << err_;
  ASSERT_EQ(wavetrace("render '" + path("s.json") + "' -o '" + path("b.pfm") + common + " --kernel wavefront"), 0)
      << err_;
  EXPECT_EQ(read(path("a.spp.pfm")), read(path("b.spp.pfm")));
  EXPECT_EQ(read(path("a.spp.pfm")).rfind("Pf\n24 16\n-1.0\n", 0), 0u);
  EXPECT_EQ(read(path("a.variance.pfm")).rfind("PF\n24 16\n-1.0\n", 0), 0u);
  const std::string stats = read(path("a.json"));
  EXPECT_NE(stats.find("\"adaptive\""), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"converged_pixels\""), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"noise_threshold\": 0.05"), std::string::npos) << stats;
  std::ofstream(path("jobs.json")) << R"({"jobs": [{"scene": "s.json", "output": "j.pfm", "backend": "cpu",
    "width": 16, "height": 8, "spp": 64, "noise_threshold": 0.1, "min_spp": 4, "aov": "spp"}]})";
  EXPECT_EQ(batch("'" + path("jobs.json") + "'"), 0) << err_;
  EXPECT_TRUE(fs::exists(path("j.spp.pfm")));
}

// A threshold that is not above 0 or above 1, min_spp above spp or without a
// threshold (the job's or the scene's): one line and exit 2, no file.
TEST_F(BatchCommand, AdaptiveSamplingsBadInputIsOneLineAndNoFile) {
  const std::string render = "render '" + path("s.json") + "' -o '" + path("o.png") + "' --backend cpu --width 8 --height 8 --spp 16 -q";
  for (const auto& [args, message] :
       {std::pair<std::string, std::string>{" --noise-threshold 0", "--noise-threshold: must be above 0 and at most 1 (got 0)"},
        {" --noise-threshold -0.5", "--noise-threshold: must be above 0 and at most 1 (got -0.5)"},
        {" --noise-threshold 1.5", "--noise-threshold: must be above 0 and at most 1 (got 1.5)"},
        {" --noise-threshold 0.1 --min-spp 32", "--min-spp: 32 is more than the 16 samples per pixel"},
        {" --min-spp 4", "--min-spp: the samples every pixel takes before adaptive sampling stops any; give --noise-threshold too"}}) {
    SCOPED_TRACE(args);
    EXPECT_EQ(wavetrace(render + args), 2) << err_;
    EXPECT_NE(err_.find(message), std::string::npos) << err_;
    EXPECT_EQ(count(err_, "\n"), 1u) << err_;
    EXPECT_FALSE(fs::exists(path("o.png")));
  }
  std::ofstream(path("jobs.json")) << R"({"jobs": [{"scene": "s.json", "output": "j.png", "backend": "cpu",
    "width": 8, "height": 8, "spp": 4, "noise_threshold": 0}]})";
  EXPECT_NE(batch("'" + path("jobs.json") + "'"), 0) << err_;
  EXPECT_NE(err_.find("/jobs/0/noise_threshold: must be above 0 and at most 1 (got 0)"), std::string::npos) << err_;
  EXPECT_FALSE(fs::exists(path("j.png")));
  // A scene's render section: its threshold checked where it is read, its min_spp
  // wanting a threshold.
  std::ofstream(path("t.json")) << R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]}, "render": {"noise_threshold": 2},
    "materials": [{"name": "m", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}],
    "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})";
  EXPECT_EQ(wavetrace("render '" + path("t.json") + "' -o '" + path("t.png") + "' --backend cpu -q"), 2) << err_;
  EXPECT_NE(err_.find("t.json: /render/noise_threshold: must be above 0 and at most 1 (got 2)"), std::string::npos) << err_;
  std::ofstream(path("m.json")) << R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]}, "render": {"min_spp": 8},
    "materials": [{"name": "m", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}],
    "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})";
  EXPECT_EQ(wavetrace("render '" + path("m.json") + "' -o '" + path("t.png") + "' --backend cpu -q"), 2) << err_;
  EXPECT_NE(err_.find("m.json: /render/min_spp: the samples every pixel takes before adaptive sampling stops any"),
            std::string::npos) << err_;
  EXPECT_EQ(count(err_, "\n"), 1u) << err_;
  EXPECT_FALSE(fs::exists(path("t.png")));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  if (argc > 1) g_wavetrace = argv[1];
  return RUN_ALL_TESTS();
}

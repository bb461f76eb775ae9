// The files a job writes (src/app/job_files.hpp): no two of a job's files may be one
// file, however it is spelled (the same string, "x/../", a relative path, a link, a
// hard link), since a render would overwrite one with the other; such a job is bad
// input (exit code 2) refused before it renders, and every file that was there
// before is left as it was. A checkpoint resumed and written back to is the one file
// it is meant to be. A checkpoint is locked for the render's life, whatever name it
// is given; the jobs of a batch may not write one file either; and a render's
// non-finite pixels are counted, in the stats too.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>

#include "app/checkpoint.hpp"
#include "app/job.hpp"
#include "app/job_files.hpp"
#include "errors/errors.hpp"
#include "job_support.hpp"
#include "test_support.hpp"

namespace wt::app {
namespace {

namespace fs = std::filesystem;

const char* kTinyScene = R"({
  "camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
  "materials": [{"name": "m", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}],
  "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]
})";

const std::string kPrecious = "bytes that were here before the job";

class JobFiles : public testing::Test {
 protected:
  void SetUp() override { scene_ = write("s.json", kTinyScene); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name), std::ios::binary) << text;
    return path(name);
  }

  static std::string bytes_of(const std::string& file) {
    std::ifstream f(file, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  }

  Job small_job(const std::string& output) const { return test::small_job(scene_, output); }

  // The names in the test's folder (links and folders included).
  std::set<std::string> names() const {
    std::set<std::string> n;
    for (const auto& e : fs::directory_iterator(dir_)) n.insert(e.path().filename().string());
    return n;
  }

  // The job is refused as bad input before it renders, with one line that holds
  // `parts`; the folder holds what it held before, byte for byte.
  void expect_refused_untouched(const Job& j, std::initializer_list<std::string> parts) {
    const std::set<std::string> before = names();
    std::vector<std::string> contents;
    for (const std::string& n : before) contents.push_back(fs::is_regular_file(path(n)) ? bytes_of(path(n)) : "");
    const JobOutcome o = run_job(j);
    EXPECT_EQ(o.exit_code, kExitBadInput) << o.message;
    EXPECT_EQ(o.message.find('\n'), std::string::npos) << "one line: " << o.message;
    for (const std::string& part : parts) EXPECT_NE(o.message.find(part), std::string::npos) << o.message;
    EXPECT_EQ(o.result.paths, 0u) << "nothing rendered";
    EXPECT_EQ(names(), before) << "no file written, none removed";
    size_t i = 0;
    for (const std::string& n : before) {
      if (fs::is_regular_file(path(n))) {
        EXPECT_EQ(bytes_of(path(n)), contents[i]) << n;
      }
      ++i;
    }
  }

  test::TestFolder folder_;
  const fs::path dir_ = folder_.root();
  std::string scene_;
};

const std::string kOwnFile = "; each of a render's files needs a file of its own";

TEST_F(JobFiles, OutputAndCheckpointOfOneNameAreRefusedBeforeTheRender) {
  Job j = small_job(write("b.pfm", kPrecious));
  j.checkpoint = j.output;
  expect_refused_untouched(j, {j.output + ": output and checkpoint name the same file (" + j.output + " and " +
                               j.output + ")" + kOwnFile});
  // Whether or not the file exists yet.
  fs::remove(j.output);
  expect_refused_untouched(j, {"output and checkpoint name the same file"});
}

TEST_F(JobFiles, AnotherSpellingThroughDotDotIsTheSameFile) {
  fs::create_directory(path("x"));
  Job j = small_job(write("b.pfm", kPrecious));
  j.checkpoint = path("x/../b.pfm");
  expect_refused_untouched(j, {"output and checkpoint name the same file (" + j.output + " and " + j.checkpoint + ")"});
  // Neither file there yet: the spellings are compared as paths.
  Job fresh = small_job(path("new.pfm"));
  fresh.stats = path("x/../x/./../new.json");
  fresh.checkpoint = path("./new.json");
  expect_refused_untouched(fresh, {"stats and checkpoint name the same file"});
}

TEST_F(JobFiles, ARelativeSpellingIsTheSameFile) {
  Job j = small_job(write("b.pfm", kPrecious));
  j.checkpoint = fs::relative(j.output, fs::current_path()).string();  // "../../tmp/...", from where the test runs
  ASSERT_NE(j.checkpoint, j.output);
  expect_refused_untouched(j, {"output and checkpoint name the same file"});
}

TEST_F(JobFiles, ASymbolicLinkToTheFileOrItsFolderIsTheSameFile) {
  Job j = small_job(write("b.pfm", kPrecious));
  fs::create_symlink(j.output, path("link.ckpt"));
  j.checkpoint = path("link.ckpt");
  expect_refused_untouched(j, {"output and checkpoint name the same file"});
  fs::create_directory_symlink(dir_, path("alias"));
  j.checkpoint = path("alias/b.pfm");
  expect_refused_untouched(j, {"output and checkpoint name the same file"});
  // A folder link to a file not there yet.
  Job fresh = small_job(path("new.pfm"));
  fresh.checkpoint = path("alias/new.pfm");
  expect_refused_untouched(fresh, {"output and checkpoint name the same file"});
}

TEST_F(JobFiles, AHardLinkOfTheFileIsTheSameFile) {
  Job j = small_job(write("b.pfm", kPrecious));
  fs::create_hard_link(j.output, path("hard.ckpt"));
  j.checkpoint = path("hard.ckpt");
  expect_refused_untouched(j, {"output and checkpoint name the same file (" + j.output + " and " + j.checkpoint + ")"});
}

// The stats written over the scene: the scene would be lost to its own render's stats.
TEST_F(JobFiles, StatsOverTheSceneAreRefused) {
  fs::create_hard_link(scene_, path("scene-too.json"));
  Job j = small_job(path("out.pfm"));
  j.stats = scene_;
  expect_refused_untouched(j, {scene_ + ": stats and scene name the same file (" + scene_ + " and " + scene_ + ")" +
                               kOwnFile});
  j.stats = path("scene-too.json");
  expect_refused_untouched(j, {"stats and scene name the same file"});
  EXPECT_EQ(bytes_of(scene_), kTinyScene);
}

TEST_F(JobFiles, AnOutputOverTheResumeFileIsRefused) {
  Job j = small_job(write("b.pfm", kPrecious));
  j.resume = j.output;
  expect_refused_untouched(j, {"output and resume name the same file"});
  // Also where the resume file is only read (a checkpoint of its own is written).
  j.checkpoint = path("c.ckpt");
  expect_refused_untouched(j, {"output and resume name the same file"});
}

TEST_F(JobFiles, StatsOverTheCheckpointAreRefused) {
  Job j = small_job(path("out.pfm"));
  j.stats = write("c.json", kPrecious);
  j.checkpoint = j.stats;
  expect_refused_untouched(j, {j.checkpoint + ": stats and checkpoint name the same file"});
}

// --checkpoint C --resume C: the checkpoint is resumed and written back to, as meant.
TEST_F(JobFiles, ACheckpointResumedAndWrittenBackToIsAllowed) {
  const JobOutcome first = run_job(small_job(path("first.pfm")));
  ASSERT_EQ(first.exit_code, 0) << first.message;
  Checkpoint c;
  c.identity = checkpoint_identity(scene_, {}, first.params, first.kernel, first.backend);
  c.samples = 1;
  c.film.assign(16 * 9 * 3, 0.5f);
  write_checkpoint(path("c.ckpt"), c);
  Job j = small_job(path("out.pfm"));
  j.checkpoint = path("c.ckpt");
  j.resume = path("x/../c.ckpt");  // and in another spelling
  fs::create_directory(path("x"));
  const JobOutcome o = run_job(j);
  ASSERT_EQ(o.exit_code, 0) << o.message;
  EXPECT_EQ(o.resumed_from_sample, 1);
  EXPECT_TRUE(fs::exists(path("out.pfm")));
  EXPECT_FALSE(fs::exists(path("c.ckpt")));  // done with once the image is written
  EXPECT_FALSE(fs::exists(path("c.ckpt.lock")));
}

// Refused before the scene loads, as a bad output path is: not after the render,
// when its first checkpoint would be written.
TEST_F(JobFiles, ACheckpointInAMissingFolderIsRefusedAtOnce) {
  Job j = small_job(path("out.pfm"));
  j.checkpoint = path("nodir/c.ckpt");
  j.spp = 1000000;  // a render that would take long, were it started
  expect_refused_untouched(j, {j.checkpoint + ": cannot write: folder '" + path("nodir") + "' does not exist"});
  EXPECT_FALSE(fs::exists(path("nodir")));
  j.checkpoint.clear();
  j.resume = path("nodir/c.ckpt");  // a resume file written back to is checked alike
  expect_refused_untouched(j, {"nodir"});
}

// ---- The checkpoint's lock ----

TEST_F(JobFiles, ASecondLockOnACheckpointIsRefusedWhateverItsSpelling) {
  fs::create_directory_symlink(dir_, path("alias"));
  CheckpointLock held(path("c.ckpt"));
  EXPECT_TRUE(fs::exists(path("c.ckpt.lock")));
  for (const std::string& spelling : {path("c.ckpt"), path("alias/c.ckpt"), path("alias/../" +
                                                                                   dir_.filename().string() +
                                                                                   "/c.ckpt")}) {
    try {
      CheckpointLock second(spelling);
      ADD_FAILURE() << spelling << ": locked twice";
    } catch (const OutputError& e) {
      EXPECT_EQ(std::string(e.what()), spelling + ": the checkpoint is in use by another render of this process; "
                                                      "two renders cannot share one checkpoint");
    }
  }
  EXPECT_TRUE(fs::exists(path("c.ckpt.lock"))) << "a refused lock leaves the held one's file";
}

TEST_F(JobFiles, TheLockFileGoesWithTheLockAndTheCheckpointCanBeLockedAgain) {
  {
    CheckpointLock first(path("c.ckpt"));
    ASSERT_TRUE(fs::exists(path("c.ckpt.lock")));
  }
  EXPECT_FALSE(fs::exists(path("c.ckpt.lock")));
  {
    CheckpointLock again(path("c.ckpt"));
    EXPECT_TRUE(fs::exists(path("c.ckpt.lock")));
    CheckpointLock moved(std::move(again));  // the lock moves with the object, and is let go once
  }
  EXPECT_FALSE(fs::exists(path("c.ckpt.lock")));
  EXPECT_NO_THROW(CheckpointLock(path("c.ckpt")));
}

// The lock is the kernel's (flock): another process cannot take it, and names the holder.
TEST_F(JobFiles, ACheckpointLockedByThisProcessIsRefusedInAnother) {
  CheckpointLock held(path("c.ckpt"));
  const std::string result = test::in_child_process([&] {
    try {
      CheckpointLock second(path("c.ckpt"));
    } catch (const OutputError& e) {
      return std::string(e.what());
    }
    return std::string("locked in the child too");
  });
  EXPECT_EQ(result, path("c.ckpt") + ": the checkpoint is in use by another render (wavetrace pid " +
                        std::to_string(::getpid()) + "); two renders cannot share one checkpoint");
}

TEST_F(JobFiles, AJobWhoseCheckpointIsInUseIsRefusedAndLeavesItAlone) {
  CheckpointLock held(path("c.ckpt"));
  Job j = small_job(path("out.pfm"));
  j.checkpoint = path("c.ckpt");
  const JobOutcome o = run_job(j);
  EXPECT_EQ(o.exit_code, kExitBadInput) << o.message;
  EXPECT_NE(o.message.find(path("c.ckpt") + ": the checkpoint is in use by another render"),
            std::string::npos)
      << o.message;
  EXPECT_FALSE(fs::exists(path("out.pfm")));
  EXPECT_TRUE(fs::exists(path("c.ckpt.lock"))) << "the holder's lock file stays";
}

// ---- The jobs of a batch ----

TEST_F(JobFiles, TwoJobsWritingOneImageCollide) {
  EXPECT_EQ(colliding_jobs({small_job(path("a.png")), small_job(path("a.png"))}, {false, false}),
            "jobs 1 and 2 would write the same file " + path("a.png") +
                " (the output of job 1, the output of job 2); the batch is refused before any job runs");
}

TEST_F(JobFiles, OneJobsStatsOverAnothersImageCollide) {
  Job a = small_job(path("a.png"));
  a.stats = path("x.json");
  Job b = small_job(path("b.png"));
  Job c = small_job(path("c.png"));
  c.checkpoint = path("x.json");
  EXPECT_EQ(colliding_jobs({a, b, c}, {false, false, false}),
            "jobs 1 and 3 would write the same file " + path("x.json") +
                " (the stats of job 1, the checkpoint of job 3); the batch is refused before any job runs");
  // In another spelling too.
  fs::create_directory(path("d"));
  c.checkpoint = path("d/../x.json");
  EXPECT_NE(colliding_jobs({a, b, c}, {false, false, false}).find("jobs 1 and 3 would write the same file"),
            std::string::npos);
}

// A job refused when it was read never runs: it writes nothing that could collide.
TEST_F(JobFiles, RefusedJobsTakeNoPartInCollisions) {
  const std::vector<Job> jobs = {small_job(path("a.png")), small_job(path("a.png")), small_job(path("a.png"))};
  EXPECT_EQ(colliding_jobs(jobs, {true, false, true}), "");
  EXPECT_NE(colliding_jobs(jobs, {true, false, false}).find("jobs 2 and 3 "), std::string::npos);
}

TEST_F(JobFiles, JobsOfDistinctFilesDoNotCollide) {
  Job a = small_job(path("a.png"));
  a.stats = path("a.json");
  a.checkpoint = path("a.ckpt");
  Job b = small_job(path("b.png"));
  b.stats = path("b.json");
  b.resume = path("b.ckpt");
  // Both read one scene: reading is not writing.
  EXPECT_EQ(colliding_jobs({a, b}, {false, false}), "");
  // A job's own files are its own check's (run_job refuses that job alone).
  Job own = small_job(path("c.png"));
  own.checkpoint = path("c.png");
  EXPECT_EQ(colliding_jobs({a, own}, {false, false}), "");
}

// A file one job writes may not be one another job reads: job 1's stats would
// replace job 2's scene before job 2 reads it (a job alone is refused for this,
// StatsOverTheSceneAreRefused), and job 1's image another's resume file. Files only
// read may be shared.
TEST_F(JobFiles, AFileOneJobWritesMayNotBeOneAnotherReads) {
  const std::string other_scene = write("s2.json", kTinyScene);
  Job a = small_job(path("a.png"));
  a.stats = other_scene;
  Job b = small_job(path("b.png"));
  b.scene = other_scene;
  EXPECT_EQ(colliding_jobs({a, b}, {false, false}),
            "jobs 1 and 2 would write and read the same file " + other_scene + " (the stats of job 1, the scene of job 2)"
            "; the batch is refused before any job runs");
  EXPECT_NE(colliding_jobs({b, a}, {false, false}), "") << "whichever job comes first";
  Job resumer = small_job(path("c.png"));
  resumer.resume = path("r.ckpt");
  resumer.checkpoint = path("c.ckpt");  // the resume file is only read
  Job writer = small_job(path("r.ckpt.png"));
  writer.stats = path("r.ckpt");
  EXPECT_NE(colliding_jobs({resumer, writer}, {false, false}).find("the resume of job 1, the stats of job 2"),
            std::string::npos);
  Job reader = small_job(path("d.png"));  // the same scene as a: read by both
  EXPECT_EQ(colliding_jobs({small_job(path("e.png")), reader}, {false, false}), "");
}

// ---- Non-finite pixels ----

TEST(NonfinitePixels, CountsPixelsWithANanOrAnInfinityInAnyChannel) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(count_nonfinite_pixels({}), 0u);
  EXPECT_EQ(count_nonfinite_pixels({0, 0, 0, 1e30f, 2, 3}), 0u);
  // Each kind in each channel; a pixel with several counts once.
  EXPECT_EQ(count_nonfinite_pixels({nan, 0, 0, 0, inf, 0, 0, 0, -inf, 1, 1, 1, nan, inf, nan}), 4u);
}

TEST_F(JobFiles, AGoodJobsStatsSayItHasNoNonfinitePixels) {
  Job j = small_job(path("out.pfm"));
  j.stats = path("stats.json");
  const JobOutcome o = run_job(j);
  ASSERT_EQ(o.exit_code, 0) << o.message;
  EXPECT_EQ(o.nonfinite_pixels, 0u);
  const nlohmann::json stats = nlohmann::json::parse(std::ifstream(path("stats.json")));
  ASSERT_TRUE(stats.contains("nonfinite_pixels")) << stats.dump();
  EXPECT_EQ(stats["nonfinite_pixels"], 0);
}

}  // namespace
}  // namespace wt::app

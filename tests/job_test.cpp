// The command's jobs as a user meets them: bad input is one line, exit code 2 and
// no output file; a good job writes its image and stats; a batch goes on past a
// failing job and says so in its exit code.
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stb/stb_image.h>

#include "app/batch.hpp"
#include "app/bench.hpp"
#include "app/job.hpp"
#include "errors/errors.hpp"
#include "exr_support.hpp"
#include "wavetrace/film.hpp"
#include "job_support.hpp"
#include "test_support.hpp"

namespace wt::app {
namespace {

namespace fs = std::filesystem;

class JobTest : public testing::Test {
 protected:

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
    return path(name);
  }

  Job small_job(const std::string& scene, const std::string& output) const { return test::small_job(scene, output); }

  bool only_expected_files(std::initializer_list<std::string> names) const {
    size_t n = 0;
    for (const auto& e : fs::directory_iterator(dir_)) {
      ++n;
      if (std::find(names.begin(), names.end(), e.path().filename().string()) == names.end()) return false;
    }
    return n == names.size();
  }

  test::TestFolder folder_;
  const fs::path dir_ = folder_.root();
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
  for (const char* phase : {"parse", "validate", "texture_load", "bvh_build", "upload"}) {
    ASSERT_TRUE(stats["load_seconds"].contains(phase)) << phase;
    EXPECT_GE(stats["load_seconds"][phase].get<double>(), 0.0) << phase;
  }
  EXPECT_GT(stats["load_seconds"]["parse"].get<double>(), 0.0);
  EXPECT_TRUE(only_expected_files({"s.json", "out.png", "stats.json"}));
}

// The PFM holds the render's linear means as they are, bottom row first, and nothing
// after them; the PNG of the same job is those values through the sRGB curve.
TEST_F(JobTest, PfmOutputHoldsLinearFloats) {
  Job j = small_job(write("s.json", kTinyScene), path("out.pfm"));
  const JobOutcome o = run_job(j);
  ASSERT_EQ(o.exit_code, 0) << o.message;
  ASSERT_EQ(o.result.rgb.size(), 16u * 9 * 3);
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
  ASSERT_TRUE(f.good());
  EXPECT_EQ(f.peek(), std::char_traits<char>::eof()) << "bytes after the pixels";
  size_t lit = 0;
  for (int y = 0; y < 9; ++y) {
    for (int x = 0; x < 16 * 3; ++x) {
      const float in_file = data[static_cast<size_t>(8 - y) * 16 * 3 + x];
      ASSERT_EQ(in_file, o.result.rgb[static_cast<size_t>(y) * 16 * 3 + x]) << "row " << y << " value " << x;
      lit += in_file > 0.0f;
    }
  }
  EXPECT_GT(lit, 16u * 9) << "an image with light in it";
  // Linear: the PNG's bytes are the same values encoded.
  j.output = path("out.png");
  const JobOutcome png = run_job(j);
  ASSERT_EQ(png.exit_code, 0) << png.message;
  int pw = 0, ph = 0, channels = 0;
  unsigned char* bytes = stbi_load(path("out.png").c_str(), &pw, &ph, &channels, 3);
  ASSERT_NE(bytes, nullptr);
  for (size_t i = 0; i < data.size(); ++i) {
    const size_t y = i / (16 * 3), x = i % (16 * 3);
    const float linear = data[(8 - y) * 16 * 3 + x];
    EXPECT_EQ(bytes[i], static_cast<unsigned char>(std::lround(encode_srgb(linear) * 255.0f))) << i;
  }
  stbi_image_free(bytes);
}

void expect_bad_input(const JobOutcome& o, const std::string& must_contain) {
  EXPECT_EQ(o.exit_code, kExitBadInput);
  EXPECT_NE(o.message.find(must_contain), std::string::npos) << o.message;
  EXPECT_EQ(o.message.find('\n'), std::string::npos) << "one line: " << o.message;
}

// The same render as a PFM and as OpenEXR, half and float: the EXR holds the PFM's
// values (half-rounded by default, exact with exr_float) at the same pixels.
TEST_F(JobTest, ExrOutputHoldsTheRendersLinearValues) {
  const std::string scene = write("s.json", kTinyScene);
  ASSERT_EQ(run_job(small_job(scene, path("out.pfm"))).exit_code, 0);
  const std::vector<float> pfm = test::read_pfm(path("out.pfm"), 16, 9);
  ASSERT_EQ(pfm.size(), 16u * 9 * 3);
  Job half_job = small_job(scene, path("half.exr"));
  Job float_job = small_job(scene, path("float.exr"));
  float_job.exr_float = true;
  ASSERT_EQ(run_job(half_job).exit_code, 0);
  ASSERT_EQ(run_job(float_job).exit_code, 0);
  const test::ExrImage half_image = test::read_exr(path("half.exr")), float_image = test::read_exr(path("float.exr"));
  EXPECT_EQ(half_image.types, std::vector<Imf::PixelType>(4, Imf::HALF));
  EXPECT_EQ(float_image.types, std::vector<Imf::PixelType>(4, Imf::FLOAT));
  ASSERT_EQ(half_image.rgba.size(), 16u * 9 * 4);
  ASSERT_EQ(float_image.rgba.size(), 16u * 9 * 4);
  size_t lit = 0;
  for (size_t p = 0; p < 16 * 9; ++p) {
    for (size_t c = 0; c < 3; ++c) {
      EXPECT_EQ(half_image.rgba[p * 4 + c], test::half_rounded(pfm[p * 3 + c])) << "pixel " << p;
      EXPECT_EQ(float_image.rgba[p * 4 + c], pfm[p * 3 + c]) << "pixel " << p;
      lit += pfm[p * 3 + c] > 0.0f;
    }
    EXPECT_EQ(half_image.rgba[p * 4 + 3], 1.0f);
    EXPECT_EQ(float_image.rgba[p * 4 + 3], 1.0f);
  }
  EXPECT_GT(lit, 0u);  // the render is not black
  EXPECT_TRUE(only_expected_files({"s.json", "out.pfm", "half.exr", "float.exr"}));
}

TEST_F(JobTest, MissingSceneFileIsBadInputAndWritesNothing) {
  expect_bad_input(run_job(small_job(path("nope.json"), path("out.png"))), "nope.json");
  EXPECT_TRUE(only_expected_files({}));
}

TEST_F(JobTest, UnknownMaterialIsBadInputAndWritesNothing) {
  std::string scene = write("s.json", R"({
    "camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
    "materials": [{"name": "m", "type": "vinyl"}],
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

// A disk that fills up while the stats file is written, after the image: in a child
// process whose files may not grow past a limit between the two files' sizes
// (test::limit_file_size: the write fails with EFBIG, as with ENOSPC).
TEST_F(JobTest, DiskFullWhileWritingStatsFailsTheJobAndWritesNeitherFile) {
  Job j = small_job(write("s.json", kTinyScene), path("out.png"));
  j.stats = path("stats.json");
  ASSERT_EQ(run_job(j).exit_code, 0);
  const uintmax_t image_bytes = fs::file_size(j.output), stats_bytes = fs::file_size(j.stats);
  ASSERT_LT(image_bytes + 64, stats_bytes);  // room for a limit between them
  fs::remove(j.output);
  fs::remove(j.stats);
  Job fits = small_job(j.scene, path("fits.png"));
  const std::string result = test::in_child_process([&] {
    if (!test::limit_file_size((image_bytes + stats_bytes) / 2)) return std::string("setrlimit failed");
    const JobOutcome o = run_job(j);
    // A batch goes on to the next job, whose image fits.
    const int batch = run_batch({{j, ""}, {fits, ""}});
    return std::to_string(o.exit_code) + " " + o.message + " | batch " + std::to_string(batch);
  });
  EXPECT_EQ(result, std::to_string(kExitFailure) + " " + j.stats + ": cannot write (" + std::strerror(EFBIG) +
                        ") | batch " + std::to_string(kExitFailure));
  EXPECT_TRUE(only_expected_files({"s.json", "fits.png"}));  // no image, no stats, no temporary file
}

// Host memory that runs out during a job (std::bad_alloc) fails that job alone: in a
// child process whose address space is capped 1 GiB above what it uses, a 16384 x
// 16384 film (3 GiB) cannot be allocated; the next job runs.
TEST_F(JobTest, OutOfHostMemoryFailsOnlyThatJob) {
  if (test::kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer's shadow memory cannot run under RLIMIT_AS";
  Job huge = small_job(write("s.json", kTinyScene), path("huge.pfm"));
  huge.width = 16384;
  huge.height = 16384;
  huge.spp = 1;
  huge.threads = 2;  // few threads: their stacks count against the cap
  Job next = small_job(huge.scene, path("next.png"));
  next.threads = 2;
  const std::string result = test::in_child_process([&] {
    long pages = 0;
    std::ifstream("/proc/self/statm") >> pages;  // the address space in use
    const rlim_t cap = static_cast<rlim_t>(pages) * ::sysconf(_SC_PAGESIZE) + (rlim_t(1) << 30);
    const rlimit r{cap, cap};
    if (::setrlimit(RLIMIT_AS, &r) != 0) return std::string("setrlimit failed");
    const JobOutcome o = run_job(huge);
    return std::to_string(o.exit_code) + " " + o.message + " | batch " + std::to_string(run_batch({{huge, ""}, {next, ""}}));
  });
  EXPECT_EQ(result, std::to_string(kExitFailure) + " out of host memory (std::bad_alloc) | batch " +
                        std::to_string(kExitFailure));
  EXPECT_TRUE(only_expected_files({"s.json", "next.png"}));
}

TEST_F(JobTest, MalformedJobsFileIsRejected) {
  std::string jobs = write("jobs.json", R"({"jobs": [)");
  EXPECT_THROW(read_jobs_file(jobs, Job{}), InputError);
}

// What a reader threw, or "" when it did not.
template <class F>
std::string error_of(F&& read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST_F(JobTest, JobsFilesTakeTheSettingsTableRanges) {
  std::string jobs = write("jobs.json", R"({"jobs": [
    {"scene": "s.json", "output": "a.png", "seed": 4294967295, "roulette_depth": 1073741824, "threads": 3},
    {"scene": "s.json", "output": "b.png", "seed": 4294967296},
    {"scene": "s.json", "output": "c.png", "roulette_depth": 1073741825},
    {"scene": "s.json", "output": "d.png", "kernel": "megakernal"}]})");
  std::vector<PlannedJob> planned = read_jobs_file(jobs, Job{});
  ASSERT_EQ(planned.size(), 4u);
  EXPECT_EQ(planned[0].error, "");
  EXPECT_EQ(planned[0].job.seed, 4294967295);
  EXPECT_EQ(planned[0].job.roulette_depth, 1 << 30);
  EXPECT_EQ(planned[0].job.threads, 3);
  EXPECT_EQ(planned[1].error, jobs + ": /jobs/1/seed: must be an integer in 0..4294967295 (got 4294967296)");
  EXPECT_EQ(planned[2].error,
            jobs + ": /jobs/2/roulette_depth: must be an integer in 0..1073741824 (got 1073741825)");
  EXPECT_NE(planned[3].error.find("/jobs/3/kernel: unknown value 'megakernal' (expected megakernel, "),
            std::string::npos)
      << planned[3].error;
}

TEST_F(JobTest, AJobsDefinesAreAMitsubaScenesParameters) {
  std::string jobs = write("jobs.json", R"({"defaults": {"defines": {"spp": 8}}, "jobs": [
    {"scene": "s.xml", "output": "a.png", "defines": {"albedo": "0.5, 0.2, 0.1", "n": 3}},
    {"scene": "s.xml", "output": "b.png"},
    {"scene": "s.xml", "output": "c.png", "defines": {"bad name": "1"}},
    {"scene": "s.xml", "output": "d.png", "defines": {"x": [1]}},
    {"scene": "s.xml", "output": "e.png", "defines": {"a=b": "1"}}]})");
  std::vector<PlannedJob> planned = read_jobs_file(jobs, Job{});
  ASSERT_EQ(planned.size(), 5u);
  EXPECT_EQ(planned[0].error, "");
  // A job's defines replace the defaults' whole, as any key does.
  EXPECT_EQ(planned[0].job.defines, (std::map<std::string, std::string>{{"albedo", "0.5, 0.2, 0.1"}, {"n", "3"}}));
  EXPECT_EQ(planned[1].job.defines, (std::map<std::string, std::string>{{"spp", "8"}}));
  EXPECT_NE(planned[2].error.find("/jobs/2/defines/bad name: a parameter's name is letters, digits and _"), std::string::npos)
      << planned[2].error;
  EXPECT_NE(planned[3].error.find("/jobs/3/defines/x: must be a string or a number"), std::string::npos) << planned[3].error;
  EXPECT_NE(planned[4].error.find("/jobs/4/defines/a=b: a parameter's name is letters, digits and _"), std::string::npos)
      << planned[4].error;
}

TEST_F(JobTest, SceneFilesAndRenderSettingsShareTheRanges) {
  // The same roulette_depth and seed limits as the jobs file above.
  std::string text = kTinyScene;
  text.insert(text.rfind('}'), R"(, "render": {"seed": 4294967295, "roulette_depth": 1073741825})");
  std::string scene = write("s.json", text);
  EXPECT_EQ(error_of([&] { load_scene(scene); }),
            scene + ": /render/roulette_depth: must be an integer in 0..1073741824 (got 1073741825)");
  RenderParams p = RenderDefaults();
  p.roulette_depth = (1 << 30) + 1;
  EXPECT_EQ(error_of([&] { validate_params(p); }), "roulette_depth: must be in 0..1073741824 (got 1073741825)");
  p.roulette_depth = 1 << 30;
  p.seed = 4294967295u;
  EXPECT_EQ(error_of([&] { validate_params(p); }), "");
}

TEST_F(JobTest, JobsFilesTakeExrFloatAsABoolean) {
  std::string jobs = write("jobs.json", R"({"defaults": {"exr_float": true}, "jobs": [
    {"scene": "s.json", "output": "a.exr"},
    {"scene": "s.json", "output": "b.exr", "exr_float": false},
    {"scene": "s.json", "output": "c.exr", "exr_float": 1}]})");
  std::vector<PlannedJob> planned = read_jobs_file(jobs, Job{});
  ASSERT_EQ(planned.size(), 3u);
  EXPECT_EQ(planned[0].error, "");
  EXPECT_TRUE(planned[0].job.exr_float);
  EXPECT_EQ(planned[1].error, "");
  EXPECT_FALSE(planned[1].job.exr_float);
  EXPECT_EQ(planned[2].error, jobs + ": /jobs/2/exr_float: must be true or false (got number)");
  EXPECT_FALSE(read_jobs_file(write("jobs.json", R"({"jobs": [{"scene": "s.json", "output": "a.exr"}]})"), Job{})[0]
                   .job.exr_float);
}

TEST_F(JobTest, JobsFilesRejectRepeatedAndUnknownKeys) {
  // A key repeated inside one job fails that job alone; outside the jobs, the file.
  std::string jobs = write("jobs.json", R"({"jobs": [{"scene": "a.json", "scene": "b.json", "output": "o.png"},
    {"scene": "a.json", "output": "p.png", "spp": 2, "spp": 3}, {"scene": "a.json", "output": "q.png"},
    {"scene": "a.json", "output": "r.png", "more": {"x": 1, "x": 2}}]})");
  std::vector<PlannedJob> planned = read_jobs_file(jobs, Job{});
  ASSERT_EQ(planned.size(), 4u);
  EXPECT_EQ(planned[0].error, jobs + ": /jobs/0/scene: duplicate key");
  EXPECT_EQ(planned[1].error, jobs + ": /jobs/1/spp: duplicate key");
  EXPECT_EQ(planned[2].error, "");
  EXPECT_EQ(planned[2].job.output, path("q.png"));
  EXPECT_EQ(planned[3].error, jobs + ": /jobs/3/more/x: duplicate key");
  jobs = write("jobs.json", R"({"defaults": {"spp": 2, "spp": 3}, "jobs": [{"scene": "a.json", "output": "o.png"}]})");
  EXPECT_EQ(error_of([&] { read_jobs_file(jobs, Job{}); }), jobs + ": /defaults/spp: duplicate key");
  jobs = write("jobs.json", R"({"jobs": [], "jobs": []})");
  EXPECT_EQ(error_of([&] { read_jobs_file(jobs, Job{}); }), jobs + ": /jobs: duplicate key");
  jobs = write("jobs.json", R"({"jobs": [], "default": {}})");
  EXPECT_EQ(error_of([&] { read_jobs_file(jobs, Job{}); }),
            jobs + ": /default: unknown key (expected jobs, defaults)");
  jobs = write("jobs.json", R"({"defaults": {"spp": "many"}, "jobs": []})");
  EXPECT_EQ(error_of([&] { read_jobs_file(jobs, Job{}); }),
            jobs + ": /defaults/spp: must be an integer in 1..1000000 (got string)");
}

const char* kSpec = R"({"warmup": 0, "repeats": 5, "check_spp": 1, "check_bound": 0.01,
  "groups": [
    {"name": "a", "scene": "scenes/s.json", "kernels": ["megakernel", "wavefront"],
     "configs": [{"width": 64, "height": 32, "spp": 2, "depth": 5},
                 {"width": 8, "height": 8, "spp": 1, "depth": 9, "roulette_depth": 3, "seed": 4294967295}]},
    {"name": "b", "scene": "t.json", "kernels": ["wavefront-unsorted"],
     "configs": [{"width": 16, "height": 16, "spp": 4, "depth": 2},
                 {"width": 16, "height": 16, "spp": 64, "depth": 2, "noise_threshold": 0.05, "min_spp": 8}]}]})";

TEST_F(JobTest, BenchSpecIsReadWithItsDefaults) {
  std::string spec = write("spec.json", kSpec);
  BenchSpec s = read_bench_spec(spec, "");
  EXPECT_EQ(s.warmup, 0);
  EXPECT_EQ(s.repeats, 5);
  EXPECT_EQ(s.check_spp, 1);
  EXPECT_DOUBLE_EQ(s.check_bound, 0.01);
  ASSERT_EQ(s.points.size(), 4u);
  EXPECT_EQ(s.points[0].noise_threshold, 0.0);
  EXPECT_EQ(s.points[3].noise_threshold, 0.05);
  EXPECT_EQ(s.points[3].min_spp, 8);
  const BenchPoint& p0 = s.points[0];
  EXPECT_EQ(p0.group, "a");
  EXPECT_EQ(p0.scene, path("scenes/s.json"));  // relative to the spec's folder
  EXPECT_EQ(p0.kernels, (std::vector<std::string>{"megakernel", "wavefront"}));
  EXPECT_EQ(p0.params.width, 64);
  EXPECT_EQ(p0.params.height, 32);
  EXPECT_EQ(p0.params.spp, 2);
  EXPECT_EQ(p0.params.depth, 5);
  EXPECT_EQ(p0.params.roulette_depth, 5);  // none given: the depth, so no roulette
  EXPECT_EQ(p0.params.seed, 1u);
  EXPECT_EQ(s.points[1].params.roulette_depth, 3);
  EXPECT_EQ(s.points[1].params.seed, 4294967295u);
  BenchSpec only_b = read_bench_spec(spec, "b");
  ASSERT_EQ(only_b.points.size(), 2u);
  EXPECT_EQ(only_b.points[0].kernels, std::vector<std::string>{"wavefront-unsorted"});
  EXPECT_EQ(error_of([&] { read_bench_spec(spec, "c"); }), spec + ": no points to run in group c");
}

// A config with a noise threshold times the kernels' adaptive renders, each row
// saying what they took: the same samples for every kernel of the CPU backend.
TEST_F(JobTest, ABenchConfigWithANoiseThresholdTimesAdaptiveRenders) {
  const std::string spec = write("adaptive.json", R"({"warmup": 0, "repeats": 1, "check_spp": 1,
    "groups": [{"name": "a", "scene": ")" + test::repo_path("scenes/quick.json") + R"(",
      "kernels": ["megakernel", "wavefront"],
      "configs": [{"width": 24, "height": 16, "spp": 128, "depth": 4, "noise_threshold": 0.1, "min_spp": 8}]}]})");
  BenchOptions o;
  o.spec = spec;
  o.out_dir = path("out");
  o.backend = "cpu";
  ASSERT_EQ(run_bench(o), 0);
  std::ifstream f(path("out/results.json"));
  const nlohmann::json results = nlohmann::json::parse(f);
  ASSERT_EQ(results["points"].size(), 2u);
  for (const nlohmann::json& row : results["points"]) {
    SCOPED_TRACE(row["kernel"].get<std::string>());
    EXPECT_EQ(row["status"], "ok");
    EXPECT_EQ(row["noise_threshold"], 0.1);
    EXPECT_EQ(row["min_spp"], 8);
    EXPECT_GE(row["mean_spp"].get<double>(), 8.0);
    EXPECT_LT(row["mean_spp"].get<double>(), 128.0);
    EXPECT_EQ(row["mean_spp"], results["points"][0]["mean_spp"]);
  }
  std::ifstream csv(path("out/results.csv"));
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find(",noise_threshold,mean_spp"), std::string::npos) << header;
}

TEST_F(JobTest, BenchSpecMistakesNameTheirPath) {
  auto error_with = [&](const std::string& from, const std::string& to) {
    std::string text = kSpec;
    size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    std::string spec = write("spec.json", text.replace(at, from.size(), to));
    return error_of([&] { read_bench_spec(spec, ""); });
  };
  const std::string spec = path("spec.json");
  EXPECT_EQ(error_with("\"roulette_depth\": 3", "\"roulete_depth\": 3"),
            spec + ": /groups/0/configs/1/roulete_depth: unknown key (expected width, height, spp, depth, "
                   "roulette_depth, seed, nee, min_spp, noise_threshold)");
  EXPECT_EQ(error_with("\"noise_threshold\": 0.05", "\"noise_threshold\": 0"),
            spec + ": /groups/1/configs/1/noise_threshold: must be above 0 and at most 1 (got 0)");
  EXPECT_EQ(error_with("\"noise_threshold\": 0.05, ", ""),
            spec + ": /groups/1/configs/1/min_spp: adaptive sampling's first samples: give noise_threshold too");
  EXPECT_EQ(error_with("\"min_spp\": 8", "\"min_spp\": 80"),
            spec + ": /groups/1/configs/1/min_spp: more than the config's spp");
  EXPECT_EQ(error_with("\"wavefront\"]", "\"wavefrnt\"]"),
            spec + ": /groups/0/kernels/1: unknown value 'wavefrnt' (expected megakernel, megakernel-constant, "
                   "wavefront, wavefront-sorted, wavefront-unsorted)");
  EXPECT_EQ(error_with("\"spp\": 4, ", ""), spec + ": /groups/1/configs/0/spp: required key is missing");
  EXPECT_EQ(error_with("\"spp\": 4", "\"spp\": 0"),
            spec + ": /groups/1/configs/0/spp: must be an integer in 1..1000000 (got 0)");
  EXPECT_EQ(error_with("\"repeats\": 5", "\"repeats\": 5, \"repeats\": 6"), spec + ": /repeats: duplicate key");
  EXPECT_EQ(error_with("\"check_bound\": 0.01", "\"check_bound\": -1"),
            spec + ": /check_bound: must be a number in [0.0, 1e+30] (got -1)");
  EXPECT_EQ(error_with("\"name\": \"b\", ", ""), spec + ": /groups/1/name: required key is missing");
}

}  // namespace
}  // namespace wt::app

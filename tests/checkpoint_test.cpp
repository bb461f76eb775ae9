// Checkpoints: the file round-trips, a damaged or foreign one is refused with one
// line, and a render stopped by a signal resumes to the image it would have made.
#include <gtest/gtest.h>
#include <pthread.h>
#include <unistd.h>
#include <zlib.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "app/batch.hpp"
#include "app/checkpoint.hpp"
#include "app/job.hpp"
#include "errors/errors.hpp"
#include "test_support.hpp"

namespace wt::app {
namespace {

namespace fs = std::filesystem;

class CheckpointTest : public testing::Test {
 protected:
  void SetUp() override {
    scene_ = test::repo_path("scenes/quick.json");
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  Checkpoint sample_checkpoint() const {
    Checkpoint c;
    c.identity = checkpoint_identity(scene_, {}, RenderParams{4, 2, 16, 8, 3, 7}, "wavefront", "cpu");
    c.samples = 5;
    for (int i = 0; i < 4 * 2 * 3; ++i) c.film.push_back(0.25f * i);
    return c;
  }

  std::string bytes_of(const std::string& file) const {
    std::ifstream f(file, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  }

  void write_bytes(const std::string& file, const std::string& bytes) const {
    std::ofstream(file, std::ios::binary) << bytes;
  }

  std::string refusal(const std::string& file) const {
    try {
      read_checkpoint(file);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }

  // A job on the CPU whose render runs in several passes: a wave of 1024 slots
  // makes passes of at least 4096 paths, 16 samples of 16 x 16 pixels, of 64.
  // A job of the settings `p` (a checkpoint's) that resumes `checkpoint`.
  Job resuming(const RenderParams& p, const std::string& output, const std::string& checkpoint) const {
    Job j = job(output);
    j.width = p.width;
    j.height = p.height;
    j.spp = p.spp;
    j.depth = p.depth;
    j.roulette_depth = p.roulette_depth;
    j.seed = p.seed;
    j.nee = p.nee;
    j.resume = checkpoint;
    return j;
  }

  // `c` made to hold every sample and written to done.ckpt; the job that resumes it.
  Job resuming_finished(Checkpoint& c) const {
    c.samples = c.identity.params.spp;
    write_checkpoint(path("done.ckpt"), c);
    return resuming(c.identity.params, path("done.pfm"), path("done.ckpt"));
  }

  Job job(const std::string& output) const {
    Job j;
    j.scene = scene_;
    j.output = output;
    j.width = 16;
    j.height = 16;
    j.spp = 64;
    j.depth = 6;
    j.backend = "cpu";
    j.kernel = "wavefront";
    j.wave_size = 1024;
    j.progress = false;
    return j;
  }

  // Runs `j` with a SIGTERM pending (blocked) on this thread when the render starts:
  // the job's catcher takes it, so the render stops after its first pass (or step)
  // with a last checkpoint. The signal is sent to this thread alone: one sent to the
  // process would go to any other thread that does not block it (the CUDA driver's),
  // and end the process before the catcher is there.
  static JobOutcome run_with_sigterm_pending(const Job& j) {
    sigset_t term, previous;
    sigemptyset(&term);
    sigaddset(&term, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &term, &previous);
    ::pthread_kill(::pthread_self(), SIGTERM);
    const JobOutcome out = run_job(j);
    pthread_sigmask(SIG_SETMASK, &previous, nullptr);
    return out;
  }

  test::TestFolder folder_;
  const fs::path dir_ = folder_.root();
  std::string scene_;
};

TEST_F(CheckpointTest, RoundTripsWhatItHolds) {
  const Checkpoint c = sample_checkpoint();
  write_checkpoint(path("c.ckpt"), c);
  const Checkpoint back = read_checkpoint(path("c.ckpt"));
  EXPECT_EQ(back.samples, 5);
  EXPECT_EQ(back.film, c.film);
  EXPECT_NO_THROW(require_same_render(path("c.ckpt"), back.identity, c.identity));
  EXPECT_EQ(back.identity.scene_crc, c.identity.scene_crc);
}

TEST_F(CheckpointTest, ADamagedOrCutOrForeignFileIsRefused) {
  write_checkpoint(path("c.ckpt"), sample_checkpoint());
  std::string bytes = bytes_of(path("c.ckpt"));

  std::string flipped = bytes;
  flipped[flipped.size() - 20] ^= 0x40;  // a bit of the film
  write_bytes(path("flipped.ckpt"), flipped);
  EXPECT_EQ(refusal(path("flipped.ckpt")), path("flipped.ckpt") + ": not a usable checkpoint: its checksum does "
                                                                  "not match (the file is damaged or was cut short)");

  write_bytes(path("cut.ckpt"), bytes.substr(0, bytes.size() / 2));
  EXPECT_NE(refusal(path("cut.ckpt")).find("checksum does not match"), std::string::npos);

  write_bytes(path("other.ckpt"), "{\"jobs\": []}");
  EXPECT_EQ(refusal(path("other.ckpt")),
            path("other.ckpt") + ": not a usable checkpoint: it does not start as a wavetrace checkpoint does");

  // A later format, with its checksum made good: refused by its version.
  std::string later = bytes.substr(0, bytes.size() - 4);
  const uint32_t version = kAdaptiveCheckpointFormat + 1;
  std::memcpy(&later[8], &version, sizeof version);
  const uint32_t crc = static_cast<uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(later.data()), later.size()));
  later.append(reinterpret_cast<const char*>(&crc), sizeof crc);
  write_bytes(path("later.ckpt"), later);
  EXPECT_EQ(refusal(path("later.ckpt")), path("later.ckpt") + ": not a usable checkpoint: format version " +
                                             std::to_string(version) + "; this wavetrace reads versions " +
                                             std::to_string(kCheckpointFormat) + " and " +
                                             std::to_string(kAdaptiveCheckpointFormat));

  EXPECT_EQ(refusal(path("missing.ckpt")), path("missing.ckpt") + ": cannot open checkpoint (No such file or directory)");
}

TEST_F(CheckpointTest, AnotherSceneSettingsOrKernelIsRefused) {
  const CheckpointIdentity then = sample_checkpoint().identity;
  auto refusal_of = [&](const CheckpointIdentity& now) {
    try {
      require_same_render("c.ckpt", then, now);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CheckpointIdentity now = then;
  now.params.spp = 32;
  EXPECT_EQ(refusal_of(now), "c.ckpt: the checkpoint is of another render: spp 16 in the checkpoint, 32 now");
  now = then;
  now.kernel = "megakernel";
  EXPECT_EQ(refusal_of(now),
            "c.ckpt: the checkpoint is of another render: cpu/wavefront in the checkpoint, cpu/megakernel now");
  now = then;
  now.scene_crc ^= 1;
  EXPECT_NE(refusal_of(now).find("the checkpoint is of another render: scene "), std::string::npos);
  now = then;
  now.renderer = "wavetrace 0.1";
  EXPECT_NE(refusal_of(now).find("made by " + then.renderer), std::string::npos);
  // A Mitsuba scene's parameters are part of the scene: another -D is another scene.
  now = checkpoint_identity(scene_, {{"spp", "64"}}, then.params, then.kernel, then.backend);
  EXPECT_NE(now.scene_crc, then.scene_crc);
  EXPECT_NE(refusal_of(now).find("the checkpoint is of another render: scene "), std::string::npos);
  EXPECT_NE(checkpoint_identity(scene_, {{"spp", "65"}}, then.params, then.kernel, then.backend).scene_crc,
            now.scene_crc);
}

TEST_F(CheckpointTest, ARenderStoppedBySigtermResumesToTheUninterruptedImage) {
  const JobOutcome whole = run_job(job(path("whole.pfm")));
  ASSERT_EQ(whole.exit_code, 0) << whole.message;

  // A SIGTERM pending when the render starts stops it after its first pass.
  Job first = job(path("resumed.pfm"));
  first.checkpoint = path("r.ckpt");
  const JobOutcome stopped = run_with_sigterm_pending(first);
  EXPECT_EQ(stopped.exit_code, 128 + SIGTERM);
  EXPECT_EQ(stopped.message, "interrupted by SIGTERM at sample 16 of 64; checkpoint written to " + path("r.ckpt") +
                                 " (resume with --resume " + path("r.ckpt") + ")");
  EXPECT_FALSE(fs::exists(path("resumed.pfm")));
  ASSERT_TRUE(fs::exists(path("r.ckpt")));
  EXPECT_EQ(read_checkpoint(path("r.ckpt")).samples, 16);

  Job rest = job(path("resumed.pfm"));
  rest.resume = path("r.ckpt");
  const JobOutcome resumed = run_job(rest);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.message;
  EXPECT_EQ(resumed.resumed_from_sample, 16);
  EXPECT_FALSE(fs::exists(path("r.ckpt")));  // the image is written: the checkpoint is done with
  EXPECT_EQ(stopped.result.rays + resumed.result.rays, whole.result.rays);
  const auto a = test::read_pfm(path("whole.pfm"), 16, 16), b = test::read_pfm(path("resumed.pfm"), 16, 16);
  ASSERT_EQ(a.size(), b.size());
  // The same samples summed in another grouping: equal to float rounding.
  for (size_t i = 0; i < a.size(); ++i) ASSERT_NEAR(a[i], b[i], 1e-5f * std::max(1.0f, a[i])) << i;
}

// An adaptive render (--noise-threshold) stopped by SIGTERM after its first step
// keeps its halves, counts and converged pixels; resumed, it ends as the
// uninterrupted render does, bit for bit (the megakernel sums each pixel's samples
// in order), each pixel with the same samples.
TEST_F(CheckpointTest, AnAdaptiveRenderStoppedBySigtermResumesToTheUninterruptedImage) {
  auto adaptive = [&](const std::string& output) {
    Job j = job(output);
    j.kernel = "megakernel";
    j.spp = 256;
    j.noise_threshold = 0.05;
    j.min_spp = 8;
    j.aov = "spp";
    return j;
  };
  const JobOutcome whole = run_job(adaptive(path("whole.pfm")));
  ASSERT_EQ(whole.exit_code, 0) << whole.message;
  ASSERT_GT(whole.result.samples, 16) << "the render ends in its first steps: nothing to resume";

  Job first = adaptive(path("resumed.pfm"));
  first.checkpoint = path("a.ckpt");
  const JobOutcome stopped = run_with_sigterm_pending(first);
  EXPECT_EQ(stopped.exit_code, 128 + SIGTERM);
  EXPECT_EQ(stopped.message, "interrupted by SIGTERM at sample 8 of 256; checkpoint written to " + path("a.ckpt") +
                                 " (resume with --resume " + path("a.ckpt") + ")");
  EXPECT_FALSE(fs::exists(path("resumed.pfm")));
  const Checkpoint kept = read_checkpoint(path("a.ckpt"));
  ASSERT_TRUE(kept.adaptive.has_value());
  EXPECT_EQ(kept.adaptive->samples, 8);
  EXPECT_EQ(kept.identity.noise_threshold, 0.05);
  EXPECT_EQ(kept.identity.min_spp, 8);

  // Another threshold does not resume it.
  Job other = adaptive(path("other.pfm"));
  other.noise_threshold = 0.1;
  other.resume = path("a.ckpt");
  const JobOutcome refused = run_job(other);
  EXPECT_EQ(refused.exit_code, kExitBadInput);
  EXPECT_NE(refused.message.find("noise_threshold 0.05, min_spp 8 in the checkpoint, noise_threshold 0.1, min_spp 8 now"),
            std::string::npos)
      << refused.message;

  Job rest = adaptive(path("resumed.pfm"));
  rest.resume = path("a.ckpt");
  const JobOutcome resumed = run_job(rest);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.message;
  EXPECT_EQ(resumed.resumed_from_sample, 8);
  EXPECT_FALSE(fs::exists(path("a.ckpt")));
  EXPECT_EQ(stopped.result.rays + resumed.result.rays, whole.result.rays);
  EXPECT_EQ(resumed.result.pixel_samples, whole.result.pixel_samples);
  EXPECT_EQ(resumed.result.converged, whole.result.converged);
  EXPECT_EQ(test::read_pfm(path("whole.pfm"), 16, 16), test::read_pfm(path("resumed.pfm"), 16, 16));
  EXPECT_EQ(bytes_of(path("whole.spp.pfm")), bytes_of(path("resumed.spp.pfm")));
}

// An adaptive state round-trips, and one whose counts its checksum vouches for but
// which cannot be (a pixel still going with fewer samples than the render's) is
// refused, naming the pixel.
TEST_F(CheckpointTest, AnAdaptiveStateRoundTripsAndIsCheckedWhenRead) {
  Checkpoint c = sample_checkpoint();  // 4 x 2, 16 spp
  c.identity.noise_threshold = 0.02;
  c.identity.min_spp = 4;
  c.film.clear();
  AdaptiveState a = AdaptiveState::start(8);
  a.samples = 8;
  for (size_t p = 0; p < 8; ++p) {
    a.n_a[p] = a.n_b[p] = 4;
    for (int k = 0; k < 3; ++k) {
      a.half_a[3 * p + k] = 0.5f * static_cast<float>(p + k);
      a.half_b[3 * p + k] = 0.25f * static_cast<float>(p + k);
    }
  }
  a.converged[3] = 1;
  c.adaptive = a;
  write_checkpoint(path("a.ckpt"), c);
  const Checkpoint back = read_checkpoint(path("a.ckpt"));
  ASSERT_TRUE(back.adaptive.has_value());
  EXPECT_EQ(back.samples, 8);
  EXPECT_EQ(back.adaptive->half_a, a.half_a);
  EXPECT_EQ(back.adaptive->half_b, a.half_b);
  EXPECT_EQ(back.adaptive->n_a, a.n_a);
  EXPECT_EQ(back.adaptive->n_b, a.n_b);
  EXPECT_EQ(back.adaptive->converged, a.converged);
  EXPECT_NO_THROW(require_same_render(path("a.ckpt"), back.identity, c.identity));
  // A uniform render does not resume it.
  Checkpoint uniform = sample_checkpoint();
  try {
    require_same_render(path("a.ckpt"), back.identity, uniform.identity);
    ADD_FAILURE() << "an adaptive checkpoint resumed by a uniform render";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("noise_threshold 0.02, min_spp 4 in the checkpoint, a uniform render now"),
              std::string::npos)
        << e.what();
  }
  c.adaptive->n_b[5] = 3;  // still going, with 7 of 8 samples
  write_checkpoint(path("bad.ckpt"), c);
  EXPECT_EQ(refusal(path("bad.ckpt")), path("bad.ckpt") + ": not a usable checkpoint: pixel 5's adaptive counts (4, 3) "
                                                          "do not fit its 8 samples");
}

TEST_F(CheckpointTest, ACheckpointHoldingEverySampleIsTheImage) {
  Checkpoint c = sample_checkpoint();
  const RenderParams& p = c.identity.params;
  const Job j = resuming_finished(c);
  const JobOutcome o = run_job(j);
  ASSERT_EQ(o.exit_code, 0) << o.message;
  EXPECT_EQ(o.result.radiance, Radiance::MeanOfSamples);
  EXPECT_EQ(o.result.paths, 0u);  // nothing left to trace
  // The mean as every render takes it: the sums times 1 / samples.
  const auto image = test::read_pfm(path("done.pfm"), p.width, p.height);
  ASSERT_EQ(image.size(), c.film.size());
  for (size_t i = 0; i < image.size(); ++i) EXPECT_EQ(image[i], c.film[i] * (1.0f / p.spp)) << i;
}

TEST_F(CheckpointTest, AnExistingCheckpointOfAnotherRenderIsNeverOverwritten) {
  write_checkpoint(path("c.ckpt"), sample_checkpoint());
  const std::string before = bytes_of(path("c.ckpt"));
  Job j = job(path("out.pfm"));
  j.checkpoint = path("c.ckpt");
  const JobOutcome o = run_job(j);
  EXPECT_EQ(o.exit_code, kExitBadInput);
  EXPECT_NE(o.message.find(path("c.ckpt") + ": the checkpoint is of another render: width 4 in the checkpoint, "
                                            "16 now"),
            std::string::npos)
      << o.message;
  EXPECT_EQ(bytes_of(path("c.ckpt")), before);
  EXPECT_FALSE(fs::exists(path("out.pfm")));
}

// ---- What a checkpoint holds ----

// A checkpoint's bytes with its header's `from` replaced by `to`, the header's length
// and the checksum made good: a file that only its contents can refuse.
std::string with_header_text(const std::string& bytes, const std::string& from, const std::string& to) {
  // Layout: magic (8), format (4), header length (4), header, float count and floats, CRC-32 (4).
  uint32_t header_bytes = 0;
  std::memcpy(&header_bytes, bytes.data() + 12, sizeof header_bytes);
  std::string header = bytes.substr(16, header_bytes);
  const std::string film = bytes.substr(16 + header_bytes, bytes.size() - 4 - (16 + header_bytes));
  const size_t at = header.find(from);
  EXPECT_NE(at, std::string::npos) << from << " in " << header;
  if (at == std::string::npos) return bytes;
  header.replace(at, from.size(), to);
  std::string out = bytes.substr(0, 12);
  header_bytes = static_cast<uint32_t>(header.size());
  out.append(reinterpret_cast<const char*>(&header_bytes), sizeof header_bytes);
  out += header + film;
  const uint32_t crc = static_cast<uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(out.data()), out.size()));
  out.append(reinterpret_cast<const char*>(&crc), sizeof crc);
  return out;
}

TEST_F(CheckpointTest, SamplesThatAreNotAWholeNumberAreRefused) {
  write_checkpoint(path("c.ckpt"), sample_checkpoint());
  const std::string bytes = bytes_of(path("c.ckpt"));
  ASSERT_NO_THROW(read_checkpoint(path("c.ckpt")));
  write_bytes(path("half.ckpt"), with_header_text(bytes, "\"samples\":5", "\"samples\":2.5"));
  EXPECT_EQ(refusal(path("half.ckpt")), path("half.ckpt") + ": not a usable checkpoint: its samples is 2.5, not a whole number");
  write_bytes(path("text.ckpt"), with_header_text(bytes, "\"samples\":5", "\"samples\":\"5\""));
  EXPECT_EQ(refusal(path("text.ckpt")),
            path("text.ckpt") + ": not a usable checkpoint: its samples is \"5\", not a whole number");
  // The same edit that keeps a whole number is read: the crafting is sound.
  write_bytes(path("four.ckpt"), with_header_text(bytes, "\"samples\":5", "\"samples\":4"));
  EXPECT_EQ(read_checkpoint(path("four.ckpt")).samples, 4);
}

TEST_F(CheckpointTest, SamplesOutsideZeroToSppAreRefused) {
  Checkpoint c = sample_checkpoint();  // 16 spp
  c.samples = 17;
  write_checkpoint(path("more.ckpt"), c);
  EXPECT_EQ(refusal(path("more.ckpt")), path("more.ckpt") + ": not a usable checkpoint: its samples is 17, outside 0..16");
  c.samples = -1;
  write_checkpoint(path("less.ckpt"), c);
  EXPECT_EQ(refusal(path("less.ckpt")), path("less.ckpt") + ": not a usable checkpoint: its samples is -1, outside 0..16");
  for (int32_t ok : {0, 16}) {
    c.samples = ok;
    write_checkpoint(path("ok.ckpt"), c);
    EXPECT_EQ(read_checkpoint(path("ok.ckpt")).samples, ok);
  }
}

TEST_F(CheckpointTest, SettingsOutsideTheirRangesAreRefused) {
  Checkpoint c = sample_checkpoint();
  c.identity.params.spp = 0;
  c.samples = 0;
  write_checkpoint(path("spp.ckpt"), c);
  EXPECT_EQ(refusal(path("spp.ckpt")), path("spp.ckpt") + ": not a usable checkpoint: its spp is 0, outside 1..1000000");
  write_checkpoint(path("c.ckpt"), sample_checkpoint());
  write_bytes(path("depth.ckpt"), with_header_text(bytes_of(path("c.ckpt")), "\"depth\":8", "\"depth\":8.5"));
  EXPECT_EQ(refusal(path("depth.ckpt")), path("depth.ckpt") + ": not a usable checkpoint: its depth is 8.5, not a whole number");
}

TEST_F(CheckpointTest, AFilmOfAnotherSizeIsRefused) {
  Checkpoint c = sample_checkpoint();  // 4 x 2
  c.film.resize(21);
  write_checkpoint(path("short.ckpt"), c);
  EXPECT_EQ(refusal(path("short.ckpt")),
            path("short.ckpt") + ": not a usable checkpoint: its film holds 21 values; a 4 x 2 render's holds 24");
  c.film.assign(4 * 2 * 3 + 3, 0.0f);
  write_checkpoint(path("long.ckpt"), c);
  EXPECT_NE(refusal(path("long.ckpt")).find("its film holds 27 values; a 4 x 2 render's holds 24"), std::string::npos);
}

// A film of sums of radiance is finite and at least 0: a NaN, an infinity or a
// negative value would go into every later sample's mean.
TEST_F(CheckpointTest, AFilmWithANanAnInfinityOrANegativeValueIsRefused) {
  Checkpoint c = sample_checkpoint();
  c.film[7] = std::nanf("");  // pixel 2 of 8: (2, 0)
  write_checkpoint(path("nan.ckpt"), c);
  EXPECT_EQ(refusal(path("nan.ckpt")), path("nan.ckpt") + ": not a usable checkpoint: its film's pixel (2, 0) holds "
                                                          "NaN; a sum of radiance is finite and at least 0");
  c = sample_checkpoint();
  c.film[23] = -1.0f;  // the last pixel: (3, 1)
  write_checkpoint(path("negative.ckpt"), c);
  const std::string negative = refusal(path("negative.ckpt"));
  EXPECT_EQ(negative.rfind(path("negative.ckpt") + ": not a usable checkpoint: its film's pixel (3, 1) holds -1", 0), 0u)
      << negative;
  EXPECT_NE(negative.find("; a sum of radiance is finite and at least 0"), std::string::npos) << negative;
  c = sample_checkpoint();
  c.film[12] = std::numeric_limits<float>::infinity();  // pixel 4: (0, 1)
  write_checkpoint(path("inf.ckpt"), c);
  EXPECT_EQ(refusal(path("inf.ckpt")), path("inf.ckpt") + ": not a usable checkpoint: its film's pixel (0, 1) holds an "
                                                          "infinity; a sum of radiance is finite and at least 0");
}

// A bad checkpoint resumed by a job: bad input, and the checkpoint left as it is.
TEST_F(CheckpointTest, AJobResumingABadCheckpointIsBadInputAndKeepsIt) {
  Checkpoint c = sample_checkpoint();
  c.film[0] = std::nanf("");
  write_checkpoint(path("bad.ckpt"), c);
  const std::string before = bytes_of(path("bad.ckpt"));
  Job j = job(path("out.pfm"));
  j.resume = path("bad.ckpt");
  const JobOutcome o = run_job(j);
  EXPECT_EQ(o.exit_code, kExitBadInput);
  EXPECT_NE(o.message.find(path("bad.ckpt") + ": not a usable checkpoint: its film's pixel (0, 0) holds NaN"),
            std::string::npos)
      << o.message;
  EXPECT_EQ(bytes_of(path("bad.ckpt")), before);
  EXPECT_FALSE(fs::exists(path("out.pfm")));
}

// Resumed with every sample done, the job renders nothing: its line says so, rather
// than a rate of rays over 0 seconds ("-nan M rays/s").
TEST_F(CheckpointTest, AFinishedCheckpointResumedSaysNothingWasLeftToRender) {
  Checkpoint c = sample_checkpoint();
  const RenderParams& p = c.identity.params;
  const Job j = resuming_finished(c);
  const JobOutcome o = run_job(j);
  ASSERT_EQ(o.exit_code, 0) << o.message;
  EXPECT_TRUE(fs::exists(path("done.pfm")));
  EXPECT_EQ(o.resumed_from_sample, p.spp);
  testing::internal::CaptureStderr();
  print_outcome(j, o);
  const std::string said = testing::internal::GetCapturedStderr();
  EXPECT_EQ(said, path("done.pfm") + ": every one of its 16 samples was in the checkpoint " + path("done.ckpt") +
                      "; nothing was left to render\n");
  EXPECT_EQ(said.find("nan"), std::string::npos) << said;
}

TEST_F(CheckpointTest, AResumedBatchSkipsTheJobsWhoseImageExists) {
  std::vector<PlannedJob> jobs = {{job(path("a.pfm")), ""}, {job(path("b.pfm")), ""}};
  write_bytes(path("a.pfm"), "an image from before");
  EXPECT_EQ(run_batch(jobs, true), 0);
  EXPECT_EQ(bytes_of(path("a.pfm")), "an image from before");
  EXPECT_TRUE(fs::exists(path("b.pfm")));
}

}  // namespace
}  // namespace wt::app

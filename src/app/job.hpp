// One render job: a scene, its settings, where the image and the stats go.
// `render` runs one; `batch` runs many and goes on past a failing one.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "app/cluster.hpp"
#include "dispatch/renderer.hpp"
#include "errors/errors.hpp"
#include "image/image_io.hpp"
#include "render/settings.hpp"

namespace wt::app {

struct Job {
  std::string scene;
  // A Mitsuba scene's parameters (-D name=value), which take precedence over its
  // <default>s; empty for a JSON scene.
  std::map<std::string, std::string> defines;
  std::string output;
  std::string stats;  // empty: no stats file
  // The render settings (src/render/settings.hpp); unset: the scene's.
  std::optional<int64_t> width, height, spp, depth, roulette_depth, seed, nee;
  std::string backend = "auto";
  std::string kernel = "megakernel";
  int64_t warmup = 0;
  int64_t wave_size = 0;  // 0: chosen at run time
  int64_t threads = 0;    // 0: every core
  int64_t megakernel_batch = 0;  // 0: chosen at run time (RenderOptions::megakernel_batch)
  // Adaptive sampling (render/adaptive.hpp): unset off, else above 0; min_spp 0 chooses.
  std::optional<double> noise_threshold;
  int64_t min_spp = 0;
  // The devices to split the render over: "all" (every CUDA device; on the CPU
  // backend, one), or indices "0,1" (on the CPU backend, as many host "devices").
  std::string devices = "all";
  // Checkpoints (docs/checkpoints.md): written to `checkpoint` every
  // `checkpoint_every` seconds and on SIGINT/SIGTERM; `resume` continues from one
  // (an existing `checkpoint` file is resumed too, never overwritten by a new start).
  std::string checkpoint, resume;
  int64_t checkpoint_every = 300;
  Encoding encoding = Encoding::Srgb;
  bool exr_float = false;  // an .exr output's pixels: 32-bit floats rather than half floats
  // Denoising (image/denoise.hpp): the output is the image Open Image Denoise makes
  // of the render, at `denoise_quality` ("high" or "balanced"); with keep_noisy the
  // render itself is written too, as noisy_output(job) (NAME.noisy.EXT).
  bool denoise = false;
  std::string denoise_quality = "high";
  bool keep_noisy = false;
  // AOVs (render/aovs.hpp) as --aov names them ("albedo,normal"; empty: none): layers
  // of an OpenEXR output, else PFM files beside it (aov_outputs in job_files.hpp).
  std::string aov;
  bool progress = true;
  bool profile = false;
};

// Exit codes: bad input (scene, settings, paths) and failures of the machine; a
// render stopped by a signal after its last checkpoint exits with 128 + the signal.
constexpr int kExitBadInput = 2;
constexpr int kExitFailure = 1;

struct JobOutcome {
  int exit_code = 0;
  std::string message;  // the one line that says why, when exit_code != 0
  // The job failed on the device with a sticky error (an illegal address, a kernel that
  // faulted): this process's CUDA context is lost, and no later CUDA work in it can run.
  bool device_lost = false;
  RenderParams params{};
  // Adaptive sampling as the render took it (the job's or the scene's): its threshold
  // (0: a uniform render) and min_spp.
  double noise_threshold = 0;
  int32_t min_spp = 0;
  LoadTimes load_times;
  Scene::Summary geometry;
  // What the scene file says is not rendered as its source meant (Scene::warnings).
  std::vector<std::string> scene_warnings;
  int32_t resumed_from_sample = 0;  // samples a resumed checkpoint held
  std::string backend, kernel;
  RenderResult result;
  std::string checkpoint;  // the render's checkpoint file, removed once its image is written
  // A render over MPI ranks: how many, and rank 0's wall-clock seconds from when every
  // rank had its scene to the summed film (result.seconds: the slowest rank's render).
  int ranks = 1;
  double wall_seconds = 0;
  // Wall clock of the whole job up to its image written, from the start of run_job
  // (scene, device set-up, render, image), and of encoding and writing the image.
  double job_seconds = 0, write_seconds = 0;
  // Of a denoised job: Open Image Denoise's seconds (its device set-up, the filter and
  // the copies), and the device it ran on ("cpu" or "cuda").
  double denoise_seconds = 0;
  std::string denoise_device;
  // The first-surface pass's sums, for the AOVs and the denoiser's guides (empty
  // where the job asks for neither).
  AovSums aovs;
  // Pixels of the image that are not finite (a NaN or an infinity in any channel): said
  // on stderr and in the stats, never written silently.
  uint64_t nonfinite_pixels = 0;
};

// Runs a job; never throws. Writes the image (and stats) only when the render and
// both writes succeeded. After a device failure that is not sticky it leaves the
// device fit for the next job (cuda::recover_after_error); after a sticky one it says
// that the context cannot be recovered and sets device_lost.
JobOutcome run_job(const Job& job);
// Prints what `render` says of a job that rendered (to stderr): its result line, and a
// line for each of its ranks and devices where it had several.
void print_outcome(const Job& job, const JobOutcome& o);
// The same job as one rank of an MPI run (app/distributed.hpp): every rank calls it;
// rank 0 alone writes, and every rank's outcome fails where any rank's part did.
JobOutcome run_job(const Job& job, const Cluster& cluster);

// The render options of a job on a scene: the job's settings over the scene's, its
// kernel, backend and devices; throws InputError naming what is wrong.
RenderOptions resolve_options(const Job& job, const Scene& scene);

// The phases after a job's render, for run_job and a session (app/session.hpp):
// - the first-surface pass (render_aovs) where the job's AOVs or its denoiser need
//   it, over the render's samples (an adaptive render's each pixel's own), into
//   out.aovs;
// - the denoiser's image of out.result (guided by out.aovs' albedo and normal; on
//   the CUDA device where the render ran on one, else or where OIDN has none there on
//   the CPU, said on stderr), its seconds and device in `out`;
// - the AOVs the job names, as images, in its order.
void render_first_surface(const Job& job, const Scene& scene, const RenderOptions& options, JobOutcome& out);
std::vector<float> denoise_outcome(const Job& job, const RenderOptions& options, JobOutcome& out);
std::vector<AovImage> job_aov_images(const Job& job, const JobOutcome& out);

// Sets a setting of the table (already checked against its range).
void set_setting(Job& job, SettingId id, int64_t value);
// Adds "name=value" parameters of a Mitsuba scene to job.defines (a later one of a
// name wins); throws InputError "<where>: ..." for one that is not name=value.
void add_defines(Job& job, const std::vector<std::string>& defines, const std::string& where);
// Whether `name` may name a parameter: letters, digits and _, at least one.
bool is_define_name(const std::string& name);
// A setting the job was given: its value, or none where the job keeps the default.
std::optional<int64_t> given_setting(const Job& job, SettingId id);

// The checkpoint a job writes: --checkpoint, or else the --resume file (written back to).
const std::string& checkpoint_of(const Job& job);

// Throws InputError "<field>: <why>" where Open Image Denoise cannot be loaded.
void check_denoiser(const std::string& field);

// Pixels (RGB triples) with a NaN or an infinity in any channel.
uint64_t count_nonfinite_pixels(const std::vector<float>& rgb);

Backend parse_backend(const std::string& name);  // "cuda" | "cpu" | "auto"; throws InputError
// Job::devices as the render's device list for `backend` (`present`: CUDA devices
// present); throws InputError naming the field for anything else.
std::vector<int> parse_devices(const std::string& text, Backend backend, int present);

}  // namespace wt::app

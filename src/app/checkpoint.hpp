// Checkpoints: a render's film sums and the samples done, written atomically while
// the render runs, so that it can be resumed after an interruption and give the
// image an uninterrupted render gives. The format: docs/checkpoints.md.
#pragma once

#include <cstdint>
#include <optional>
#include <map>
#include <string>
#include <vector>

#include "render/adaptive.hpp"
#include "render/render_types.hpp"

namespace wt::app {

// Version 1: a film of sums and the samples done. Version 2 (an adaptive render's):
// besides, the halves and counts of render/adaptive.hpp's AdaptiveState.
constexpr uint32_t kCheckpointFormat = 1;
constexpr uint32_t kAdaptiveCheckpointFormat = 2;

// What a checkpoint must match to be resumed: the scene file's bytes, the render's
// settings, the kernel and backend, and the renderer's version.
struct CheckpointIdentity {
  std::string scene;         // the scene file, as given
  uint32_t scene_crc = 0;    // CRC-32 of its bytes
  RenderParams params{};
  std::string kernel, backend;
  // An adaptive render's threshold (-1: its rounds without a threshold, for the
  // variance AOV) and the samples every pixel takes first; 0, 0 for a uniform render.
  double noise_threshold = 0;
  int32_t min_spp = 0;
  std::string renderer = kRendererVersion;

  static constexpr const char* kRendererVersion = "wavetrace 0.3 (light transport of 2026-11)";
};

// Reads the scene file and fills the identity; throws InputError if it cannot be read.
// A Mitsuba scene's parameters (-D) count as part of its bytes: the CRC is of the
// file followed by a line "-D name=value" for each (none for a JSON scene, whose CRC
// is its file's).
CheckpointIdentity checkpoint_identity(const std::string& scene, const std::map<std::string, std::string>& defines,
                                       const RenderParams& params, const std::string& kernel,
                                       const std::string& backend);

struct Checkpoint {
  CheckpointIdentity identity;
  int32_t samples = 0;       // samples of every pixel the film sums, from sample 0
  std::vector<float> film;   // linear RGB sums per pixel, row 0 = top
  // An adaptive render's state between two steps (identity.noise_threshold != 0): its
  // halves, counts and converged pixels; `samples` is then its samples and `film`
  // empty.
  std::optional<AdaptiveState> adaptive;
};

// Writes atomically (temporary file renamed into place); throws OutputError.
void write_checkpoint(const std::string& path, const Checkpoint& checkpoint);

// Reads and checks the checksum and the format; throws InputError naming the file
// and what is wrong.
Checkpoint read_checkpoint(const std::string& path);

// Throws InputError naming the file and the first thing that differs.
void require_same_render(const std::string& path, const CheckpointIdentity& checkpoint,
                         const CheckpointIdentity& now);

}  // namespace wt::app

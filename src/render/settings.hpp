// The one table of a render's settings: name, type, inclusive range and default.
// The command line, a scene's `render` section, jobs files, bench specs,
// validate_params and the stats writer all read it, so a setting has one range
// wherever it is given.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "errors/errors.hpp"
#include "render/render_types.hpp"

namespace wt {

// The sane limits of a render's settings, wherever they are given (scene file,
// command line, jobs file, bench spec), gathered with the defaults below into the one
// table of settings that every reader checks against.
constexpr int kMaxImageSide = 16384;
constexpr int kMaxSpp = 1000000;
constexpr int kMaxPathDepth = 1024;
// Russian roulette starts at the latest after this many bounces (a path never gets
// near it: depth is at most kMaxPathDepth).
constexpr int kMaxRouletteDepth = 1 << 30;

// A render's settings where nothing gives them: a scene's, unless its `render`
// section says otherwise.
struct RenderDefaults : RenderParams {
  RenderDefaults() : RenderParams{640, 360, 16, 10, 5, 1} {}
  // Adaptive sampling (render/adaptive.hpp), which a scene's `render` section may ask
  // for too: a threshold above 0 turns it on; min_spp 0 chooses.
  double noise_threshold = 0;
  int32_t min_spp = 0;
};

enum class SettingId {
  Width,
  Height,
  Spp,
  Depth,
  RouletteDepth,
  Seed,
  Nee,
  Warmup,
  WaveSize,
  Threads,
  CheckpointEvery,
  MegakernelBatch,
  MinSpp,
  NoiseThreshold
};

// Real: a number, in (real_above, real_most] (the one setting of this type, the noise
// threshold, has no default: unset, it is off).
enum class SettingType { Int32, UInt32, Int64, Real };

struct Setting {
  SettingId id;
  const char* key;   // in JSON (scene `render` sections, jobs files, bench configs, stats)
  const char* flag;  // on the command line
  SettingType type;
  int64_t lo, hi;    // the inclusive range of a value that is given
  int64_t fallback;  // the default; 0 for wave_size and threads: chosen at run time
  const char* help;
  double real_above = 0, real_most = 0;  // a Real setting's range (lo, hi are an integer's)
};

// Every setting, in the order above.
const std::vector<Setting>& settings();
const Setting& setting(SettingId id);

// The settings a RenderParams holds (width .. nee): a scene's `render` section
// and a bench configuration give these.
const std::vector<SettingId>& render_settings();
int64_t get_param(const RenderParams& p, SettingId id);
void set_param(RenderParams& p, SettingId id, int64_t value);

// Throws InputError "<key>: must be in lo..hi (got value)" when value is out of range.
void check_setting(SettingId id, int64_t value);
// Of a Real setting: "<key>: must be above A and at most B (got value)".
void check_real_setting(SettingId id, double value);
// The settings a scene's `render` section takes: render_settings(), and adaptive
// sampling's (min_spp, noise_threshold), which RenderDefaults holds beside them.
const std::vector<SettingId>& scene_settings();

// The kernels, in the order the docs and plots list them, their names, and the
// backends each runs on.
const std::vector<Kernel>& kernels();
const char* kernel_name(Kernel k);
bool kernel_runs_on(Kernel kernel, Backend backend);
std::vector<std::string> kernel_names();
std::vector<std::string> kernel_names(Backend backend);
Kernel parse_kernel(const std::string& name);  // throws InputError naming the kernels

// The names a backend may be asked for ("auto": CUDA when a device is present), and
// the PNG encodings.
const std::vector<std::string>& backend_choices();
const std::vector<std::string>& encoding_choices();
// Open Image Denoise's qualities that --denoise-quality takes (image/denoise.hpp).
const std::vector<std::string>& denoise_quality_choices();

}  // namespace wt

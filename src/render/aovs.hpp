// The AOVs a render can write beside its image (--aov), from the sums of the
// first-surface pass (include/wavetrace/aov.hpp) that every backend runs.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "render/render_types.hpp"

namespace wt {

enum class AovKind : uint32_t { Albedo, Normal, Depth, Position, Variance, Spp };

// The AOVs' names, as --aov takes them: "albedo", "normal", "depth", "position"
// (the first-surface pass's), "variance" and "spp" (the render's own: adaptive
// sampling's estimate of the variance of each pixel's mean, and its samples).
const std::vector<std::string>& aov_names();
const char* aov_name(AovKind kind);

// A comma-separated list of names ("albedo,normal"), each at most once, in the order
// given. Throws InputError naming `field` (where not empty) and the name for an
// unknown or repeated one.
std::vector<AovKind> parse_aovs(const std::string& list, const std::string& field = "--aov");

// The first-surface pass's sums (kAovFloats floats a pixel, include/wavetrace/aov.hpp)
// over samples [0, samples) of every pixel, or [0, pixel_samples[p]) of pixel p where
// the pass followed an adaptive render's counts, as a backend returns them.
struct AovSums {
  std::vector<float> sums;
  int32_t samples = 0;
  std::vector<int32_t> pixel_samples;  // empty: `samples` for every pixel
  double seconds = 0;  // the pass alone (CUDA events on the GPU, wall clock on the CPU)
};

// One AOV as an image: its name, its channels' names ("R", "G", "B"; "X", "Y", "Z";
// "Z" for depth) and width x height x channels floats, row 0 = top.
struct AovImage {
  AovKind kind;
  std::string name;
  std::vector<std::string> channels;
  std::vector<float> values;
};

// Whether the AOV comes from the first-surface pass (else from the render itself).
bool from_first_surface(AovKind kind);

// The AOV `kind` of a render from the first-surface pass's sums over `samples`
// samples a pixel (kAovFloats a pixel): albedo and normal are means over every
// sample; depth and position means over the samples that hit a surface, a pixel none
// of whose samples did holding an infinite depth and a zero position.
AovImage aov_image(AovKind kind, const AovSums& sums);
// The AOV `kind` (variance or spp) of the render's result: the variance of each
// pixel's mean (R, G, B; render/adaptive.hpp), its samples (Y).
AovImage result_aov_image(AovKind kind, const RenderResult& result);

// The albedo and normal as OIDN takes them: the albedo's mean clamped to [0, 1], the
// normal's mean.
std::vector<float> denoise_albedo(const AovSums& sums);
std::vector<float> denoise_normal(const AovSums& sums);

}  // namespace wt

// Adaptive sampling: a render that stops each pixel once its noise is under a
// threshold (--noise-threshold), from the render's samples alone.
//
// The estimate. A pixel's samples fall into two halves, A and B (alternate rounds of
// samples, below), of n_A and n_B samples, n = n_A + n_B. The difference of the
// halves' means, D = mean_A - mean_B, has variance sigma^2 (1/n_A + 1/n_B), sigma^2
// a sample's variance; the pixel's mean has sigma^2 / n. So
//     V = D^2 n_A n_B / n^2
// is an unbiased estimate of the variance of the pixel's mean (E[V] = sigma^2 / n),
// per channel. The pixel's relative error is that of its luminance Y (Rec. 709):
//     r^2 = V_Y / max(Y, floor)^2,   floor = kNoiseFloor,
// relative, so that a threshold means the same in a dark room and under the sun, and
// held to an absolute error of T x floor where the pixel is darker than the floor.
// One pixel's V has a single degree of freedom, so a lucky pair of halves would stop
// it early: a pixel is converged when the root mean square of r over its 3 x 3
// neighbourhood (clipped at the image's edges) is at most T, and once converged it
// takes no more samples.
//
// The rounds. Every pixel first takes min_spp samples, in two rounds (A, then B);
// then each step gives every pixel not yet converged max(min_spp, n / 4) more (an
// eighth to a quarter more, so that the steps grow with the samples and their
// number stays small), half in a round of A and half in one of B, until the pixel
// converges or reaches spp. A round renders only the pixels still going
// (RenderOptions::active_pixels), every one of them the same samples [n, n + k), so
// that the image depends on the seed and the threshold alone, as every kernel
// renders it.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "render/device_renderer.hpp"
#include "render/render_types.hpp"

namespace wt {

// The luminance below which a pixel's error is measured against this instead.
constexpr double kNoiseFloor = 0.01;

// Y of linear Rec. 709 RGB.
inline double luminance(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

// The two halves' sums of one pixel and their sample counts.
struct PixelHalves {
  double a[3], b[3];
  int32_t n_a, n_b;
};

// V of each channel (the variance of the pixel's mean), per the header: 0 where
// either half is empty.
void mean_variance(const PixelHalves& h, double v[3]);

// r^2 of one pixel: its luminance's V over max(Y, kNoiseFloor)^2.
double relative_error_squared(const PixelHalves& h);

// Whether each pixel is converged at threshold T: the RMS of r over its 3 x 3
// neighbourhood at most T. `r2` holds r^2 of width x height pixels.
std::vector<uint8_t> converged_pixels(const std::vector<double>& r2, int width, int height, double threshold);

// The samples of one step for pixels that have n: max(min_spp, n / 4), even, within
// what spp leaves.
int32_t step_samples(int32_t n, int32_t min_spp, int32_t spp);

// All that decides the rest of an adaptive render, as it stands between two steps
// (a checkpoint holds it, app/checkpoint.hpp): the samples every pixel still going
// has, each pixel's halves and whether it has converged. A pixel still going is one
// not converged; after the last step, none is going.
struct AdaptiveState {
  int32_t samples = 0;                // n
  std::vector<float> half_a, half_b;  // each pixel's sums of its halves, RGB
  std::vector<int32_t> n_a, n_b;      // their samples
  std::vector<uint8_t> converged;     // 1: stopped under the threshold
  // Zeros for `pixels` pixels: the state before the first step.
  static AdaptiveState start(size_t pixels);
  // Empty where the sizes disagree with `pixels`, else what is wrong with it (a
  // checkpoint's is checked so before it is resumed): the halves' sums finite and at
  // least 0, the counts within 0..samples and adding up to samples for a pixel still
  // going.
  std::string check(size_t pixels, int32_t spp) const;
};

// What an adaptive render tells and asks of its caller besides the image.
struct AdaptiveHooks {
  // Continue from this state (a resumed checkpoint's) rather than from the start; the
  // render then ends as the uninterrupted one does, bit for bit.
  const AdaptiveState* resume = nullptr;
  // After each step, with the state and whether it was the last: false stops the
  // render there (the result then says `interrupted`, and holds the image as far as
  // it went).
  std::function<bool(const AdaptiveState&, bool last)> after_step;
  // After each step: the pixels converged so far (the progress line's).
  std::function<void(uint64_t converged)> converged;
};

// Renders options.params' image adaptively with `render` (a device's renderer, or
// several devices' split by pixels: each call renders the pixels and samples its
// options name and returns their sums, Radiance::SumOfSamples). The result holds
// each pixel's mean (MeanOfSamples), `pixel_samples` and `variance` (V of each
// channel), `converged` (the pixels that stopped before spp), and the rounds' rays,
// paths and seconds summed.
RenderResult render_adaptive(const ChunkRenderer& render, const RenderOptions& options, double threshold,
                             int32_t min_spp, const AdaptiveHooks& hooks = {});

// min_spp as a render takes it: 0 chooses 16, or spp where less.
int32_t resolved_min_spp(int32_t min_spp, int32_t spp);

// The mean of an adaptive result's pixel_samples (0 where it has none).
double mean_spp(const RenderResult& r);

}  // namespace wt

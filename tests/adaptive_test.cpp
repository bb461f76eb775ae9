// Adaptive sampling (render/adaptive.hpp): the error estimate against a known
// variance, the neighbourhood rule, the steps, and whole renders that stop flat
// pixels before edges, keep every kernel's image the same, and hold their error to
// the threshold against a converged reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "errors/errors.hpp"
#include "render/adaptive.hpp"
#include "render_support.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

// V's expectation is the variance of the pixel's mean, sigma^2 / n, with equal
// halves and unequal ones: 200000 pixels of n samples of a known distribution (the
// uniform on [0, 2]: sigma^2 = 1/3), their mean V within 4 standard errors of it.
TEST(AdaptiveEstimate, TheVarianceEstimateIsUnbiased) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 2.0);
  for (const auto& [n_a, n_b] : {std::pair{8, 8}, std::pair{5, 3}, std::pair{1, 1}}) {
    SCOPED_TRACE(std::to_string(n_a) + " + " + std::to_string(n_b));
    const int trials = 200000;
    std::vector<double> v_of(trials);
    for (int t = 0; t < trials; ++t) {
      PixelHalves h{{0, 0, 0}, {0, 0, 0}, n_a, n_b};
      for (int i = 0; i < n_a; ++i) h.a[0] += u(rng);
      for (int i = 0; i < n_b; ++i) h.b[0] += u(rng);
      double v[3];
      mean_variance(h, v);
      v_of[t] = v[0];
      EXPECT_EQ(v[1], 0.0);
    }
    const double exact = (1.0 / 3.0) / (n_a + n_b);
    test::expect_mean_within_4_sigma(v_of, exact, 0.02, "V");
  }
  // An empty half estimates nothing.
  double v[3];
  mean_variance(PixelHalves{{1, 1, 1}, {0, 0, 0}, 4, 0}, v);
  EXPECT_EQ(v[0], 0.0);
}

// r^2 is V of the luminance over Y^2, or over the floor's square for a dark pixel.
TEST(AdaptiveEstimate, TheErrorIsRelativeWithAFloor) {
  // Grey halves of means 1.1 and 0.9 (4 samples each): V = 0.04 / 4, Y = 1.
  EXPECT_NEAR(relative_error_squared(PixelHalves{{4.4, 4.4, 4.4}, {3.6, 3.6, 3.6}, 4, 4}), 0.01, 1e-12);
  // Ten times brighter: the same relative error.
  EXPECT_NEAR(relative_error_squared(PixelHalves{{44, 44, 44}, {36, 36, 36}, 4, 4}), 0.01, 1e-12);
  // Under the floor: V over the floor's square.
  const double dark = relative_error_squared(PixelHalves{{0.0044, 0.0044, 0.0044}, {0.0036, 0.0036, 0.0036}, 4, 4});
  EXPECT_NEAR(dark, (0.0002 * 0.0002 / 4) / (kNoiseFloor * kNoiseFloor), 1e-15);
}

// A pixel converges when the RMS of r over its 3 x 3 neighbourhood is at most T:
// one noisy pixel holds back its neighbours, and a lucky quiet pixel among noisy
// ones is held back by them.
TEST(AdaptiveEstimate, APixelStopsWithItsNeighbourhood) {
  const int w = 7, h = 5;
  std::vector<double> r2(w * h, 0.0);
  r2[2 * w + 3] = 9 * 0.05 * 0.05;  // r = 0.15 at (3, 2): its neighbourhood's RMS is 0.05
  std::vector<uint8_t> done = converged_pixels(r2, w, h, 0.049);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool near = std::abs(x - 3) <= 1 && std::abs(y - 2) <= 1;
      EXPECT_EQ(done[y * w + x], near ? 0 : 1) << x << ", " << y;
    }
  }
  EXPECT_EQ(converged_pixels(r2, w, h, 0.051)[2 * w + 3], 1);
  // Noisy everywhere but one pixel that happened to have equal halves.
  std::vector<double> noisy(w * h, 0.2 * 0.2);
  noisy[2 * w + 3] = 0.0;
  EXPECT_EQ(converged_pixels(noisy, w, h, 0.1)[2 * w + 3], 0);
  // At an edge, the neighbourhood is what lies inside the image.
  std::vector<double> corner(w * h, 0.0);
  corner[0] = 4 * 0.1 * 0.1;  // the corner's 2 x 2: RMS 0.1
  EXPECT_EQ(converged_pixels(corner, w, h, 0.099)[0], 0);
  EXPECT_EQ(converged_pixels(corner, w, h, 0.101)[0], 1);
}

TEST(AdaptiveEstimate, StepsGrowWithTheSamplesWithinSpp) {
  EXPECT_EQ(step_samples(16, 16, 1024), 16);
  EXPECT_EQ(step_samples(64, 16, 1024), 16);
  EXPECT_EQ(step_samples(100, 16, 1024), 26);  // 25, made even
  EXPECT_EQ(step_samples(1000, 16, 1024), 24);  // what spp leaves
  EXPECT_EQ(step_samples(1024, 16, 1024), 0);
  EXPECT_EQ(step_samples(8, 3, 1024), 4);
}

// The driver over a renderer whose samples are known: pixel p's sample s is a
// hash's uniform over 1 +- c_p / 2 for a noise level c_p (0 on the left half: a
// flat region; 1 to 8 across the right half). The flat pixels stop after min_spp; the noisy ones take samples until
// under the threshold or at spp; each round renders only the pixels still going,
// every one of them the same samples; the image is the mean of each pixel's samples.
TEST(AdaptiveDriver, FlatPixelsStopAndNoisyOnesGoOn) {
  const int w = 16, h = 8, spp = 512;
  RenderOptions o;
  o.params = RenderParams{w, h, spp, 4, 4, 1};
  auto value = [](uint32_t p, int32_t s) {
    uint64_t x = (static_cast<uint64_t>(p) << 32) ^ static_cast<uint64_t>(s) ^ 0x9e3779b97f4a7c15ull;
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdull;
    x ^= x >> 33;
    x *= 0xc4ceb9fe1a85ec53ull;
    x ^= x >> 33;
    return static_cast<double>(x >> 11) / static_cast<double>(1ull << 53);
  };
  auto noise = [&](uint32_t p) { return (p % w) < w / 2 ? 0.0 : 1.0 + (p % w) - w / 2; };
  int rounds = 0;
  bool every_round_uniform = true;
  const ChunkRenderer fake = [&](const RenderOptions& chunk) {
    ++rounds;
    RenderResult r;
    r.rgb.assign(w * h * 3, 0.0f);
    std::vector<uint32_t> all(w * h);
    std::iota(all.begin(), all.end(), 0u);
    const std::vector<uint32_t>& active = chunk.active_pixels ? *chunk.active_pixels : all;
    every_round_uniform = every_round_uniform && chunk.sample_count > 0;
    for (uint32_t p : active) {
      for (int32_t s = chunk.first_sample; s < chunk.first_sample + chunk.sample_count; ++s) {
        const float v = static_cast<float>(1.0 + noise(p) * (2.0 * value(p, s) - 1.0) * 0.5);
        for (int c = 0; c < 3; ++c) r.rgb[3 * p + c] += v;
      }
    }
    r.paths = active.size() * chunk.sample_count;
    return r;
  };
  const RenderResult r = render_adaptive(fake, o, 0.05, 16);
  EXPECT_TRUE(every_round_uniform);
  ASSERT_EQ(r.pixel_samples.size(), static_cast<size_t>(w * h));
  EXPECT_EQ(r.radiance, Radiance::MeanOfSamples);
  for (int y = 1; y < h - 1; ++y) {
    EXPECT_EQ(r.pixel_samples[y * w + 2], 16) << "a flat pixel stops after min_spp";
    EXPECT_GT(r.pixel_samples[y * w + w - 1], r.pixel_samples[y * w + w / 2 + 1]) << "more noise, more samples";
    EXPECT_FLOAT_EQ(r.rgb[3 * (y * w + 2)], 1.0f);
  }
  // Pixel values are uniform over 1 +- noise / 2, sigma = noise / sqrt(12): a
  // relative error sigma / sqrt(n) <= 0.05 needs n >= (sigma / 0.05)^2, 133 samples
  // for noise 2 (the column right of the middle), 2133 for noise 8 (the last
  // column), which reaches spp.
  EXPECT_EQ(r.pixel_samples[3 * w + w - 1], spp);
  EXPECT_GT(r.converged, static_cast<uint64_t>(w * h / 2 - 1));
  EXPECT_LT(r.converged, static_cast<uint64_t>(w * h));
  EXPECT_GT(rounds, 4);
  // The image is each pixel's mean.
  double mean = 0;
  for (int s = 0; s < r.pixel_samples[3 * w + w - 1]; ++s) mean += 1.0 + 8.0 * (2.0 * value(3 * w + w - 1, s) - 1.0) * 0.5;
  EXPECT_NEAR(r.rgb[3 * (3 * w + w - 1)], mean / spp, 1e-4);
}

// A unit sphere under a uniform sky, 4 units off, filling the middle of a 24 x 16
// view: the sky's pixels are flat (every sample the same), the sphere's lit by the
// sky through diffuse bounces, its silhouette's pixels partly sky.
Scene sky_and_sphere() {
  return parse_scene(R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0], "vfov": 40},
    "sky": {"type": "uniform", "radiance": [1, 1, 1]},
    "materials": [{"name": "m", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}],
    "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}, {"center": [0, -101, 0], "radius": 100, "material": "m"}]})",
                     "adaptive_scene.json");
}

RenderOptions adaptive_options(Backend b, Kernel k, double threshold, int spp) {
  RenderOptions o = test::options_for(b, k, 24, 16, spp, 6, 3, 17);
  o.noise_threshold = threshold;
  o.min_spp = 16;
  return o;
}

// The sky's pixels stop after min_spp; the sphere's edge, where sky and shade mix
// within a pixel, takes more.
TEST(AdaptiveRender, AFlatPixelConvergesBeforeAnEdge) {
  const Scene scene = sky_and_sphere();
  const RenderResult r = render(scene, adaptive_options(Backend::Cpu, Kernel::Megakernel, 0.02, 1024));
  ASSERT_EQ(r.pixel_samples.size(), 24u * 16u);
  EXPECT_EQ(r.pixel_samples[0], 16) << "the sky's corner";
  EXPECT_EQ(r.pixel_samples[23], 16) << "the sky's corner";
  // Along the middle row, from the sky across the sphere's silhouette to its middle:
  // the pixels where sky and sphere mix take the most.
  const int y = 8;
  int most = 0;
  for (int x = 0; x < 12; ++x) most = std::max(most, r.pixel_samples[y * 24 + x]);
  EXPECT_EQ(r.pixel_samples[y * 24], 16) << "the sky at the row's start";
  EXPECT_GT(most, 4 * 16) << "the silhouette took no more than a few steps";
  EXPECT_GT(r.converged, 0u);
}

// Against a converged reference (8192 samples a pixel), the converged pixels'
// relative errors have a root mean square of at most 1.25 T: each stopped where
// its neighbourhood's estimated error was at most T, and the reference's own noise
// is a twentieth of that. (T = 0.04, at most 2048 samples.)
TEST(AdaptiveRender, TheConvergedPixelsErrorIsAtMostTheThreshold) {
  const Scene scene = sky_and_sphere();
  const double t = 0.04;
  const RenderResult r = render(scene, adaptive_options(Backend::Cpu, Kernel::Megakernel, t, 2048));
  RenderOptions ref_options = test::options_for(Backend::Cpu, Kernel::Megakernel, 24, 16, 8192, 6, 3, 99);
  const RenderResult ref = render(scene, ref_options);
  double sum = 0;
  int n = 0;
  for (size_t p = 0; p < r.pixel_samples.size(); ++p) {
    if (r.pixel_samples[p] >= 2048) continue;  // stopped by spp, not by the threshold
    const double y = luminance(r.rgb[3 * p], r.rgb[3 * p + 1], r.rgb[3 * p + 2]);
    const double y_ref = luminance(ref.rgb[3 * p], ref.rgb[3 * p + 1], ref.rgb[3 * p + 2]);
    const double e = (y - y_ref) / std::max(y_ref, kNoiseFloor);
    sum += e * e;
    ++n;
  }
  ASSERT_GT(n, 200) << "too few pixels converged to measure";
  EXPECT_LE(std::sqrt(sum / n), 1.25 * t) << n << " converged pixels";
  // And the threshold bought something: fewer samples than spp on average.
  uint64_t samples = 0;
  for (int32_t s : r.pixel_samples) samples += s;
  EXPECT_LT(static_cast<double>(samples) / r.pixel_samples.size(), 0.75 * 2048);
}

// Every kernel on the CPU takes the same samples of each pixel and renders the same
// image to rounding; CUDA's kernels too, where a device is present (a pixel whose
// error lies within rounding of T may take another step there: at most 1 in 100).
TEST(AdaptiveRender, EveryKernelTakesTheSameSamples) {
  const Scene scene = sky_and_sphere();
  const RenderResult mk = render(scene, adaptive_options(Backend::Cpu, Kernel::Megakernel, 0.03, 256));
  std::vector<test::Variant> others = {{Backend::Cpu, Kernel::Wavefront}};
  if (test::cuda_available()) {
    others.push_back({Backend::Cuda, Kernel::Megakernel});
    others.push_back({Backend::Cuda, Kernel::MegakernelConstant});
    others.push_back({Backend::Cuda, Kernel::Wavefront});
  }
  for (const test::Variant& v : others) {
    SCOPED_TRACE(std::string(backend_name(v.backend)) + "/" + kernel_name(v.kernel));
    const RenderResult r = render(scene, adaptive_options(v.backend, v.kernel, 0.03, 256));
    size_t differ = 0;
    for (size_t p = 0; p < mk.pixel_samples.size(); ++p) differ += r.pixel_samples[p] != mk.pixel_samples[p];
    if (v.backend == Backend::Cpu) {
      EXPECT_EQ(differ, 0u);
    } else {
      EXPECT_LE(differ, mk.pixel_samples.size() / 100);
    }
    EXPECT_LT(test::mean_abs_diff(mk.rgb, r.rgb), 1e-3);
  }
  if (!test::cuda_available()) GTEST_SKIP() << "the CPU's kernels agree; no CUDA device for the rest";
}

// Split over three host devices (each round's pixels cut between them), the render
// is the one-device render bit for bit: every pixel's samples are rendered by one
// device, in order. Each device took a part of every round.
TEST(AdaptiveRender, SeveralDevicesRenderTheOneDeviceImage) {
  const Scene scene = sky_and_sphere();
  const RenderResult one = render(scene, adaptive_options(Backend::Cpu, Kernel::Megakernel, 0.03, 256));
  RenderOptions three = adaptive_options(Backend::Cpu, Kernel::Megakernel, 0.03, 256);
  three.devices = {0, 1, 2};
  three.threads = 3;
  const RenderResult r = render(scene, three);
  EXPECT_EQ(r.pixel_samples, one.pixel_samples);
  EXPECT_EQ(r.rgb, one.rgb);
  EXPECT_EQ(r.variance, one.variance);
  EXPECT_EQ(r.rays, one.rays);
  ASSERT_EQ(r.shares.size(), 3u);
  for (const DeviceShare& s : r.shares) {
    SCOPED_TRACE(s.device);
    EXPECT_GT(s.paths, 0u);
    EXPECT_GT(s.chunks, 2) << "a part of each round";
  }
  if (!test::cuda_available()) GTEST_SKIP() << "the CPU's devices agree; no CUDA device to split over";
  // One GPU twice: two renderers of the same device, each its own run of pixels.
  const RenderResult gpu = render(scene, adaptive_options(Backend::Cuda, Kernel::Megakernel, 0.03, 256));
  RenderOptions twice = adaptive_options(Backend::Cuda, Kernel::Megakernel, 0.03, 256);
  twice.devices = {0, 0};
  const RenderResult split = render(scene, twice);
  EXPECT_EQ(split.pixel_samples, gpu.pixel_samples);
  EXPECT_EQ(split.rgb, gpu.rgb);
}

// A render stopped after a step (after_step says so) holds its state; resumed from
// that state, it ends as the uninterrupted render does, bit for bit.
TEST(AdaptiveRender, AStoppedRenderResumedFromItsStateEndsAsTheWholeRender) {
  const Scene scene = sky_and_sphere();
  const RenderOptions o = adaptive_options(Backend::Cpu, Kernel::Megakernel, 0.03, 256);
  const RenderResult whole = render(scene, o);
  AdaptiveState kept;
  int steps = 0;
  AdaptiveHooks stop;
  stop.after_step = [&](const AdaptiveState& s, bool) {
    kept = s;
    return ++steps < 2;
  };
  const RenderResult stopped = render(scene, o, stop);
  EXPECT_TRUE(stopped.interrupted);
  EXPECT_EQ(steps, 2);
  EXPECT_LT(stopped.samples, whole.samples);
  EXPECT_EQ(kept.check(24 * 16, 256), "");
  AdaptiveHooks resume;
  resume.resume = &kept;
  std::vector<uint64_t> converged;
  resume.converged = [&](uint64_t c) { converged.push_back(c); };
  const RenderResult rest = render(scene, o, resume);
  EXPECT_FALSE(rest.interrupted);
  EXPECT_EQ(rest.pixel_samples, whole.pixel_samples);
  EXPECT_EQ(rest.rgb, whole.rgb);
  EXPECT_EQ(rest.variance, whole.variance);
  EXPECT_EQ(stopped.rays + rest.rays, whole.rays);
  // The progress line's count: never falling, ending at the render's.
  ASSERT_FALSE(converged.empty());
  EXPECT_TRUE(std::is_sorted(converged.begin(), converged.end()));
  EXPECT_EQ(converged.back(), whole.converged);
}

// Bad settings: min_spp above spp.
TEST(AdaptiveRender, MinSppAboveSppIsBadInput) {
  RenderOptions o = adaptive_options(Backend::Cpu, Kernel::Megakernel, 0.05, 8);
  o.min_spp = 16;
  try {
    render(sky_and_sphere(), o);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "--min-spp: 16 is more than the 8 samples per pixel (--spp, the most a pixel takes)");
  }
}

}  // namespace
}  // namespace wt


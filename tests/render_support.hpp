// What the whole-render tests share: every (backend, kernel) pair as a test
// parameter, the options of a small render, and image statistics.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numeric>
#include <ostream>
#include <string>
#include <vector>

#include "dispatch/renderer.hpp"
#include "scene/scene.hpp"

namespace wt::test {

struct Variant {
  Backend backend;
  Kernel kernel;
};

inline void PrintTo(const Variant& v, std::ostream* os) {
  *os << backend_name(v.backend) << "/" << kernel_name(v.kernel);
}

// "cuda_wavefront_unsorted": a test name's suffix.
inline std::string variant_name(const testing::TestParamInfo<Variant>& info) {
  std::string n = std::string(backend_name(info.param.backend)) + "_" + kernel_name(info.param.kernel);
  for (char& c : n) c = c == '-' ? '_' : c;
  return n;
}

// Every kernel on every backend that runs it (the CUDA ones skip without a device).
inline std::vector<Variant> all_variants() {
  return {{Backend::Cpu, Kernel::Megakernel},          {Backend::Cpu, Kernel::Wavefront},
          {Backend::Cpu, Kernel::WavefrontSorted},     {Backend::Cpu, Kernel::WavefrontUnsorted},
          {Backend::Cuda, Kernel::Megakernel},         {Backend::Cuda, Kernel::MegakernelConstant},
          {Backend::Cuda, Kernel::Wavefront},          {Backend::Cuda, Kernel::WavefrontSorted},
          {Backend::Cuda, Kernel::WavefrontUnsorted}};
}

inline RenderOptions options_for(Backend b, Kernel k, int w, int h, int spp, int depth, int roulette,
                                 uint32_t seed) {
  RenderOptions o;
  o.backend = b;
  o.kernel = k;
  o.params = RenderParams{w, h, spp, depth, roulette, seed};
  o.wave_size = 4096;  // several waves even for small images: regeneration is exercised
  return o;
}

inline double mean(const std::vector<float>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / v.size(); }

// The mean of independent estimates of one value, and its standard error (from
// their spread).
struct MeanAndError {
  double mean, standard_error;
};
inline MeanAndError mean_and_standard_error(const std::vector<double>& v) {
  const double avg = std::accumulate(v.begin(), v.end(), 0.0) / v.size();
  double var = 0;
  for (double x : v) var += (x - avg) * (x - avg);
  return MeanAndError{avg, std::sqrt(var / (v.size() - 1) / v.size())};
}

// The estimates' mean lies within four standard errors of `exact`, and four
// standard errors are at most `power` of it (or of `value`, where `exact` is a
// difference's 0), so that the test sees a bias that large.
inline void expect_mean_within_4_sigma(const std::vector<double>& estimates, double exact, double power,
                                       const std::string& what, double value = -1) {
  if (value < 0) value = exact;  // `power` is a share of this
  const MeanAndError e = mean_and_standard_error(estimates);
  EXPECT_NEAR(e.mean, exact, 4 * e.standard_error) << what << ": mean " << e.mean << ", standard error "
                                                    << e.standard_error;
  EXPECT_LT(4 * e.standard_error, power * value) << what << ": too noisy to see a bias of " << power;
}

// Image means of renders with two settings that must estimate the same value (one
// mean per independent seed, at least 16 each): they agree within four standard
// errors of their difference (each from its own seeds' spread, plus 1e-4 of the
// value), and four standard errors are at most `power` of the value, so that the
// test sees a bias that large (docs/testing.md lists each test's).
inline void expect_same_expectation(const std::vector<double>& a, const std::vector<double>& b, double power) {
  ASSERT_GE(a.size(), 16u);
  ASSERT_GE(b.size(), 16u);
  const MeanAndError ea = mean_and_standard_error(a), eb = mean_and_standard_error(b);
  const double ma = ea.mean, sa = ea.standard_error, mb = eb.mean, sb = eb.standard_error;
  const double four_sigma = 4.0 * std::sqrt(sa * sa + sb * sb);
  std::printf("[ power     ] 4 sigma of the difference: %.2f%% of the value\n", 100.0 * four_sigma / mb);
  EXPECT_NEAR(ma, mb, four_sigma + 1e-4 * mb) << ma << " +- " << sa << " against " << mb << " +- " << sb;
  EXPECT_LT(four_sigma, power * mb) << "too noisy to see a bias of " << power << ": " << ma << " +- " << sa
                                    << " against " << mb << " +- " << sb;
}

// The image means of 16 seeds' CPU megakernel renders of `scene` (w x h at spp,
// depth 8, roulette from 3), light sampling on or off (`nee`): one side of
// expect_same_expectation's light sampling on/off comparisons.
inline std::vector<double> seed_means(const Scene& scene, int w, int h, int spp, int nee) {
  std::vector<double> out;
  for (uint32_t seed = 1; seed <= 16; ++seed) {
    RenderOptions o = options_for(Backend::Cpu, Kernel::Megakernel, w, h, spp, 8, 3, seed);
    o.params.nee = nee;
    out.push_back(mean(render(scene, o).rgb));
  }
  return out;
}

// The CPU's wavefront kernels trace the same paths and light samples as its
// megakernel (32 x 18, 4 spp, seed 1); only the order of the film's additions
// differs, so every value agrees to 1e-5 relative.
inline void expect_cpu_wavefront_kernels_match_the_megakernel(const Scene& scene) {
  const RenderResult mk = render(scene, options_for(Backend::Cpu, Kernel::Megakernel, 32, 18, 4, 8, 3, 1));
  for (Kernel k : {Kernel::Wavefront, Kernel::WavefrontSorted, Kernel::WavefrontUnsorted}) {
    const RenderResult wf = render(scene, options_for(Backend::Cpu, k, 32, 18, 4, 8, 3, 1));
    ASSERT_EQ(wf.rgb.size(), mk.rgb.size());
    for (size_t i = 0; i < mk.rgb.size(); ++i) {
      ASSERT_NEAR(wf.rgb[i], mk.rgb[i], 1e-5f * (1.0f + std::fabs(mk.rgb[i]))) << kernel_name(k) << " " << i;
    }
  }
}

// Renders that lose no light return the sky's radiance 1 in every pixel: the mean
// of 16 seeds' CPU renders (w x h at spp, no roulette before `depth`) within 4
// standard errors of 1 (plus 1e-6, for the float sums of scenes whose every path
// returns 1), and 4 standard errors at most 0.5%.
inline void expect_vanishes_under_a_uniform_sky(const Scene& scene, int w, int h, int spp, int depth,
                                                const std::string& what) {
  std::vector<double> means;
  for (uint32_t seed = 1; seed <= 16; ++seed) {
    means.push_back(mean(render(scene, options_for(Backend::Cpu, Kernel::Megakernel, w, h, spp, depth, depth, seed)).rgb));
  }
  const MeanAndError e = mean_and_standard_error(means);
  EXPECT_NEAR(e.mean, 1.0, 4 * e.standard_error + 1e-6) << what << ": standard error " << e.standard_error;
  EXPECT_LT(4 * e.standard_error, 0.005) << what;
}

// The scene's sky made a LatLong environment of radiance 1 everywhere (a w x h
// image: every lookup blends texels of 1), its lights and table rebuilt for it.
inline void set_constant_environment(Scene& scene, int w, int h) {
  Image one;
  one.path = "one";
  one.width = w;
  one.height = h;
  one.texels.assign(static_cast<size_t>(w) * h * 4, 1.0f);
  scene.sky = Sky{SkyKind::Environment, vec3(0.0f), vec3(0.0f)};
  scene.sky.image = static_cast<int32_t>(scene.images.size());
  scene.images.push_back(one);
  build_bvh(scene);
}

inline double mean_abs_diff(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += std::fabs(static_cast<double>(a[i]) - b[i]);
  return s / a.size();
}

// Every CUDA kernel's render against the CPU megakernel's, same seed, by render(
// backend, kernel, seed). The two trace the same paths but round differently (FMA
// contraction, device sqrt and division), so a path can take another branch (a
// roulette draw, a hit at an edge) and from there on is an independent sample. The
// bounds are set against what fully independent renders differ by: the CPU's own
// render with the next seed, measured here. The CUDA image must be within a tenth
// of that difference on average per value (at most about a tenth of the paths may
// have diverged), and its mean within 3% of the CPU's (a tenth diverged moves the
// mean by about sqrt(0.2) of its own spread, a few percent at the sizes the tests
// use; the bound is there to catch energy lost or gained on one backend).
template <class Render>
void expect_cuda_agrees_with_cpu(Render render, uint32_t seed) {
  const RenderResult cpu = render(Backend::Cpu, Kernel::Megakernel, seed);
  const RenderResult other_seed = render(Backend::Cpu, Kernel::Megakernel, seed + 1);
  const double independent = mean_abs_diff(cpu.rgb, other_seed.rgb);
  ASSERT_GT(independent, 1e-3) << "two seeds should give visibly different noise";
  for (Kernel k : {Kernel::Megakernel, Kernel::MegakernelConstant, Kernel::Wavefront, Kernel::WavefrontSorted, Kernel::WavefrontUnsorted}) {
    const RenderResult gpu = render(Backend::Cuda, k, seed);
    ASSERT_EQ(gpu.rgb.size(), cpu.rgb.size()) << kernel_name(k);
    const double mad = mean_abs_diff(cpu.rgb, gpu.rgb);
    EXPECT_LT(mad, 0.1 * independent) << kernel_name(k) << " (other seed: " << independent << ")";
    EXPECT_NEAR(mean(gpu.rgb), mean(cpu.rgb), 0.03 * mean(cpu.rgb)) << kernel_name(k);
    EXPECT_NEAR(static_cast<double>(gpu.rays), static_cast<double>(cpu.rays), 2e-3 * cpu.rays) << kernel_name(k);
    EXPECT_NEAR(static_cast<double>(gpu.shadow_rays), static_cast<double>(cpu.shadow_rays), 2e-3 * cpu.shadow_rays)
        << kernel_name(k);
  }
}

}  // namespace wt::test

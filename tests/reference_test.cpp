// Converged references: small scenes that together cover the renderer's features,
// each rendered once at a high sample count by an independent renderer (the
// Mitsuba 3 peer) where the models are the same, otherwise by wavetrace itself at
// 64 times or more the test's samples (tests/data/references/manifest.json says
// which, and tools/make_references.py makes them). Every kernel of every backend,
// with light sampling on and off, must agree with each reference tile by tile.
//
// The statistics: S independent seeds render the scene; each pixel's variance is
// estimated from its S values, so a tile's mean has a variance known from
// (pixels x (S - 1)) degrees of freedom (nearly exact: the z below is close to
// normal). A tile's z is its mean's difference from the reference's, over that
// standard error (inflated by the reference's own noise, test samples / reference
// samples, and floored at 1e-4 of the value for tiles without noise). Every tile and
// channel must have |z| < 4.5: over the 2,304 tiles and channels that one variant
// tests (all references, both settings), an unbiased renderer fails by chance with
// probability about 1.6%, once for all seeds (they are fixed). The whole image's
// mean, per channel, must have |z| < 4: that is where a small bias everywhere
// shows, and the test prints the smallest relative bias each image can see (4
// sigma of its mean; docs/testing.md lists them).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "render_support.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

using nlohmann::json;

constexpr double kTileSigmas = 4.5;
constexpr double kImageSigmas = 4.0;

json manifest() {
  std::ifstream in(test::repo_path("tests/data/references/manifest.json"));
  return json::parse(in);
}

// Per pixel and channel, the mean of the seeds' values and the variance of that mean.
struct SeedStatistics {
  std::vector<double> mean, mean_variance;
};

SeedStatistics over_seeds(const Scene& scene, const test::Variant& v, const json& ref, int nee) {
  const json& t = ref.at("test");
  const int w = ref.at("width"), h = ref.at("height"), seeds = t.at("seeds"), spp = t.at("spp_per_seed");
  const size_t n = static_cast<size_t>(w) * h * 3;
  std::vector<double> sum(n, 0.0), sum2(n, 0.0);
  for (int s = 0; s < seeds; ++s) {
    RenderOptions o = test::options_for(v.backend, v.kernel, w, h, spp, ref.at("depth"), ref.at("roulette_depth"),
                                        t.at("first_seed").get<uint32_t>() + static_cast<uint32_t>(s));
    o.params.nee = nee;
    const RenderResult r = render(scene, o);
    const double per_pixel = r.radiance == Radiance::SumOfSamples ? r.samples : 1.0;
    for (size_t i = 0; i < n; ++i) {
      const double x = r.rgb[i] / per_pixel;
      sum[i] += x;
      sum2[i] += x * x;
    }
  }
  SeedStatistics out{std::vector<double>(n), std::vector<double>(n)};
  for (size_t i = 0; i < n; ++i) {
    const double m = sum[i] / seeds;
    out.mean[i] = m;
    out.mean_variance[i] = std::max(0.0, sum2[i] / seeds - m * m) / (seeds - 1);
  }
  return out;
}

// One comparison: a region's mean against the reference's, in standard errors.
struct Z {
  double z, mean, reference, sigma;
};

Z compare(const SeedStatistics& s, const std::vector<float>& reference, int w, int x0, int y0, int x1, int y1, int c,
          double reference_share) {
  double m = 0, r = 0, var = 0;
  int count = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const size_t i = 3 * (static_cast<size_t>(y) * w + x) + c;
      m += s.mean[i];
      r += reference[i];
      var += s.mean_variance[i];
      ++count;
    }
  }
  m /= count;
  r /= count;
  var /= static_cast<double>(count) * count;
  const double sigma = std::max(std::sqrt(var * (1.0 + reference_share)), 1e-4 * std::fabs(r) + 1e-7);
  return Z{(m - r) / sigma, m, r, sigma};
}

class ConvergedReference : public testing::TestWithParam<test::Variant> {};

TEST_P(ConvergedReference, EveryTileAgreesWithTheReference) {
  const test::Variant v = GetParam();
  if (v.backend == Backend::Cuda && !test::cuda_available()) GTEST_SKIP() << "no CUDA device";
  const json m = manifest();
  ASSERT_GE(m.at("references").size(), 6u);
  for (const json& ref : m.at("references")) {
    const std::string name = ref.at("name");
    const Scene scene = load_scene(test::repo_path("tests/data/references/" + ref.at("scene").get<std::string>()));
    const int w = ref.at("width"), h = ref.at("height"), tile = ref.at("test").at("tile");
    const std::vector<float> reference =
        test::read_pfm(test::repo_path("tests/data/references/" + ref.at("image").get<std::string>()), w, h);
    ASSERT_FALSE(reference.empty()) << name;
    const json& t = ref.at("test");
    const double test_samples = t.at("seeds").get<double>() * t.at("spp_per_seed").get<double>();
    const double share = test_samples / ref.at("reference_spp").get<double>();
    for (int nee : t.at("nee").get<std::vector<int>>()) {
      const std::string what = name + ", nee " + std::to_string(nee);
      const SeedStatistics s = over_seeds(scene, v, ref, nee);
      int failed = 0;
      Z worst{0, 0, 0, 0};
      for (int c = 0; c < 3; ++c) {
        for (int y0 = 0; y0 < h; y0 += tile) {
          for (int x0 = 0; x0 < w; x0 += tile) {
            const Z z = compare(s, reference, w, x0, y0, std::min(x0 + tile, w), std::min(y0 + tile, h), c, share);
            if (std::fabs(z.z) > std::fabs(worst.z)) worst = z;
            if (!(std::fabs(z.z) < kTileSigmas)) {
              if (++failed <= 4) {
                ADD_FAILURE() << what << ": tile (" << x0 << ", " << y0 << ") channel " << c << ": " << z.mean
                              << " against " << z.reference << ", z = " << z.z;
              }
            }
          }
        }
        const Z whole = compare(s, reference, w, 0, 0, w, h, c, share);
        EXPECT_LT(std::fabs(whole.z), kImageSigmas)
            << what << ": image mean, channel " << c << ": " << whole.mean << " against " << whole.reference
            << ", z = " << whole.z;
        if (c == 1) {
          std::printf("[ reference ] %s: image z %+.2f, sees a bias of %.2f%%; worst tile z %+.2f\n", what.c_str(),
                      whole.z, 100.0 * kImageSigmas * whole.sigma / std::fabs(whole.reference), worst.z);
        }
      }
      EXPECT_EQ(failed, 0) << what << ": tiles beyond " << kTileSigmas << " sigma";
    }
  }
}

// The CPU's megakernel, and every CUDA kernel (which skip without a device). The
// CPU's wavefronts trace the same paths and light samples as its megakernel, up to
// the order of the film's additions (LightSamplingRender.
// CpuWavefrontMatchesCpuMegakernelToRounding, CornellBox and the goldens), so they
// would repeat its result at several times its cost.
std::vector<test::Variant> reference_variants() {
  std::vector<test::Variant> out;
  for (const test::Variant& v : test::all_variants()) {
    if (v.backend == Backend::Cpu && v.kernel != Kernel::Megakernel) continue;
    out.push_back(v);
  }
  return out;
}

INSTANTIATE_TEST_SUITE_P(Render, ConvergedReference, testing::ValuesIn(reference_variants()), test::variant_name);

}  // namespace
}  // namespace wt

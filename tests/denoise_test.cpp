// Denoising through Open Image Denoise (src/image/denoise.hpp), loaded at run time:
// a known image under known noise comes out closer to it, with and without the
// albedo and normal guides. Skipped, with a notice, where OIDN is not installed
// (scripts/setup.sh fetches it; --denoise then refuses to run).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "image/denoise.hpp"

namespace wt {
namespace {

#define WT_REQUIRE_OIDN()                                                        \
  do {                                                                           \
    std::string why;                                                             \
    if (!oidn_available(why)) GTEST_SKIP() << "Open Image Denoise absent: " << why; \
  } while (0)

// A 128 x 96 HDR image: a smooth gradient with a bright disc (radiance up to 4),
// and the same with zero-mean noise of a path tracer's kind (relative, sd 30%).
struct Noisy {
  int w = 128, h = 96;
  std::vector<float> clean, noisy, albedo, normal;
  Noisy() {
    std::mt19937 rng(11);
    std::normal_distribution<float> n(0.0f, 0.3f);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const float dx = x - 80.0f, dy = y - 40.0f;
        const bool disc = dx * dx + dy * dy < 20.0f * 20.0f;
        const float base[3] = {0.2f + 0.5f * x / w, 0.3f + 0.4f * y / h, 0.4f};
        for (int c = 0; c < 3; ++c) {
          const float v = disc ? 4.0f : base[c];
          clean.push_back(v);
          noisy.push_back(std::max(0.0f, v * (1.0f + n(rng))));
          albedo.push_back(disc ? 0.9f : 0.5f);
        }
        normal.insert(normal.end(), {0.0f, 0.0f, 1.0f});
      }
    }
  }
  double mse(const std::vector<float>& a) const {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i) s += (a[i] - clean[i]) * (a[i] - clean[i]);
    return s / static_cast<double>(a.size());
  }
};

// The denoised image's mean squared error against the clean image is under a
// quarter of the noisy one's (OIDN's high quality removes most of this noise; a
// filter that did nothing, or blurred the disc's edge away, would not pass).
TEST(Denoise, LowersTheErrorOfANoisyImage) {
  WT_REQUIRE_OIDN();
  const Noisy im;
  for (DenoiseQuality q : {DenoiseQuality::High, DenoiseQuality::Balanced}) {
    const std::vector<float> out = denoise({im.w, im.h, im.noisy.data()}, q, DenoiseDevice::Cpu);
    ASSERT_EQ(out.size(), im.noisy.size());
    EXPECT_LT(im.mse(out), 0.25 * im.mse(im.noisy)) << (q == DenoiseQuality::High ? "high" : "balanced");
    std::printf("[ denoise   ] %s: MSE %.4g against the noisy %.4g\n", q == DenoiseQuality::High ? "high" : "balanced", im.mse(out), im.mse(im.noisy));
  }
  const std::vector<float> guided =
      denoise({im.w, im.h, im.noisy.data(), im.albedo.data(), im.normal.data()}, DenoiseQuality::High, DenoiseDevice::Cpu);
  EXPECT_LT(im.mse(guided), 0.25 * im.mse(im.noisy));
}

// A normal without an albedo is not a valid set of guides (OIDN's rule), refused
// before OIDN is called.
TEST(Denoise, ANormalNeedsAnAlbedo) {
  WT_REQUIRE_OIDN();
  const Noisy im;
  EXPECT_THROW(denoise({im.w, im.h, im.noisy.data(), nullptr, im.normal.data()}, DenoiseQuality::High,
                       DenoiseDevice::Cpu),
               std::invalid_argument);
}

}  // namespace
}  // namespace wt

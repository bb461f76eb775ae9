// The alpha-mask tile (tools/make_gltf_tiles.cpp) casts the leaf's shadow, not the
// quad's: rendered under a small distant sun, the shadow on the floor matches the
// tile's expected coverage image (alpha-mask.png) pixel by pixel, on every kernel.
//
// The tiles are the generator's own files: the CTest GltfAlphaMaskShadow writes them
// and runs this test with WAVETRACE_TILES naming their folder (the test skips,
// saying so, where it is not set).
//
// The set-up. The leaf stands in the plane z = 0 over x in [-0.4, 0.4], y in
// [0, 0.8], its texture's top row at y = 0.8. The sun shines down along
// (0, -1, -1) / sqrt 2, so the leaf's point (x, y, 0) shadows the floor's (x, 0, -y):
// the shadow is the leaf's coverage, unstretched. A camera high above looks
// straight down at that part of the floor (x right, -z up the image), where no ray
// of its meets the leaf. Depth 2: the floor's direct light alone.
#include <gtest/gtest.h>
#include <stb/stb_image.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>

#include "render_support.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

class GltfAlphaMaskShadow : public testing::TestWithParam<test::Variant> {
 protected:
  void SetUp() override {
    const char* tiles = std::getenv("WAVETRACE_TILES");
    if (!tiles) GTEST_SKIP() << "WAVETRACE_TILES is not set: the CTest GltfAlphaMaskShadow writes the tiles and sets it";
    tiles_ = tiles;
  }
  std::string tiles_;
  test::TestFolder folder_;
};

TEST_P(GltfAlphaMaskShadow, TheShadowIsTheLeafsCoverage) {
  const test::Variant v = GetParam();
  if (v.backend == Backend::Cuda) WT_REQUIRE_CUDA();
  int mw = 0, mh = 0, channels = 0;
  unsigned char* mask = stbi_load((tiles_ + "/alpha-mask.png").c_str(), &mw, &mh, &channels, 1);
  ASSERT_NE(mask, nullptr) << tiles_ << "/alpha-mask.png";
  const std::string floor = (folder_.root() / "floor.obj").string();
  std::ofstream(floor) << "v -2 0 -3\nv 2 0 -3\nv 2 0 1\nv -2 0 1\nf 1 3 2\nf 1 4 3\n";
  // The sun: radius 2 at 1000 (0.002 rad, a penumbra of 2 mm at the shadow's far end,
  // against the mask's 6 mm texels), of radiance giving the floor an irradiance near 1.
  const std::string scene_text = R"({
      "camera": {"look_from": [0, 200, -0.5], "look_at": [0, 0, -0.5], "up": [0, 0, -1], "vfov": 0.2865},
      "sky": {"type": "uniform", "radiance": [0, 0, 0]},
      "materials": [{"name": "floor", "type": "lambertian", "albedo": [1, 1, 1]},
                    {"name": "sun", "type": "emissive", "emission": [80000, 80000, 80000]}],
      "spheres": [{"center": [0, 707.107, 707.107], "radius": 2, "material": "sun"}],
      "meshes": [{"name": "floor", "file": "floor.obj", "material": "floor"},
                 {"name": "leaf", "file": ")" + tiles_ + R"(/alpha-mask.glb"}],
      "instances": [{"mesh": "floor"}, {"mesh": "leaf"}]})";
  const Scene scene = parse_scene(scene_text, (folder_.root() / "scene.json").string());
  ASSERT_EQ(scene.alpha_tests.size(), 1u);
  // The image spans 1 x 1 m of floor: x in [-0.5, 0.5], z in [-1, 0].
  const int n = 100;
  const RenderResult r = render(scene, test::options_for(v.backend, v.kernel, n, n, 16, 2, 100, 7));
  const double lit = 80000.0 * kPi * (2.0 / 1000.0) * (2.0 / 1000.0) * std::sqrt(0.5) / kPi;  // albedo / pi E cos 45
  int compared = 0, wrong = 0, edges = 0;
  for (int py = 0; py < n; ++py) {
    for (int px = 0; px < n; ++px) {
      const double x = -0.5 + (px + 0.5) / n, z = -1.0 + (py + 0.5) / n;
      const double y = -z;  // the leaf's height that shadows it
      // The leaf's texel there (u right, v down from y = 0.8), or none off the quad.
      const double u = (x + 0.4) / 0.8, t = 1.0 - y / 0.8;
      auto covered = [&](double uu, double tt) {
        if (uu < 0 || uu >= 1 || tt < 0 || tt >= 1) return false;
        return mask[static_cast<int>(tt * mh) * mw + static_cast<int>(uu * mw)] >= 128;
      };
      // Pixels within a pixel and a texel of the leaf's edge are not compared: a
      // pixel's footprint (a centimetre) straddles it, and the cutoff of the alpha's
      // bilinear magnification moves it by up to half a texel.
      const double d = 1.0 / n / 0.8 + 1.0 / mw;
      const bool here = covered(u, t);
      if (covered(u - d, t) != here || covered(u + d, t) != here || covered(u, t - d) != here ||
          covered(u, t + d) != here) {
        ++edges;
        continue;
      }
      const double value = r.rgb[3 * (static_cast<size_t>(py) * n + px) + 1] /
                           (r.radiance == Radiance::SumOfSamples ? r.samples : 1);
      const bool shadowed = value < 0.5 * lit;
      wrong += shadowed != here;
      ++compared;
      if (!here) EXPECT_NEAR(value, lit, 0.05 * lit) << "lit floor at pixel " << px << ", " << py;
    }
  }
  stbi_image_free(mask);
  EXPECT_GT(compared, 8500) << edges << " edge pixels";
  EXPECT_EQ(wrong, 0) << "of " << compared << " pixels off the leaf's edge";
}

INSTANTIATE_TEST_SUITE_P(All, GltfAlphaMaskShadow, testing::ValuesIn(test::all_variants()), test::variant_name);

}  // namespace
}  // namespace wt

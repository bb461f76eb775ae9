// The AOVs (render/aovs.hpp): the first-surface pass checked on scenes whose answer
// is known, the same on the CPU and on CUDA, and the --aov list's names.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "errors/errors.hpp"
#include "render_support.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"
#include "wavetrace/aov.hpp"

namespace wt {
namespace {

constexpr int kSize = 33;  // odd: a middle pixel

// A 33 x 33 view down -z at a unit sphere 5 units away, which covers the middle
// pixels and not the corners, under a uniform sky of radiance `sky`; `extra`
// more spheres and materials.
Scene sphere_scene(const std::string& material, const std::string& extra_materials = "",
                   const std::string& extra_spheres = "", const std::string& sky = "[2, 0.25, 0.5]") {
  const std::string doc = R"({"camera": {"look_from": [0, 0, 5], "look_at": [0, 0, 0], "vfov": 30},
    "sky": {"type": "uniform", "radiance": )" + sky + R"(},
    "materials": [)" + material + extra_materials + R"(],
    "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"})" + extra_spheres + "]}";
  return parse_scene(doc, "aov_scene.json");
}

RenderOptions aov_options(Backend backend, int spp = 16) {
  return test::options_for(backend, Kernel::Megakernel, kSize, kSize, spp, 8, 8, 7);
}

// Pixel (x, y)'s channels of an AOV image.
std::vector<float> at(const AovImage& image, int x, int y) {
  const size_t n = image.channels.size();
  const size_t i = (static_cast<size_t>(y) * kSize + x) * n;
  return std::vector<float>(image.values.begin() + i, image.values.begin() + i + n);
}

// A Lambertian surface's albedo is its colour, sample by sample (one BSDF sample's
// f cos / pdf is exactly that); its normal faces the camera; the depth is the
// distance to the sphere along the camera's ray, the position on the sphere. A pixel
// that sees only sky has the sky's radiance clamped to [0, 1] for an albedo, no
// normal, an infinite depth and a zero position.
TEST(Aovs, ALambertianSphereAndTheSkyAreWhatTheyAre) {
  const Scene scene = sphere_scene(R"({"name": "m", "type": "lambertian", "albedo": [0.3, 0.5, 0.7]})");
  const AovSums sums = render_aovs(scene, aov_options(Backend::Cpu));
  ASSERT_EQ(sums.samples, 16);
  ASSERT_EQ(sums.sums.size(), static_cast<size_t>(kSize) * kSize * kAovFloats);
  const AovImage albedo = aov_image(AovKind::Albedo, sums);
  const AovImage normal = aov_image(AovKind::Normal, sums);
  const AovImage depth = aov_image(AovKind::Depth, sums);
  const AovImage position = aov_image(AovKind::Position, sums);
  EXPECT_EQ(albedo.channels, (std::vector<std::string>{"R", "G", "B"}));
  EXPECT_EQ(normal.channels, (std::vector<std::string>{"X", "Y", "Z"}));
  EXPECT_EQ(depth.channels, (std::vector<std::string>{"Z"}));
  EXPECT_EQ(position.channels, (std::vector<std::string>{"X", "Y", "Z"}));
  const int mid = kSize / 2;
  const std::vector<float> a = at(albedo, mid, mid);
  EXPECT_NEAR(a[0], 0.3f, 1e-6f);
  EXPECT_NEAR(a[1], 0.5f, 1e-6f);
  EXPECT_NEAR(a[2], 0.7f, 1e-6f);
  // A pixel spans 30/33 degrees; over it the sphere's normal turns by under 0.02.
  const std::vector<float> n = at(normal, mid, mid);
  EXPECT_NEAR(n[0], 0.0f, 0.02f);
  EXPECT_NEAR(n[1], 0.0f, 0.02f);
  EXPECT_GT(n[2], 0.999f);
  EXPECT_NEAR(at(depth, mid, mid)[0], 4.0f, 1e-3f);
  const std::vector<float> p = at(position, mid, mid);
  EXPECT_NEAR(p[0], 0.0f, 0.02f);
  EXPECT_NEAR(p[1], 0.0f, 0.02f);
  EXPECT_NEAR(p[2], 1.0f, 1e-3f);
  // A pixel off the sphere's side: its normal leans out that way.
  EXPECT_LT(at(normal, mid - 5, mid)[0], -0.3f);
  EXPECT_GT(at(normal, mid, mid - 5)[1], 0.3f);  // row 0 is the top
  for (const auto& [x, y] : {std::pair{0, 0}, std::pair{kSize - 1, kSize - 1}}) {
    SCOPED_TRACE("corner " + std::to_string(x));
    EXPECT_EQ(at(albedo, x, y), (std::vector<float>{1.0f, 0.25f, 0.5f}));
    EXPECT_EQ(at(normal, x, y), (std::vector<float>{0.0f, 0.0f, 0.0f}));
    EXPECT_EQ(at(depth, x, y)[0], std::numeric_limits<float>::infinity());
    EXPECT_EQ(at(position, x, y), (std::vector<float>{0.0f, 0.0f, 0.0f}));
  }
}

// A mirror is passed through: the albedo is the mirror's colour times that of the
// surface it shows, the normal that surface's, while the depth and position stay
// the mirror's (the first surface). Inside a Lambertian sphere of albedo 0.5, a
// smooth metal sphere of albedo 0.8 has an albedo of 0.4; the big sphere beside it 0.5.
TEST(Aovs, AMirrorShowsTheAlbedoAndNormalOfWhatItReflects) {
  const Scene scene = sphere_scene(R"({"name": "m", "type": "metal", "albedo": [0.8, 0.8, 0.8], "fuzz": 0})",
                                   R"(, {"name": "room", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]})",
                                   R"(, {"center": [0, 0, 0], "radius": 50, "material": "room"})");
  const AovSums sums = render_aovs(scene, aov_options(Backend::Cpu));
  const AovImage albedo = aov_image(AovKind::Albedo, sums);
  const AovImage normal = aov_image(AovKind::Normal, sums);
  const AovImage depth = aov_image(AovKind::Depth, sums);
  const int mid = kSize / 2;
  for (float v : at(albedo, mid, mid)) EXPECT_NEAR(v, 0.4f, 1e-5f);
  for (float v : at(albedo, 0, 0)) EXPECT_NEAR(v, 0.5f, 1e-6f);
  // Straight back from the mirror, the room's wall behind the camera: its normal is
  // along z (either way: which side a surface's normal faces is its own), unit length.
  const std::vector<float> n = at(normal, mid, mid);
  EXPECT_GT(std::abs(n[2]), 0.99f);
  EXPECT_NEAR(at(depth, mid, mid)[0], 4.0f, 1e-3f);
  // The corner sees the room's wall, about 50 units off.
  EXPECT_NEAR(at(depth, 0, 0)[0], 50.0f, 5.0f);
}

// Smooth glass shows what lies behind and what it reflects, each as often as the
// path's own Fresnel choice takes it: over many samples, the albedo of a clear
// sphere in a room of albedo 0.5 is 0.5 wherever it is.
TEST(Aovs, SmoothGlassShowsWhatLiesBehindIt) {
  const Scene scene = sphere_scene(R"({"name": "m", "type": "dielectric", "ior": 1.5})",
                                   R"(, {"name": "room", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]})",
                                   R"(, {"center": [0, 0, 0], "radius": 50, "material": "room"})");
  const AovSums sums = render_aovs(scene, aov_options(Backend::Cpu, 64));
  const AovImage albedo = aov_image(AovKind::Albedo, sums);
  const int mid = kSize / 2;
  for (float v : at(albedo, mid, mid)) EXPECT_NEAR(v, 0.5f, 1e-5f);
}

// The sums are the CPU's on CUDA, to float rounding, on a scene with every kind of
// material, textures and a normal map (the shipped materials scene).
TEST(Aovs, CudaSumsTheCpusFirstSurfaces) {
  if (!test::cuda_available()) GTEST_SKIP() << "no CUDA device";
  const Scene scene = load_scene(test::repo_path("scenes/cornell-materials.json"));
  RenderOptions o = test::options_for(Backend::Cpu, Kernel::Megakernel, 64, 48, 8, 8, 8, 11);
  const AovSums cpu = render_aovs(scene, o);
  o.backend = Backend::Cuda;
  const AovSums gpu = render_aovs(scene, o);
  ASSERT_EQ(cpu.sums.size(), gpu.sums.size());
  size_t differ = 0;
  double worst = 0;
  for (size_t i = 0; i < cpu.sums.size(); ++i) {
    const double d = std::abs(cpu.sums[i] - gpu.sums[i]) / std::max(1.0, std::abs(static_cast<double>(cpu.sums[i])));
    worst = std::max(worst, d);
    if (d > 1e-3) ++differ;
  }
  // A sample whose rounding sends a path the other way at an edge changes one
  // pixel's sums: at most one pixel in a thousand.
  EXPECT_LE(differ, cpu.sums.size() / 1000) << "worst relative difference " << worst;
}

// After an adaptive render the pass takes each pixel's own samples: a pixel's
// depth and position are over as many hits as it took samples where every sample
// hits, and the means divide by each pixel's count. On CUDA, the CPU's sums.
TEST(Aovs, AnAdaptiveRendersPassTakesEachPixelsSamples) {
  const Scene scene = sphere_scene(R"({"name": "m", "type": "lambertian", "albedo": [0.3, 0.5, 0.7]})",
                                   R"(, {"name": "room", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]})",
                                   R"(, {"center": [0, 0, 0], "radius": 50, "material": "room"})");
  std::vector<int32_t> counts(kSize * kSize);
  for (size_t p = 0; p < counts.size(); ++p) counts[p] = 1 + static_cast<int32_t>(p % 7);
  const RenderOptions o = aov_options(Backend::Cpu, 8);
  const AovSums sums = render_aovs(scene, o, &counts);
  ASSERT_EQ(sums.pixel_samples, counts);
  for (size_t p = 0; p < counts.size(); ++p) {
    ASSERT_EQ(sums.sums[p * kAovFloats + kAovHits], static_cast<float>(counts[p])) << p;
  }
  const int mid = kSize / 2;
  for (float v : at(aov_image(AovKind::Albedo, sums), mid, mid)) EXPECT_GT(v, 0.29f);  // a mean, not a sum over 8
  EXPECT_NEAR(at(aov_image(AovKind::Albedo, sums), mid, mid)[0], 0.3f, 1e-6f);
  if (!test::cuda_available()) GTEST_SKIP() << "the CPU's pass checked; no CUDA device";
  RenderOptions g = o;
  g.backend = Backend::Cuda;
  const AovSums gpu = render_aovs(scene, g, &counts);
  ASSERT_EQ(gpu.sums.size(), sums.sums.size());
  for (size_t p = 0; p < counts.size(); ++p) {
    ASSERT_EQ(gpu.sums[p * kAovFloats + kAovHits], static_cast<float>(counts[p])) << p;
  }
}

TEST(Aovs, TheListNamesKnownAovsOnce) {
  EXPECT_EQ(parse_aovs("albedo,normal"), (std::vector<AovKind>{AovKind::Albedo, AovKind::Normal}));
  EXPECT_EQ(parse_aovs("position, depth"), (std::vector<AovKind>{AovKind::Position, AovKind::Depth}));
  const auto message = [](const std::string& list) {
    try {
      parse_aovs(list);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("albedo,shadow"), "--aov: unknown AOV 'shadow' (known: albedo, normal, depth, position, variance, spp)");
  EXPECT_EQ(message("normal,normal"), "--aov: AOV 'normal' is named twice");
  EXPECT_EQ(message("albedo,"), "--aov: unknown AOV '' (known: albedo, normal, depth, position, variance, spp)");
}

}  // namespace
}  // namespace wt

// Principled's coat, transmission, volume and emission in whole renders:
//   - a clear volume of index 1 absorbs as Beer-Lambert says along the ray through
//     a sphere's centre, exactly, on every kernel;
//   - clear volumes and thin walls of any roughness vanish under a uniform sky;
//   - light sampling on and off converge to the same image on a scene of every
//     layer, lit by a reflecting emitter;
//   - the CPU's wavefront kernels equal its megakernel (which runs every feature) on
//     a scene with the layers and on one without them, which the kernels without
//     the layers serve, and every CUDA kernel agrees with the CPU on both (the GPU
//     suite).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "render_support.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

using test::mean;
using test::options_for;

constexpr const char* kSource = "principled-layers-test.json";

// A unit sphere of `material` at the origin, seen from 4 away under a uniform sky
// of radiance 1, through a field of view narrow enough that every pixel's ray
// passes within 0.007 of the centre (a chord of 2 less 3e-5).
Scene sphere_under_sky(const std::string& material, float vfov = 0.2f) {
  return parse_scene(R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0], "vfov": )" + std::to_string(vfov) +
                         R"(}, "sky": {"type": "uniform", "radiance": [1, 1, 1]}, "materials": [)" + material + R"(],
      "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})",
                     kSource);
}

class PrincipledLayersEveryKernel : public testing::TestWithParam<test::Variant> {};

// Index 1 refracts nothing and reflects nothing (its Fresnel is 0): the ray crosses
// the sphere along a chord of 2, and the sky behind arrives times
// exp(-2 sigma), sigma = -ln(colour) / distance: (0.25, 0.64, 1) for the colour
// (0.5, 0.8, 1) over 1.
TEST_P(PrincipledLayersEveryKernel, AClearVolumeAbsorbsAsBeerLambertSays) {
  const test::Variant v = GetParam();
  if (v.backend == Backend::Cuda) WT_REQUIRE_CUDA();
  const Scene scene = sphere_under_sky(R"({"name": "m", "type": "principled", "ior": 1, "transmission": 1,
      "thin": false, "attenuation_color": [0.5, 0.8, 1], "attenuation_distance": 1})");
  const RenderResult r = render(scene, options_for(v.backend, v.kernel, 4, 4, 4, 8, 8, 1));
  for (size_t p = 0; p < r.rgb.size() / 3; ++p) {
    EXPECT_NEAR(r.rgb[3 * p + 0], 0.25f, 1e-3f) << "pixel " << p;
    EXPECT_NEAR(r.rgb[3 * p + 1], 0.64f, 1e-3f) << "pixel " << p;
    EXPECT_NEAR(r.rgb[3 * p + 2], 1.0f, 1e-3f) << "pixel " << p;
  }
}

INSTANTIATE_TEST_SUITE_P(All, PrincipledLayersEveryKernel, testing::ValuesIn(test::all_variants()), test::variant_name);

// What loses no light returns the sky in every pixel: a clear white volume (glass,
// compensated) and a white thin wall (which reflects E_s and passes the rest),
// smooth and rough. Depth 64 and no roulette; per seed 16 x 16 pixels at 128 spp,
// the mean of 16 seeds within 4 standard errors of 1 (plus 1e-6), 4 standard
// errors at most 0.5%.
TEST(PrincipledLayersRender, ClearVolumesAndThinWallsVanishUnderAUniformSky) {
  for (const char* m : {R"({"name": "m", "type": "principled", "transmission": 1, "thin": false})",
                        R"({"name": "m", "type": "principled", "transmission": 1, "thin": false, "roughness": 0.4})",
                        R"({"name": "m", "type": "principled", "transmission": 1, "roughness": 0.4})",
                        R"({"name": "m", "type": "principled", "transmission": 1})"}) {
    const Scene scene = sphere_under_sky(m, 16.0f);
    test::expect_vanishes_under_a_uniform_sky(scene, 16, 16, 128, 64, m);
  }
}

// A coated red sphere, a tinted thin wall, a rough absorbing volume and a coated
// metal on a principled ground, lit by a principled lamp that reflects as well as
// emits, and a dim sky.
const Scene& layers_scene() {
  static const Scene scene = parse_scene(R"({
    "camera": {"look_from": [0, 2.2, 6], "look_at": [0, 0.4, 0], "vfov": 40},
    "sky": {"type": "uniform", "radiance": [0.3, 0.3, 0.35]},
    "materials": [
      {"name": "ground", "type": "principled", "albedo": [0.6, 0.6, 0.6], "roughness": 0.5},
      {"name": "coated", "type": "principled", "albedo": [0.8, 0.1, 0.1], "roughness": 0.6, "clearcoat": 1,
       "clearcoat_roughness": 0.1},
      {"name": "wall", "type": "principled", "albedo": [0.9, 0.8, 0.5], "roughness": 0.3, "transmission": 0.9},
      {"name": "volume", "type": "principled", "albedo": [1, 1, 1], "roughness": 0.2, "transmission": 1, "thin": false,
       "attenuation_color": [0.9, 0.5, 0.3], "attenuation_distance": 0.5},
      {"name": "coated-metal", "type": "principled", "albedo": [0.9, 0.7, 0.3], "metallic": 1, "roughness": 0.5,
       "clearcoat": 0.7, "clearcoat_roughness": 0.3},
      {"name": "lamp", "type": "principled", "albedo": [0.5, 0.5, 0.5], "roughness": 0.4, "emission": [30, 28, 25]}],
    "spheres": [
      {"center": [0, -1000, 0], "radius": 1000, "material": "ground"},
      {"center": [-1.8, 0.5, 0], "radius": 0.5, "material": "coated"},
      {"center": [-0.6, 0.5, 0], "radius": 0.5, "material": "wall"},
      {"center": [0.6, 0.5, 0], "radius": 0.5, "material": "volume"},
      {"center": [1.8, 0.5, 0], "radius": 0.5, "material": "coated-metal"},
      {"center": [1.5, 4, 2], "radius": 0.4, "material": "lamp"}]})",
                                         kSource);
  return scene;
}

TEST(PrincipledLayersRender, AReflectingEmitterIsALight) {
  const Scene& s = layers_scene();
  int emitters = 0;
  for (const LightRef& l : s.lights) emitters += l.instance != kSkyLight && l.instance != kPunctualLight;
  EXPECT_EQ(emitters, 1) << "the lamp, a principled material that emits";
  EXPECT_TRUE(s.materials.at(5).flags & kMaterialEmits);
  EXPECT_EQ(s.materials.at(5).kind, MaterialKind::Principled);
}

// With and without light sampling: the same image mean (16 seeds each, within 4
// standard errors of the difference, at most 3% of the value).
TEST(PrincipledLayersRender, LightSamplingOnAndOffConvergeToTheSameImage) {
  auto means = [](int nee) {
    std::vector<double> out;
    for (uint32_t seed = 1; seed <= 16; ++seed) {
      RenderOptions o = options_for(Backend::Cpu, Kernel::Megakernel, 48, 27, 48, 8, 3, seed);
      o.params.nee = nee;
      out.push_back(mean(render(layers_scene(), o).rgb));
    }
    return out;
  };
  test::expect_same_expectation(means(1), means(0), 0.03);
}

// The same spheres of principled materials without a coat or transmission: the
// scene the kernels without the layers serve (kLayersAndAlpha).
const Scene& layerless_scene() {
  static const Scene scene = parse_scene(R"({
    "camera": {"look_from": [0, 2.2, 6], "look_at": [0, 0.4, 0], "vfov": 40},
    "sky": {"type": "uniform", "radiance": [0.3, 0.3, 0.35]},
    "materials": [
      {"name": "ground", "type": "principled", "albedo": [0.6, 0.6, 0.6], "roughness": 0.5},
      {"name": "red", "type": "principled", "albedo": [0.8, 0.1, 0.1], "roughness": 0.6},
      {"name": "tinted", "type": "principled", "albedo": [0.9, 0.8, 0.5], "roughness": 0.3, "specular_color": [1, 0.6, 0.3]},
      {"name": "metal", "type": "principled", "albedo": [0.9, 0.7, 0.3], "metallic": 1, "roughness": 0.5},
      {"name": "lamp", "type": "principled", "albedo": [0.5, 0.5, 0.5], "roughness": 0.4, "emission": [30, 28, 25]}],
    "spheres": [
      {"center": [0, -1000, 0], "radius": 1000, "material": "ground"},
      {"center": [-1.2, 0.5, 0], "radius": 0.5, "material": "red"},
      {"center": [0, 0.5, 0], "radius": 0.5, "material": "tinted"},
      {"center": [1.2, 0.5, 0], "radius": 0.5, "material": "metal"},
      {"center": [1.5, 4, 2], "radius": 0.4, "material": "lamp"}]})",
                                         kSource);
  return scene;
}

// The CPU's megakernel runs every feature; its wavefront, the kernels the scene
// selects: with the layers for layers_scene, without them for layerless_scene.
TEST(PrincipledLayersRender, CpuWavefrontKernelsMatchTheMegakernelToRounding) {
  ASSERT_TRUE(layers_scene().kernel_kinds() & kLayersAndAlpha);
  ASSERT_FALSE(layerless_scene().kernel_kinds() & kLayersAndAlpha);
  for (const Scene* scene : {&layers_scene(), &layerless_scene()}) {
    const RenderResult mega = render(*scene, options_for(Backend::Cpu, Kernel::Megakernel, 48, 27, 8, 8, 3, 5));
    for (Kernel k : {Kernel::Wavefront, Kernel::WavefrontSorted, Kernel::WavefrontUnsorted}) {
      const RenderResult wave = render(*scene, options_for(Backend::Cpu, k, 48, 27, 8, 8, 3, 5));
      ASSERT_EQ(wave.rgb.size(), mega.rgb.size());
      for (size_t i = 0; i < mega.rgb.size(); ++i) {
        ASSERT_NEAR(wave.rgb[i], mega.rgb[i], 1e-5f * (1.0f + std::fabs(mega.rgb[i]))) << kernel_name(k) << " " << i;
      }
      EXPECT_EQ(wave.rays, mega.rays) << kernel_name(k);
    }
  }
}

TEST(PrincipledLayersRender, EveryCudaKernelAgreesWithTheCpu) {
  WT_REQUIRE_CUDA();
  test::expect_cuda_agrees_with_cpu(
      [](Backend b, Kernel k, uint32_t seed) { return render(layers_scene(), options_for(b, k, 64, 36, 8, 8, 3, seed)); },
      3);
  test::expect_cuda_agrees_with_cpu(
      [](Backend b, Kernel k, uint32_t seed) { return render(layerless_scene(), options_for(b, k, 64, 36, 8, 8, 3, seed)); },
      3);
}

}  // namespace
}  // namespace wt

// The environment sky: each mapping looks up the texel a direction names, the turn
// and the intensity do what they say, .hdr and .exr images load as radiance (and
// bad ones are refused with the file and field named), and every kernel renders
// it: a constant environment is the uniform sky (the furnace holds), and the CUDA
// kernels agree with the CPU under a light probe.
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "image/image_io.hpp"
#include "errors/errors.hpp"
#include "render_support.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

using test::all_variants;
using test::mean;
using test::options_for;
using test::Variant;
using test::variant_name;

// An environment sky over one host image.
struct HostEnvironment {
  std::vector<float> texels;  // RGBA
  ImageView view{};
  Sky sky{SkyKind::Environment, vec3(0.0f), vec3(0.0f)};

  HostEnvironment(int w, int h, float (*value)(int x, int y), EnvironmentMapping mapping) {
    texels.resize(static_cast<size_t>(w) * h * 4);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        float* t = &texels[4 * (static_cast<size_t>(y) * w + x)];
        t[0] = value(x, y);
        t[1] = 2.0f * value(x, y);
        t[2] = 1.0f;
        t[3] = 1.0f;
      }
    view = ImageView{0, texels.data(), w, h};
    sky.image = 0;
    sky.mapping = mapping;
  }
  vec3 at(const vec3& d) const { return sky.radiance(glm::normalize(d), &view); }
};

// The direction at the centre of texel (x, y) of a w x h latitude-longitude image.
vec3 latlong_direction(int x, int y, int w, int h) {
  const double phi = 2.0 * 3.14159265358979 * (x + 0.5) / w, theta = 3.14159265358979 * (y + 0.5) / h;
  return vec3(static_cast<float>(std::sin(phi) * std::sin(theta)), static_cast<float>(std::cos(theta)),
              static_cast<float>(-std::cos(phi) * std::sin(theta)));
}

TEST(Environment, LatLongLooksUpTheTexelEachDirectionNames) {
  const HostEnvironment env(8, 4, [](int x, int y) { return static_cast<float>(x + 10 * y); },
                            EnvironmentMapping::LatLong);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) {
      const vec3 r = env.at(latlong_direction(x, y, 8, 4));
      EXPECT_NEAR(r.x, static_cast<float>(x + 10 * y), 1e-3f) << x << ", " << y;
      EXPECT_NEAR(r.y, 2.0f * static_cast<float>(x + 10 * y), 2e-3f) << x << ", " << y;
      EXPECT_EQ(r.z, 1.0f);
    }
  // The landmarks docs/scene-format.md names: +y at the top row, -y at the bottom,
  // -z at the left and right edges, +z in the middle.
  EXPECT_NEAR(env.sky.environment_uv(vec3(0, 1, 0)).y, 0.0f, 1e-6f);
  EXPECT_NEAR(env.sky.environment_uv(vec3(0, -1, 0)).y, 1.0f, 1e-6f);
  EXPECT_NEAR(env.sky.environment_uv(vec3(0, 0, -1)).x, 0.0f, 1e-6f);
  EXPECT_NEAR(env.sky.environment_uv(vec3(0, 0, 1)).x, 0.5f, 1e-6f);
  EXPECT_NEAR(env.sky.environment_uv(vec3(1, 0, 0)).x, 0.25f, 1e-6f);
}

// A smooth image, so that looking up nearby points gives nearby values.
float smooth(int x, int y) { return 2.0f + std::sin(0.4f * x) + std::cos(0.7f * y); }

// Turned by an angle about +y, the environment shows at R d what it showed at d.
TEST(Environment, TurningTheEnvironmentTurnsWhatEachDirectionSees) {
  HostEnvironment still(64, 32, smooth, EnvironmentMapping::LatLong);
  HostEnvironment turned = still;
  turned.view.texels = turned.texels.data();
  const double angle = 70.0 * 3.14159265358979 / 180.0;
  turned.sky.turn_cos = static_cast<float>(std::cos(angle));
  turned.sky.turn_sin = static_cast<float>(std::sin(angle));
  std::mt19937 rng(3);
  std::normal_distribution<float> g;
  int differ = 0;
  for (int i = 0; i < 200; ++i) {
    const vec3 d = glm::normalize(vec3(g(rng), g(rng), g(rng)));
    // R d for a turn by `angle` about +y (x toward -z).
    const vec3 rd(static_cast<float>(std::cos(angle) * d.x + std::sin(angle) * d.z), d.y,
                  static_cast<float>(-std::sin(angle) * d.x + std::cos(angle) * d.z));
    const vec3 expect = still.at(d);
    EXPECT_NEAR(turned.at(rd).x, expect.x, 1e-3f) << i;
    differ += std::fabs(turned.at(d).x - expect.x) > 1e-2f;
  }
  EXPECT_GT(differ, 100) << "the turn should change what most directions see";
}

// The mirror ball of scenes/textures/probe_*.png (tools/make_textures.cpp): the
// pixel at disc position (x, y) shows the viewing ray (0, 0, -1) reflected off the
// normal (x, y, sqrt(1 - x^2 - y^2)).
TEST(Environment, MirrorBallInvertsTheProbesReflection) {
  const HostEnvironment env(16, 16, smooth, EnvironmentMapping::MirrorBall);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  for (int i = 0; i < 500; ++i) {
    const float px = unit(rng), py = unit(rng);
    if (px * px + py * py > 0.98f) continue;
    const vec3 n(px, py, std::sqrt(1.0f - px * px - py * py));
    const vec3 view(0, 0, -1);
    const vec3 d = view - 2.0f * glm::dot(view, n) * n;
    const vec2 uv = env.sky.environment_uv(glm::normalize(d));
    EXPECT_NEAR(uv.x, 0.5f + 0.5f * px, 1e-5f) << px << ", " << py;
    EXPECT_NEAR(uv.y, 0.5f - 0.5f * py, 1e-5f) << px << ", " << py;
  }
}

// The angular map: the centre looks along -z; the distance from it grows with the
// angle from -z, to the rim at +z.
TEST(Environment, AngularMapRadiusIsTheAngleFromMinusZ) {
  const HostEnvironment env(16, 16, smooth, EnvironmentMapping::Angular);
  EXPECT_NEAR(env.sky.environment_uv(vec3(0, 0, -1)).x, 0.5f, 1e-6f);
  EXPECT_NEAR(env.sky.environment_uv(vec3(0, 0, -1)).y, 0.5f, 1e-6f);
  for (double degrees : {10.0, 45.0, 90.0, 135.0, 170.0}) {
    const double a = degrees * 3.14159265358979 / 180.0;
    const vec2 right = env.sky.environment_uv(vec3(static_cast<float>(std::sin(a)), 0, static_cast<float>(-std::cos(a))));
    EXPECT_NEAR(right.x, 0.5 + 0.5 * degrees / 180.0, 1e-5) << degrees;
    EXPECT_NEAR(right.y, 0.5, 1e-6) << degrees;
    const vec2 up = env.sky.environment_uv(vec3(0, static_cast<float>(std::sin(a)), static_cast<float>(-std::cos(a))));
    EXPECT_NEAR(up.x, 0.5, 1e-6) << degrees;
    EXPECT_NEAR(up.y, 0.5 - 0.5 * degrees / 180.0, 1e-5) << degrees;  // row 0 is the top
  }
}

TEST(Environment, IntensityScalesTheImage) {
  HostEnvironment env(8, 4, smooth, EnvironmentMapping::LatLong);
  const vec3 d(0.3f, 0.5f, -0.2f);
  const vec3 once = env.at(d);
  env.sky.intensity = 2.5f;
  const vec3 scaled = env.at(d);
  for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(scaled[k], 2.5f * once[k]);
}

// ---- Scene files ----

std::string sky_scene(const std::string& sky) {
  return R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]}, "sky": )" + sky +
         R"(, "materials": [{"name": "white", "type": "lambertian", "albedo": [1, 1, 1]}],
         "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "white"}]})";
}

std::string error_of(const std::string& json, const std::string& source) {
  try {
    parse_scene(json, source);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Environment, RadianceHdrLoadsAsLinearRadiance) {
  test::TestFolder folder;
  const int w = 4, h = 2;
  std::vector<float> rgb;
  for (int i = 0; i < w * h; ++i) rgb.insert(rgb.end(), {0.5f * i, 100.0f, 0.01f});
  ASSERT_TRUE(stbi_write_hdr((folder.root() / "sky.hdr").string().c_str(), w, h, 3, rgb.data()));
  const Scene s = parse_scene(sky_scene(R"({"type": "environment", "file": "sky.hdr", "mapping": "angular",
      "rotation": 90, "intensity": 3})"),
                              (folder.root() / "scene.json").string());
  ASSERT_EQ(s.sky.kind, SkyKind::Environment);
  EXPECT_EQ(s.sky.mapping, EnvironmentMapping::Angular);
  EXPECT_FLOAT_EQ(s.sky.intensity, 3.0f);
  EXPECT_NEAR(s.sky.turn_cos, 0.0f, 1e-7f);
  EXPECT_FLOAT_EQ(s.sky.turn_sin, 1.0f);
  ASSERT_GE(s.sky.image, 0);
  const Image& im = s.images.at(s.sky.image);
  ASSERT_EQ(im.width, w);
  ASSERT_EQ(im.height, h);
  for (int i = 0; i < w * h; ++i) {
    // Radiance's shared exponent keeps 8 bits of the largest component.
    EXPECT_NEAR(im.texels[4 * i], 0.5f * i, 0.5f * i / 128.0f + 1e-6f) << i;
    EXPECT_NEAR(im.texels[4 * i + 1], 100.0f, 100.0f / 128.0f) << i;
    EXPECT_EQ(im.texels[4 * i + 3], 1.0f);
  }
}

// A truncated Radiance file (its run-length data cut short) is refused with one
// line naming it, and does not hang the reader (stb's decoder alone loops forever
// at the end of such a file).
TEST(Environment, TruncatedRadianceHdrIsRefused) {
  test::TestFolder folder;
  std::ifstream in(test::repo_path("scenes/textures/sky_sun.hdr"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1000u);
  for (size_t keep : {size_t(200), bytes.size() / 2, bytes.size() - 1}) {
    std::ofstream(folder.root() / "cut.hdr", std::ios::binary) << bytes.substr(0, keep);
    const std::string e = error_of(sky_scene(R"({"type": "environment", "file": "cut.hdr"})"),
                                   (folder.root() / "scene.json").string());
    EXPECT_NE(e.find("/sky/file: cannot read image"), std::string::npos) << keep << ": " << e;
    EXPECT_NE(e.find("cut.hdr"), std::string::npos) << e;
    // The same bytes under another name, as an image texture (stb reads by content).
    std::ofstream(folder.root() / "cut.png", std::ios::binary) << bytes.substr(0, keep);
    const std::string t = error_of(R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
        "textures": [{"name": "t", "type": "image", "file": "cut.png"}],
        "materials": [{"name": "m", "type": "lambertian", "albedo": [1, 1, 1], "texture": "t"}],
        "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})",
                                   (folder.root() / "scene.json").string());
    EXPECT_NE(t.find("/textures/0/file: cannot read image"), std::string::npos) << keep << ": " << t;
  }
  // The whole file still loads.
  std::ofstream(folder.root() / "whole.hdr", std::ios::binary) << bytes;
  const Scene s = parse_scene(sky_scene(R"({"type": "environment", "file": "whole.hdr"})"),
                              (folder.root() / "scene.json").string());
  EXPECT_EQ(s.images.at(s.sky.image).width, 512);
}

TEST(Environment, OpenExrLoadsAndBadValuesAreRefusedNamingTheTexel) {
  test::TestFolder folder;
  const std::string good = (folder.root() / "good.exr").string(), bad = (folder.root() / "bad.exr").string();
  std::vector<float> rgb = {1.0f, 2.0f, 3.0f, 40000.0f, 0.25f, 0.0f};
  write_image(good, 2, 1, rgb, Encoding::Srgb, ExrPixels::Float);
  const Scene s = parse_scene(sky_scene(R"({"type": "environment", "file": "good.exr"})"),
                              (folder.root() / "scene.json").string());
  const Image& im = s.images.at(s.sky.image);
  ASSERT_EQ(im.width, 2);
  EXPECT_EQ(im.texels[0], 1.0f);
  EXPECT_EQ(im.texels[2], 3.0f);
  EXPECT_EQ(im.texels[4], 40000.0f);
  EXPECT_EQ(im.texels[5], 0.25f);
  rgb[4] = std::nanf("");
  write_image(bad, 2, 1, rgb, Encoding::Srgb, ExrPixels::Float);
  const std::string e = error_of(sky_scene(R"({"type": "environment", "file": "bad.exr"})"),
                                 (folder.root() / "scene.json").string());
  EXPECT_NE(e.find("/sky/file"), std::string::npos) << e;
  EXPECT_NE(e.find("bad.exr"), std::string::npos) << e;
  EXPECT_NE(e.find("texel (1, 0) holds NaN"), std::string::npos) << e;
}

TEST(Environment, BadSettingsNameTheFieldAndTheFile) {
  test::TestFolder folder;
  const std::string source = (folder.root() / "scene.json").string();
  const std::string missing = error_of(sky_scene(R"({"type": "environment", "file": "nowhere.hdr"})"), source);
  EXPECT_NE(missing.find("scene.json: /sky/file: cannot read image"), std::string::npos) << missing;
  EXPECT_NE(missing.find("nowhere.hdr"), std::string::npos) << missing;
  const std::string no_file = error_of(sky_scene(R"({"type": "environment"})"), source);
  EXPECT_NE(no_file.find("/sky"), std::string::npos) << no_file;
  EXPECT_NE(no_file.find("file"), std::string::npos) << no_file;
  ASSERT_TRUE(std::filesystem::copy_file(test::repo_path("scenes/textures/sky_sun.hdr"), folder.root() / "sky.hdr"));
  const std::string mapping =
      error_of(sky_scene(R"({"type": "environment", "file": "sky.hdr", "mapping": "cube"})"), source);
  EXPECT_NE(mapping.find("/sky/mapping: unknown mapping 'cube' (expected latlong, angular, mirror_ball)"),
            std::string::npos)
      << mapping;
  const std::string intensity =
      error_of(sky_scene(R"({"type": "environment", "file": "sky.hdr", "intensity": -1})"), source);
  EXPECT_NE(intensity.find("/sky/intensity"), std::string::npos) << intensity;
  const std::string unknown = error_of(sky_scene(R"({"type": "environment", "file": "sky.hdr", "gamma": 2})"), source);
  EXPECT_NE(unknown.find("gamma"), std::string::npos) << unknown;
}

// The brightest texel times the intensity is the most radiance the sky gives: at most
// 1e9, as every radiance of a scene.
TEST(Environment, BrightestTexelTimesIntensityIsAtMostABillion) {
  test::TestFolder folder;
  const std::vector<float> rgb = {1000.0f, 1.0f, 1.0f, 0.5f, 0.5f, 0.5f};
  ASSERT_TRUE(stbi_write_hdr((folder.root() / "sky.hdr").string().c_str(), 2, 1, 3, rgb.data()));
  const std::string source = (folder.root() / "scene.json").string();
  const std::string e = error_of(sky_scene(R"({"type": "environment", "file": "sky.hdr", "intensity": 1e7})"), source);
  EXPECT_EQ(e.rfind(source + ": /sky/intensity: the environment's brightest texel (1000", 0), 0u) << e;
  EXPECT_NE(e.find("is more than 1e9, the most radiance a scene may hold"), std::string::npos) << e;
  EXPECT_EQ(error_of(sky_scene(R"({"type": "environment", "file": "sky.hdr", "intensity": 1e6})"), source), "");
}

// ---- Every kernel ----

class EnvironmentRender : public testing::TestWithParam<Variant> {
 protected:
  void SetUp() override {
    if (GetParam().backend == Backend::Cuda) WT_REQUIRE_CUDA();
  }
};

// The furnace under an environment of 1 everywhere (a 5 x 3 image: every lookup
// blends texels of 1): a white sphere is 1 everywhere, as under the uniform sky.
TEST_P(EnvironmentRender, ConstantEnvironmentIsTheFurnace) {
  Scene scene = parse_scene(sky_scene(R"({"type": "uniform", "radiance": [1, 1, 1]})"), "furnace.json");
  test::set_constant_environment(scene, 5, 3);
  RenderOptions o = options_for(GetParam().backend, GetParam().kernel, 24, 16, 4, 8, 100, 7);
  o.params.nee = 0;  // exact for path tracing; with light sampling in expectation (light_sampling_render_test)
  const RenderResult r = render(scene, o);
  ASSERT_EQ(r.rgb.size(), 24u * 16u * 3u);
  for (size_t i = 0; i < r.rgb.size(); ++i) ASSERT_NEAR(r.rgb[i], 1.0f, 1e-5f) << "value " << i;
  EXPECT_GT(r.rays, r.paths + r.paths / 4) << "the sphere should fill a good part of the frame";
}

INSTANTIATE_TEST_SUITE_P(Render, EnvironmentRender, testing::ValuesIn(all_variants()), variant_name);

// Under the beach probe as the environment (a mirror ball, turned), every CUDA
// kernel agrees with the CPU megakernel (render_support.hpp).
RenderResult render_probe(Backend b, Kernel k, uint32_t seed) {
  static const Scene scene = [] {
    return parse_scene(R"({"camera": {"look_from": [0, 1.6, 7.5], "look_at": [0, 0.6, 0], "vfov": 35},
      "sky": {"type": "environment", "file": "textures/probe_beach.png", "mapping": "mirror_ball", "rotation": 40},
      "materials": [{"name": "clay", "type": "lambertian", "albedo": [0.75, 0.45, 0.3]},
                    {"name": "chrome", "type": "metal", "albedo": [0.9, 0.9, 0.9], "fuzz": 0},
                    {"name": "glass", "type": "dielectric", "ior": 1.5}],
      "spheres": [{"center": [0, -1000, 0], "radius": 1000, "material": "clay"},
                  {"center": [-1.3, 0.6, 0], "radius": 0.6, "material": "chrome"},
                  {"center": [0, 0.6, 0], "radius": 0.6, "material": "glass"},
                  {"center": [1.3, 0.6, 0], "radius": 0.6, "material": "clay"}]})",
                       test::repo_path("scenes/probe.json"));
  }();
  return render(scene, options_for(b, k, 64, 36, 8, 8, 3, seed));
}

TEST(EnvironmentProbe, EveryCudaKernelAgreesWithTheCpuMegakernel) {
  WT_REQUIRE_CUDA();
  test::expect_cuda_agrees_with_cpu(render_probe, 5);
}

// The shipped scene lit only by its generated sky loads and renders on the CPU,
// and is lit: the sky's sun and blue reach the sphere tops and the ground.
TEST(EnvironmentProbe, SkySunSceneRendersLit) {
  const Scene s = load_scene(test::repo_path("scenes/sky-sun.json"));
  ASSERT_EQ(s.sky.kind, SkyKind::Environment);
  const RenderResult r = render(s, options_for(Backend::Cpu, Kernel::Megakernel, 32, 18, 4, 6, 3, 1));
  EXPECT_GT(mean(r.rgb), 0.2);
}

}  // namespace
}  // namespace wt

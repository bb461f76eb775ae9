// Emission textures: an emitter's texture scales its emission where the camera
// sees it and where light sampling reaches it, so that the floor under a lamp that
// is half red and half blue is red on one side and blue on the other, with light
// sampling on and off converging to the same image.
#include <gtest/gtest.h>

#include <stb/stb_image_write.h>

#include <fstream>
#include <string>
#include <vector>

#include "dispatch/renderer.hpp"
#include "render_support.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

// A floor square at y = 0 and, above it at y = 0.8, a lamp square (both faces
// emit) of emission 4 times a 2 x 1 image: red over x < 0, blue over x > 0. A dark
// sky; the camera looks at the floor from the front, the lamp in view.
Scene red_blue_lamp(const test::TestFolder& folder) {
  const std::string root = folder.root().string();
  const unsigned char px[] = {255, 0, 0, 255, 0, 0, 255, 255};
  EXPECT_NE(stbi_write_png((root + "/halves.png").c_str(), 2, 1, 4, px, 8), 0);
  std::ofstream(root + "/floor.obj") << "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 3 2\nf 1 4 3\n";
  std::ofstream(root + "/lamp.obj") << "v -0.5 0.8 -0.5\nv 0.5 0.8 -0.5\nv 0.5 0.8 0.5\nv -0.5 0.8 0.5\n"
                                       "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  std::ofstream(root + "/scene.json") << R"({
    "camera": {"look_from": [0, 0.5, 2.6], "look_at": [0, 0.2, 0], "vfov": 50},
    "sky": {"type": "uniform", "radiance": [0, 0, 0]},
    "textures": [{"name": "halves", "type": "image", "file": "halves.png", "colorspace": "linear",
                  "wrap": "clamp", "filter": "bilinear"}],
    "materials": [{"name": "floor", "type": "lambertian", "albedo": [0.8, 0.8, 0.8]},
                  {"name": "lamp", "type": "emissive", "emission": [4, 4, 4], "emission_texture": "halves"}],
    "meshes": [{"name": "floor", "file": "floor.obj", "material": "floor"},
               {"name": "lamp", "file": "lamp.obj", "material": "lamp"}],
    "instances": [{"mesh": "floor"}, {"mesh": "lamp"}]})";
  return load_scene(root + "/scene.json");
}

// Per channel, the mean over the image's left or right half.
vec3 half_mean(const RenderResult& r, int w, int h, bool right) {
  glm::dvec3 sum(0.0);
  for (int y = 0; y < h; ++y) {
    for (int x = right ? w / 2 : 0; x < (right ? w : w / 2); ++x) {
      const size_t i = 3 * (static_cast<size_t>(y) * w + x);
      sum += glm::dvec3(r.rgb[i], r.rgb[i + 1], r.rgb[i + 2]);
    }
  }
  const double per_pixel = r.radiance == Radiance::SumOfSamples ? double(r.samples) : 1.0;
  return vec3(sum / (per_pixel * (w / 2) * h));
}

TEST(EmissionTexture, LightSamplingSeesTheTextureAsTheCameraDoes) {
  test::TestFolder folder;
  const Scene scene = red_blue_lamp(folder);
  const int w = 32, h = 24;
  std::vector<double> red[2], blue[2];  // [nee]: the left half's red, the right half's blue
  for (int nee = 0; nee < 2; ++nee) {
    for (uint32_t seed = 1; seed <= 16; ++seed) {
      RenderOptions o = test::options_for(Backend::Cpu, Kernel::Megakernel, w, h, 64, 4, 100, seed);
      o.params.nee = nee;
      const RenderResult r = render(scene, o);
      const vec3 left = half_mean(r, w, h, false), right = half_mean(r, w, h, true);
      red[nee].push_back(left.x);
      blue[nee].push_back(right.z);
      // The floor takes the colour of the lamp's half above it: with the emission
      // untextured where light sampling reaches it, both halves would be white.
      EXPECT_GT(left.x, 1.5f * left.z) << "nee " << nee << ", seed " << seed;
      EXPECT_GT(right.z, 1.5f * right.x) << "nee " << nee << ", seed " << seed;
    }
  }
  test::expect_same_expectation(red[1], red[0], 0.05);
  test::expect_same_expectation(blue[1], blue[0], 0.05);
}

}  // namespace
}  // namespace wt

// An image texture lands on a mesh the way up its author saw it, from OBJ (whose
// v = 0 is the image's bottom row) and from glTF (whose v = 0 is its top row):
// the render of a textured square that fills the view shows each quadrant of the
// image where the image has it.
#include <gtest/gtest.h>

#include <stb/stb_image_write.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "dispatch/renderer.hpp"
#include "render_support.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

// An 8 x 8 image in four quadrants: red at the top left, yellow at the top right,
// blue at the bottom left, cyan at the bottom right (row 0 at the top).
void write_quadrants(const std::string& path) {
  std::vector<unsigned char> px;
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      const bool top = y < 4, right = x >= 4;
      px.push_back(top ? 255 : 0);
      px.push_back(right ? 255 : 0);
      px.push_back(top ? 0 : 255);
      px.push_back(255);
    }
  }
  ASSERT_NE(stbi_write_png(path.c_str(), 8, 8, 4, px.data(), 8 * 4), 0);
}

// The square [-1, 1]^2 in z = 0, facing +z, with the UVs its author gives it: in
// OBJ the image's bottom-left corner is uv (0, 0).
const char* kObjSquare = R"(v -1 -1 0
v 1 -1 0
v 1 1 0
v -1 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
f 1/1 2/2 3/3
f 1/1 3/3 4/4
)";

// The same square in glTF, where the image's top-left corner is uv (0, 0): the
// vertices as above, uvs (0, 1), (1, 1), (1, 0), (0, 0).
void write_gltf_square(const std::string& folder) {
  const float positions[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const float uvs[] = {0, 1, 1, 1, 1, 0, 0, 0};
  const uint16_t indices[] = {0, 1, 2, 0, 2, 3};
  std::string bin(sizeof positions + sizeof uvs + sizeof indices, '\0');
  std::memcpy(&bin[0], positions, sizeof positions);
  std::memcpy(&bin[sizeof positions], uvs, sizeof uvs);
  std::memcpy(&bin[sizeof positions + sizeof uvs], indices, sizeof indices);
  std::ofstream(folder + "/square.bin", std::ios::binary) << bin;
  std::ofstream(folder + "/square.gltf") << R"({"asset": {"version": "2.0"}, "scene": 0,
    "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2}]}],
    "buffers": [{"uri": "square.bin", "byteLength": 92}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                    {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                    {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                   "min": [-1, -1, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                  {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}]})";
}

// The square seen head-on, filling the view, lit by a uniform sky of 1: each pixel's
// value is the texel's colour (a Lambertian plane that sees only the sky).
Scene square_scene(const test::TestFolder& folder, const std::string& mesh_file) {
  const std::string root = folder.root().string();
  write_quadrants(root + "/quadrants.png");
  std::ofstream(root + "/square.obj") << kObjSquare;
  write_gltf_square(root);
  std::ofstream(root + "/scene.json") << R"({
    "camera": {"look_from": [0, 0, 3], "look_at": [0, 0, 0], "vfov": 30},
    "sky": {"type": "uniform", "radiance": [1, 1, 1]},
    "textures": [{"name": "quadrants", "type": "image", "file": "quadrants.png", "colorspace": "linear"}],
    "materials": [{"name": "picture", "type": "lambertian", "texture": "quadrants"}],
    "meshes": [{"name": "square", "file": ")" + mesh_file + R"(", "material": "picture"}],
    "instances": [{"mesh": "square"}]})";
  return load_scene(root + "/scene.json");
}

void expect_quadrants_upright(const std::string& mesh_file) {
  test::TestFolder folder;
  const Scene scene = square_scene(folder, mesh_file);
  const int n = 16;
  const RenderResult r = render(scene, test::options_for(Backend::Cpu, Kernel::Megakernel, n, n, 8, 2, 100, 1));
  // Each quadrant's mean colour, rows from the top.
  auto quadrant = [&](bool top, bool right) {
    vec3 sum(0.0f);
    for (int y = top ? 0 : n / 2; y < (top ? n / 2 : n); ++y) {
      for (int x = right ? n / 2 : 0; x < (right ? n : n / 2); ++x) {
        const size_t i = 3 * (static_cast<size_t>(y) * n + x);
        sum += vec3(r.rgb[i], r.rgb[i + 1], r.rgb[i + 2]);
      }
    }
    const float per_pixel = r.radiance == Radiance::SumOfSamples ? float(r.samples) : 1.0f;
    return sum / (per_pixel * (n / 2) * (n / 2));
  };
  struct Expect {
    bool top, right;
    vec3 colour;
    const char* name;
  };
  for (const Expect& e : {Expect{true, false, vec3(1, 0, 0), "top left: red"},
                          Expect{true, true, vec3(1, 1, 0), "top right: yellow"},
                          Expect{false, false, vec3(0, 0, 1), "bottom left: blue"},
                          Expect{false, true, vec3(0, 1, 1), "bottom right: cyan"}}) {
    const vec3 got = quadrant(e.top, e.right);
    // Bilinear filtering blends the quadrants' borders over one texel (a sixteenth of
    // the image each side): a quadrant's mean lies within 0.2 of its colour, and a
    // flipped or mirrored image misses by about 0.8 in one channel.
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(got[c], e.colour[c], 0.2) << mesh_file << ", " << e.name << ", channel " << c;
    }
  }
}

TEST(TextureOrientation, AnObjTextureLandsTheWayUpItsAuthorSawIt) { expect_quadrants_upright("square.obj"); }

TEST(TextureOrientation, AGltfTextureLandsTheWayUpItsAuthorSawIt) { expect_quadrants_upright("square.gltf"); }

}  // namespace
}  // namespace wt

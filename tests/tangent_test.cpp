// Per-vertex tangents for normal maps (build_tangents): on a smooth UV sphere they
// are the analytic direction of increasing u, as MikkTSpace's are; a UV mirror seam
// keeps one tangent per side; a glTF file's TANGENT is used as given, and the
// shading frame at a hit is built from it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "scene/scene.hpp"
#include "test_support.hpp"
#include "wavetrace/path.hpp"

namespace wt {
namespace {

// A scene of one mesh file under a normal-mapped Lambertian (a flat checker map:
// the tangents are built, and a lookup leaves the normal as it is).
Scene normal_mapped(const test::TestFolder& folder, const std::string& mesh_file) {
  const std::string root = folder.root().string();
  std::ofstream(root + "/scene.json") << R"({
    "camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0], "vfov": 40},
    "textures": [{"name": "flat", "type": "checker", "size": 1, "even": [0.5, 0.5, 1], "odd": [0.5, 0.5, 1]}],
    "materials": [{"name": "m", "type": "lambertian", "normal_texture": "flat"}],
    "meshes": [{"name": "mesh", "file": ")" + mesh_file + R"(", "material": "m"}],
    "instances": [{"mesh": "mesh"}]})";
  return load_scene(root + "/scene.json");
}

// A unit UV sphere of `rings` x `segments` quads: u = phi / 2 pi around +y, v from
// the north pole (the image's top) down; OBJ's vt is (u, 1 - v). The seam's
// vertices are doubled (u = 0 and u = 1), as a UV map needs.
std::string uv_sphere(int rings, int segments) {
  std::ostringstream obj;
  for (int r = 0; r <= rings; ++r) {
    const double theta = kPi * r / rings;
    for (int s = 0; s <= segments; ++s) {
      const double phi = 2.0 * kPi * s / segments;
      const double x = std::sin(theta) * std::cos(phi), y = std::cos(theta), z = std::sin(theta) * std::sin(phi);
      obj << "v " << x << " " << y << " " << z << "\nvn " << x << " " << y << " " << z << "\nvt "
          << double(s) / segments << " " << 1.0 - double(r) / rings << "\n";
    }
  }
  auto id = [&](int r, int s) { return r * (segments + 1) + s + 1; };
  auto corner = [&](int i) { return std::to_string(i) + "/" + std::to_string(i) + "/" + std::to_string(i); };
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const int a = id(r, s), b = id(r, s + 1), c = id(r + 1, s + 1), d = id(r + 1, s);
      if (r > 0) obj << "f " << corner(a) << " " << corner(c) << " " << corner(b) << "\n";
      if (r < rings - 1) obj << "f " << corner(a) << " " << corner(d) << " " << corner(c) << "\n";
    }
  }
  return obj.str();
}

TEST(Tangents, OnASmoothUvSphereTheyRunAlongUAsMikkTSpaceGivesThem) {
  test::TestFolder folder;
  std::ofstream(folder.root() / "sphere.obj") << uv_sphere(24, 48);
  const Scene scene = normal_mapped(folder, "sphere.obj");
  ASSERT_EQ(scene.tangents.size(), 2 * scene.normals.size());
  size_t checked = 0;
  double worst = 1.0;
  // u runs clockwise seen from outside and v down from the pole: the negative
  // handedness, on every triangle.
  for (const TriangleShading& sh : scene.triangle_shadings) {
    ASSERT_TRUE(sh.flags & kTriangleHasTangents);
    EXPECT_TRUE(sh.flags & kTriangleTangentFlipped) << "one handedness all over";
    for (int c = 0; c < 3; ++c) {
      const vec3 n = scene.normals[sh.vertex[c]];
      if (std::fabs(n.y) > 0.999f) continue;  // the poles: u has no direction there
      // The seam's vertices (u = 0, u = 1) are a UV border: their triangles lie on
      // one side only, and the tangent there is that side's (MikkTSpace's too).
      const float u = scene.uvs[sh.vertex[c]].x;
      if (u <= 0.0f || u >= 1.0f) continue;
      // dp/dphi at the vertex, which is where u grows.
      const vec3 along = glm::normalize(vec3(-n.z, 0.0f, n.x));
      const vec3 t = scene.tangents[2 * sh.vertex[c] + 1];
      EXPECT_NEAR(glm::length(t), 1.0f, 1e-5);
      EXPECT_NEAR(glm::dot(t, n), 0.0f, 1e-5) << "orthogonal to the vertex normal";
      worst = std::min(worst, double(glm::dot(t, along)));
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000u);
  // The corners' dp/du average to the analytic tangent: the per-triangle ones alone
  // are off by half a segment's turn (3.75 degrees: cos 0.9979).
  EXPECT_GT(worst, 0.99999);
}

// Two squares side by side sharing the edge x = 0, the right one's UVs the left's
// mirrored (u = 1 on the shared edge), so the vertices of that edge are shared by
// faces of both handednesses.
const char* kMirrored = R"(v -1 -1 0
v 0 -1 0
v 0 1 0
v -1 1 0
v 1 -1 0
v 1 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/4/1
f 2/2/1 5/1/1 6/4/1
f 2/2/1 6/4/1 3/3/1
)";

TEST(Tangents, AUvMirrorSeamKeepsATangentForEachSide) {
  test::TestFolder folder;
  std::ofstream(folder.root() / "mirrored.obj") << kMirrored;
  const Scene scene = normal_mapped(folder, "mirrored.obj");
  int left = 0, right = 0;
  for (size_t i = 0; i < scene.triangles.size(); ++i) {
    const TriangleShading& sh = scene.triangle_shadings[i];
    const float cx = (scene.triangles[i].corner(0).x + scene.triangles[i].corner(1).x + scene.triangles[i].corner(2).x);
    const bool flipped = (sh.flags & kTriangleTangentFlipped) != 0;
    EXPECT_EQ(flipped, cx > 0.0f) << "the mirrored half has the other handedness";
    const uint32_t s = flipped ? 1u : 0u;
    for (int c = 0; c < 3; ++c) {
      const vec3 t = scene.tangents[2 * sh.vertex[c] + s];
      // u grows to the right on the left square and to the left on the right one,
      // the shared edge included.
      EXPECT_NEAR(t.x, flipped ? -1.0f : 1.0f, 1e-6) << "triangle " << i << " corner " << c;
    }
    (flipped ? right : left)++;
  }
  EXPECT_EQ(left, 2);
  EXPECT_EQ(right, 2);
}

// A glTF square in z = 0 facing +z whose TANGENT says +y with handedness -1 (not
// the UVs' dp/du): the tangents are the file's, and the shading frame at a hit
// follows them.
TEST(Tangents, AGltfFilesTangentsAreUsedAsGiven) {
  test::TestFolder folder;
  const float positions[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const float normals[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  const float uvs[] = {0, 1, 1, 1, 1, 0, 0, 0};
  const float tangents[] = {0, 1, 0, -1, 0, 1, 0, -1, 0, 1, 0, -1, 0, 1, 0, -1};
  const uint16_t indices[] = {0, 1, 2, 0, 2, 3};
  std::string bin;
  auto add = [&](const void* data, size_t n) { bin.append(static_cast<const char*>(data), n); };
  add(positions, sizeof positions);
  add(normals, sizeof normals);
  add(uvs, sizeof uvs);
  add(tangents, sizeof tangents);
  add(indices, sizeof indices);
  std::ofstream(folder.root() / "square.bin", std::ios::binary) << bin;
  std::ofstream(folder.root() / "square.gltf") << R"({"asset": {"version": "2.0"}, "scene": 0,
    "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "TANGENT": 3},
                                "indices": 4}]}],
    "buffers": [{"uri": "square.bin", "byteLength": 204}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                    {"buffer": 0, "byteOffset": 48, "byteLength": 48},
                    {"buffer": 0, "byteOffset": 96, "byteLength": 32},
                    {"buffer": 0, "byteOffset": 128, "byteLength": 64},
                    {"buffer": 0, "byteOffset": 192, "byteLength": 12}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                   "min": [-1, -1, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
                  {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
                  {"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC4"},
                  {"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}]})";
  const Scene scene = normal_mapped(folder, "square.gltf");
  for (const TriangleShading& sh : scene.triangle_shadings) {
    EXPECT_TRUE(sh.flags & kTriangleHasTangents);
    EXPECT_TRUE(sh.flags & kTriangleTangentFlipped);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(scene.tangents[2 * sh.vertex[c] + 1], vec3(0, 1, 0));
  }
  std::vector<ImageView> images;
  const SceneView view = host_view(scene, 16, 16, images);
  const Ray ray{vec3(0.3f, 0.2f, 2.0f), vec3(0, 0, -1)};
  const Hit hit = intersect_scene(view, ray);
  ASSERT_FALSE(hit.missed());
  const SurfacePoint sp = surface_at<kAllKinds | kMicrofacet>(view, ray, hit);  // tangents: microfacet kernels
  EXPECT_NEAR(glm::normalize(sp.dpdu).y, 1.0f, 1e-6);
  EXPECT_EQ(sp.tangent_sign, -1.0f);
}

}  // namespace
}  // namespace wt

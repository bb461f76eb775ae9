// glTF assets as their authors make them (issue 24): images embedded in a .glb's
// buffer views and in data URIs decode as their .png twins do and render the same
// image; samplers' wrap and filter modes, KHR_texture_transform and TEXCOORD_1 reach
// the textures; quantized and sparse accessors decode; the extensions a file
// requires or uses are refused or counted; bad embedded images are one line each.
#include <gtest/gtest.h>

#include <stb/stb_image_write.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "dispatch/renderer.hpp"
#include "errors/errors.hpp"
#include "render_support.hpp"
#include "scene/mesh_load.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"
#include "wavetrace/path.hpp"
#include "wavetrace/texture.hpp"

// tinygltf's own encoder (compiled in src/scene/mesh_libraries.cpp), for data URIs.
namespace tinygltf {
std::string base64_encode(unsigned char const* bytes, unsigned int len);
}

namespace wt {
namespace {

using nlohmann::json;

std::string base64(const std::string& bytes) {
  return tinygltf::base64_encode(reinterpret_cast<const unsigned char*>(bytes.data()),
                                 static_cast<unsigned>(bytes.size()));
}

template <class T>
std::string bytes_of(const std::vector<T>& v) {
  return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

// A glTF document built here: one binary buffer of views, accessors over them, and
// a unit quad in z = 0 (facing +z) whose one primitive uses material 0.
struct Doc {
  json j;
  std::string bin;

  Doc() {
    j = {{"asset", {{"version", "2.0"}}}, {"scene", 0}, {"scenes", {{{"nodes", {0}}}}},
         {"nodes", {{{"mesh", 0}}}}, {"bufferViews", json::array()}, {"accessors", json::array()}};
    const std::vector<float> p = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const std::vector<float> n = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const std::vector<float> uv0 = {0, 1, 1, 1, 1, 0, 0, 0};
    const std::vector<float> uv1 = {0.5f, 0.5f, 0.75f, 0.5f, 0.75f, 0.25f, 0.5f, 0.25f};
    const std::vector<uint16_t> idx = {0, 1, 2, 0, 2, 3};
    json attributes = {{"POSITION", accessor(view(bytes_of(p)), 5126, 4, "VEC3")},
                       {"NORMAL", accessor(view(bytes_of(n)), 5126, 4, "VEC3")},
                       {"TEXCOORD_0", accessor(view(bytes_of(uv0)), 5126, 4, "VEC2")},
                       {"TEXCOORD_1", accessor(view(bytes_of(uv1)), 5126, 4, "VEC2")}};
    j["meshes"] = {{{"primitives", {{{"attributes", attributes},
                                    {"indices", accessor(view(bytes_of(idx)), 5123, 6, "SCALAR")},
                                    {"material", 0}}}}}};
    j["materials"] = {{{"pbrMetallicRoughness", {{"metallicFactor", 0}}}}};
  }

  int view(const std::string& bytes) {
    while (bin.size() % 4) bin.push_back('\0');
    j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes.size()}});
    bin += bytes;
    return static_cast<int>(j["bufferViews"].size()) - 1;
  }
  int accessor(int view_index, int component, size_t count, const char* type, bool normalized = false) {
    json a = {{"bufferView", view_index}, {"componentType", component}, {"count", count}, {"type", type}};
    if (normalized) a["normalized"] = true;
    j["accessors"].push_back(a);
    return static_cast<int>(j["accessors"].size()) - 1;
  }
  // The base colour texture: image `image`, with `info`'s extra fields.
  void base_colour(const json& image, const json& info = json::object(), const json& sampler = json()) {
    json tex = {{"source", 0}};
    if (!sampler.is_null()) {
      j["samplers"] = {sampler};
      tex["sampler"] = 0;
    }
    j["textures"] = {tex};
    j["images"] = {image};
    json i = info;
    i["index"] = 0;
    j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = i;
  }

  // As .gltf, the buffer a data URI.
  std::string gltf() const {
    json out = j;
    out["buffers"] = {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}};
    return out.dump();
  }
  // As .glb: header, JSON chunk (space-padded), BIN chunk.
  std::string glb() const {
    json out = j;
    std::string b = bin;
    while (b.size() % 4) b.push_back('\0');
    out["buffers"] = {{{"byteLength", b.size()}}};
    std::string text = out.dump();
    while (text.size() % 4) text.push_back(' ');
    auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    std::string s = "glTF" + u32(2) + u32(static_cast<uint32_t>(12 + 8 + text.size() + 8 + b.size()));
    s += u32(static_cast<uint32_t>(text.size())) + "JSON" + text;
    s += u32(static_cast<uint32_t>(b.size())) + "BIN" + std::string(1, '\0') + b;
    return s;
  }
};

// An RGBA PNG of w x h texels, encoded in memory.
std::string png_of(int w, int h, const unsigned char* rgba) {
  std::string out;
  auto append = [](void* ctx, void* data, int size) {
    static_cast<std::string*>(ctx)->append(static_cast<const char*>(data), static_cast<size_t>(size));
  };
  EXPECT_NE(stbi_write_png_to_func(append, &out, w, h, 4, rgba, 4 * w), 0);
  return out;
}

// A 4 x 4 RGBA PNG: a grey ramp with one red texel at (1, 2).
std::string marked_png() {
  std::vector<unsigned char> px(4 * 4 * 4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      unsigned char* p = &px[4 * (4 * y + x)];
      const unsigned char g = static_cast<unsigned char>(40 + 12 * (4 * y + x));
      p[0] = p[1] = p[2] = g;
      p[3] = 255;
      if (x == 1 && y == 2) p[1] = p[2] = 0, p[0] = 255;
    }
  }
  return png_of(4, 4, px.data());
}

// The red texel, decoded from sRGB (to rounding).
bool is_red(const vec3& c) { return c.x > 0.999f && c.y == 0.0f && c.z == 0.0f; }

class GltfAssets : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& bytes) {
    const std::string path = (folder_.root() / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  // A scene of the mesh file facing the camera, lit by a white sky.
  Scene scene_of(const std::string& mesh_file) {
    write("scene.json", R"({"camera": {"look_from": [0.5, 0.5, 2], "look_at": [0.5, 0.5, 0], "vfov": 40},
      "sky": {"type": "uniform", "radiance": [1, 1, 1]}, "materials": [],
      "meshes": [{"name": "m", "file": ")" + mesh_file + R"("}], "instances": [{"mesh": "m"}]})");
    return load_scene((folder_.root() / "scene.json").string());
  }
  // The scene's texture t looked up at uv (no footprint: the magnified lookup).
  vec3 lookup(const Scene& scene, int32_t t, vec2 uv) {
    std::vector<ImageView> views;
    host_view(scene, 8, 8, views);
    SurfacePoint sp{};
    sp.has_uv = true;
    sp.uv = uv;
    return eval_texture(scene.textures.at(t), views.data(), sp);
  }
  void expect_error(const std::string& path, const std::string& what, bool scene = false) {
    try {
      if (scene) {
        scene_of(path);
      } else {
        load_mesh(path);
      }
      ADD_FAILURE() << path << " loaded; expected: " << what;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path + ": "), std::string::npos) << message;
      EXPECT_NE(message.find(what), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
  test::TestFolder folder_;
};

// The same image beside the file, in the .glb's binary buffer and in a data URI:
// the same texels, and the same rendered image to the last bit.
TEST_F(GltfAssets, EmbeddedImagesDecodeAndRenderAsTheirFileTwin) {
  const std::string png = marked_png();
  write("marked.png", png);
  Doc file, glb, datauri;
  file.base_colour({{"uri", "marked.png"}});
  glb.base_colour({{"bufferView", glb.view(png)}, {"mimeType", "image/png"}});
  datauri.base_colour({{"uri", "data:image/png;base64," + base64(png)}});
  write("file.gltf", file.gltf());
  write("embedded.glb", glb.glb());
  write("datauri.gltf", datauri.gltf());

  const TriangleMesh m = load_mesh((folder_.root() / "embedded.glb").string());
  ASSERT_EQ(m.embedded.size(), 1u);
  EXPECT_EQ(m.materials.at(0).albedo_map.image, m.source + "#images[0]");
  EXPECT_EQ(m.embedded[0].bytes, png);

  std::vector<RenderResult> renders;
  std::vector<std::vector<float>> texels;
  for (const char* f : {"file.gltf", "embedded.glb", "datauri.gltf"}) {
    const Scene scene = scene_of(f);
    ASSERT_EQ(scene.images.size(), 1u) << f;
    texels.push_back(scene.images[0].texels);
    RenderOptions o = test::options_for(Backend::Cpu, Kernel::Megakernel, 24, 16, 4, 4, 100, 7);
    renders.push_back(render(scene, o));
  }
  ASSERT_EQ(texels[0].size(), 4u * 4 * 4);
  for (size_t i = 1; i < renders.size(); ++i) {
    EXPECT_EQ(texels[i], texels[0]) << i;
    EXPECT_EQ(renders[i].rgb, renders[0].rgb) << i;
  }
  // The texture is seen: the red texel makes the image's red mean exceed its green.
  double red = 0, green = 0;
  for (size_t i = 0; i < renders[0].rgb.size(); i += 3) red += renders[0].rgb[i], green += renders[0].rgb[i + 1];
  EXPECT_GT(red, green * 1.01);
}

// A sampler's wrap modes and filters reach the scene's texture; NEAREST reads one
// texel where LINEAR blends four.
TEST_F(GltfAssets, SamplerWrapAndFilterReachTheTexture) {
  write("marked.png", marked_png());
  Doc d;
  d.base_colour({{"uri", "marked.png"}}, json::object(),
                {{"wrapS", 33071}, {"wrapT", 33648}, {"magFilter", 9728}, {"minFilter", 9729}});
  const Scene scene = scene_of(write("sampled.gltf", d.gltf()));
  const int32_t t = scene.materials.at(0).texture;
  ASSERT_GE(t, 0);
  const Texture& tex = scene.textures[t];
  EXPECT_EQ(tex.wrap_u, Wrap::Clamp);
  EXPECT_EQ(tex.wrap_v, Wrap::Mirror);
  EXPECT_EQ(tex.magnify, Filter::Nearest);
  EXPECT_EQ(tex.filter, Filter::Bilinear);
  // Nearest: anywhere inside texel (1, 2) is that texel's red, even by its edge.
  EXPECT_TRUE(is_red(lookup(scene, t, vec2(0.26f, 0.74f))));
  EXPECT_TRUE(is_red(lookup(scene, t, vec2(0.49f, 0.51f))));
  // Clamped in u: far right is column 3; mirrored in v: v = 1.375 is row 2 (0.625).
  EXPECT_EQ(lookup(scene, t, vec2(7.0f, 0.1f)), lookup(scene, t, vec2(0.9f, 0.1f)));
  EXPECT_TRUE(is_red(lookup(scene, t, vec2(0.3f, 1.375f))));

  Doc bad;
  bad.base_colour({{"uri", "marked.png"}}, json::object(), {{"wrapS", 1234}});
  expect_error(write("bad-wrap.gltf", bad.gltf()), "sampler 0 wrapS 1234 is not a wrap mode");
}

// KHR_texture_transform (offset, then rotation, then scale, as the extension orders
// them) moves the red texel: at uv' = offset + R(rotation) (scale uv).
TEST_F(GltfAssets, TextureTransformMovesATexelWhereExpected) {
  write("marked.png", marked_png());
  const json nearest = {{"magFilter", 9728}, {"minFilter", 9728}};
  const vec2 centre(1.5f / 4, 2.5f / 4);  // the red texel's centre
  {
    Doc d;
    d.base_colour({{"uri", "marked.png"}},
                  {{"extensions", {{"KHR_texture_transform", {{"offset", {0.25, 0}}, {"scale", {2, 2}}}}}}}, nearest);
    const Scene scene = scene_of(write("moved.gltf", d.gltf()));
    const int32_t t = scene.materials.at(0).texture;
    EXPECT_TRUE(is_red(lookup(scene, t, (centre - vec2(0.25f, 0.0f)) / 2.0f)));
    EXPECT_FALSE(is_red(lookup(scene, t, centre)));
  }
  {
    // The extension's own example: offset (0, 1), a quarter turn, scale 0.5 shows
    // the image's lower-left quadrant: uv (u, v) reads (v / 2, 1 - u / 2).
    Doc d;
    d.base_colour({{"uri", "marked.png"}},
                  {{"extensions",
                    {{"KHR_texture_transform", {{"offset", {0, 1}}, {"rotation", 1.57079632679}, {"scale", {0.5, 0.5}}}}}}},
                  nearest);
    const Scene scene = scene_of(write("turned.gltf", d.gltf()));
    const int32_t t = scene.materials.at(0).texture;
    // The red texel (u' 0.375, v' 0.625) is at u = 2 (1 - v') = 0.75, v = 2 u' = 0.75.
    EXPECT_TRUE(is_red(lookup(scene, t, vec2(0.75f, 0.75f))));
  }
  Doc bad;
  bad.base_colour({{"uri", "marked.png"}}, {{"extensions", {{"KHR_texture_transform", {{"scale", {1, "x"}}}}}}});
  expect_error(write("bad-transform.gltf", bad.gltf()), "KHR_texture_transform scale must be 2 numbers");
}

// One texture read for two parameters (the coat's strength and roughness, as
// glTF's sample assets pack them) is one lookup; the same image under another
// KHR_texture_transform is a texture of its own, moved as its transform says.
TEST_F(GltfAssets, OneImageUnderTwoTransformsIsTwoTextures) {
  write("marked.png", marked_png());
  for (const bool same : {true, false}) {
    json roughness = {{"index", 0}};
    if (!same) roughness["extensions"] = {{"KHR_texture_transform", {{"offset", {0.25, 0}}}}};
    Doc d;
    d.base_colour({{"uri", "marked.png"}});
    d.j["materials"][0]["extensions"]["KHR_materials_clearcoat"] = {
        {"clearcoatFactor", 1}, {"clearcoatTexture", {{"index", 0}}}, {"clearcoatRoughnessTexture", roughness}};
    const Scene scene = scene_of(write("coat.gltf", d.gltf()));
    const MaterialParams& p = scene.material_params.at(scene.materials.at(0).params);
    ASSERT_GE(p.clearcoat_texture, 0);
    ASSERT_GE(p.coat_roughness_texture, 0);
    EXPECT_EQ(p.coat_roughness_texture == p.clearcoat_texture, same);
    EXPECT_EQ(scene.textures.size(), same ? 2u : 3u);  // the base colour's, and the coat's one or two
    if (!same) {
      const vec2 centre(1.5f / 4, 2.5f / 4);  // the red texel's centre
      EXPECT_TRUE(is_red(lookup(scene, p.clearcoat_texture, centre)));
      EXPECT_TRUE(is_red(lookup(scene, p.coat_roughness_texture, centre - vec2(0.25f, 0.0f))));
      EXPECT_FALSE(is_red(lookup(scene, p.coat_roughness_texture, centre)));
    }
  }
}

// A material whose textures name texCoord 1 (or whose transform does) has the
// mesh's TEXCOORD_1 as its UVs; one naming a set the primitive lacks is refused.
TEST_F(GltfAssets, TexCoord1IsReadWhereTheTexturesNameIt) {
  const std::vector<vec2> uv1 = {{0.5f, 0.5f}, {0.75f, 0.5f}, {0.75f, 0.25f}, {0.5f, 0.25f}};
  for (const json& info : {json{{"texCoord", 1}},
                           json{{"extensions", {{"KHR_texture_transform", {{"texCoord", 1}}}}}}}) {
    Doc d;
    d.base_colour({{"uri", "marked.png"}}, info);
    const TriangleMesh m = load_mesh(write("uv1.gltf", d.gltf()));
    EXPECT_EQ(m.materials.at(0).uv_set, 1);
    ASSERT_EQ(m.uvs.size(), 4u);
    for (size_t i = 0; i < 4; ++i) EXPECT_EQ(m.uvs[i], uv1[i]) << i;
  }
  Doc plain;
  plain.base_colour({{"uri", "marked.png"}});
  EXPECT_EQ(load_mesh(write("uv0.gltf", plain.gltf())).uvs.at(1), vec2(1.0f, 1.0f));

  Doc missing;
  missing.base_colour({{"uri", "marked.png"}}, {{"texCoord", 1}});
  missing.j["meshes"][0]["primitives"][0]["attributes"].erase("TEXCOORD_1");
  expect_error(write("no-uv1.gltf", missing.gltf()), "textures read TEXCOORD_1, which the primitive does not have");
  Doc two;
  two.base_colour({{"uri", "marked.png"}}, {{"texCoord", 2}});
  expect_error(write("uv2.gltf", two.gltf()), "texCoord 2 is not supported");
}

// KHR_mesh_quantization's component types decode as the specification maps them,
// and a sparse accessor's values replace the elements it names.
TEST_F(GltfAssets, QuantizedAndSparseAccessorsDecode) {
  Doc d;
  json& attributes = d.j["meshes"][0]["primitives"][0]["attributes"];
  // Positions as shorts (not normalized), normals as normalized bytes, UVs as
  // normalized unsigned shorts.
  const std::vector<int16_t> p = {0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0};
  const std::vector<int8_t> n = {0, 0, 127, 0, 0, 127, 0, 0, 127, 0, -128, 127};
  const std::vector<uint16_t> uv = {0, 65535, 65535, 65535, 65535, 0, 0, 0};
  attributes["POSITION"] = d.accessor(d.view(bytes_of(p)), 5122, 4, "VEC3");
  attributes["NORMAL"] = d.accessor(d.view(bytes_of(n)), 5120, 4, "VEC3", true);
  attributes["TEXCOORD_0"] = d.accessor(d.view(bytes_of(uv)), 5123, 4, "VEC2", true);
  // Vertex 2 moved to (3, 3, 0) by a sparse substitution on a float copy.
  const std::vector<float> pf = {0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0};
  const int dense = d.accessor(d.view(bytes_of(pf)), 5126, 4, "VEC3");
  const std::vector<uint8_t> at = {2};
  const std::vector<float> value = {3, 3, 0};
  d.j["accessors"][dense]["sparse"] = {{"count", 1},
                                       {"indices", {{"bufferView", d.view(bytes_of(at))}, {"componentType", 5121}}},
                                       {"values", {{"bufferView", d.view(bytes_of(value))}}}};
  d.j["extensionsUsed"] = {"KHR_mesh_quantization"};
  d.j["extensionsRequired"] = {"KHR_mesh_quantization"};
  const TriangleMesh q = load_mesh(write("quantized.gltf", d.gltf()));
  ASSERT_EQ(q.positions.size(), 4u);
  EXPECT_EQ(q.positions[2], vec3(2, 2, 0));
  EXPECT_EQ(q.normals[0], vec3(0, 0, 1));
  EXPECT_EQ(q.uvs[1], vec2(1, 1));
  EXPECT_TRUE(q.warnings.empty());

  attributes["POSITION"] = dense;
  const TriangleMesh s = load_mesh(write("sparse.gltf", d.gltf()));
  EXPECT_EQ(s.positions[1], vec3(2, 0, 0));
  EXPECT_EQ(s.positions[2], vec3(3, 3, 0));

  d.j["accessors"][dense]["sparse"]["count"] = 2;  // its index view holds one
  expect_error(write("short-sparse.gltf", d.gltf()), "POSITION (accessor " + std::to_string(dense) +
                                                         ") sparse indices: elements run past the end of the buffer view");
}

// An extension the file requires and wavetrace does not read is refused; one it only
// uses is a warning that the scene counts.
TEST_F(GltfAssets, RequiredExtensionsAreRefusedAndUsedOnesCounted) {
  Doc d;
  d.j["extensionsUsed"] = {"KHR_materials_sheen", "KHR_texture_transform"};
  const TriangleMesh m = load_mesh(write("used.gltf", d.gltf()));
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_NE(m.warnings[0].find("KHR_materials_sheen is used but not read"), std::string::npos) << m.warnings[0];
  const Scene scene = scene_of("used.gltf");
  EXPECT_EQ(scene.summary().meshes.at(0).warnings, m.warnings);

  d.j["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  expect_error(write("required.gltf", d.gltf()),
               "the file requires the extension KHR_draco_mesh_compression (compressed geometry), which wavetrace does "
               "not read");
}

// Each bad embedded image is one line naming the mesh file and the image; a scene
// that uses it writes nothing (its error comes before rendering).
TEST_F(GltfAssets, BadEmbeddedImagesAreOneLineErrors) {
  const std::string png = marked_png();
  {
    Doc d;  // an image whose buffer view does not exist
    d.base_colour({{"bufferView", 99}, {"mimeType", "image/png"}});
    expect_error(write("missing.glb", d.glb()), "malformed glTF: image[0] bufferView");
  }
  {
    Doc d;  // a buffer view past the end of the buffer
    const int v = d.view(png);
    d.j["bufferViews"][v]["byteLength"] = png.size() + 4096;
    d.base_colour({{"bufferView", v}, {"mimeType", "image/png"}});
    expect_error(write("past-end.glb", d.glb()),
                 "material 'material 0': base colour texture: image 0: buffer view runs past the end of its buffer");
  }
  {
    Doc d;  // a data URI that is no image
    d.base_colour({{"uri", "data:image/png;base64," + base64("not an image at all")}});
    const std::string path = write("not-image.gltf", d.gltf());
    expect_error(path, "not-image.gltf#images[0]' (unknown image type)", true);
  }
  {
    Doc d;  // a data URI of a type tinygltf does not decode
    d.base_colour({{"uri", "data:image/webp;base64," + base64("RIFF")}});
    expect_error(write("webp.gltf", d.gltf()), "image 0: a data URI of type 'image/webp' is not an image wavetrace reads");
  }
  {
    Doc d;  // KTX2, by its MIME type and by its bytes
    d.base_colour({{"bufferView", d.view(png)}, {"mimeType", "image/ktx2"}});
    expect_error(write("ktx2.glb", d.glb()), "KTX2 / Basis Universal textures are not supported");
    Doc e;
    const std::string ktx2 = std::string("\xABKTX 20\xBB\r\n\x1A\n", 12) + std::string(64, '\0');
    e.base_colour({{"bufferView", e.view(ktx2)}, {"mimeType", "image/png"}});
    expect_error(write("ktx2-bytes.glb", e.glb()), "KTX2 / Basis Universal textures are not supported");
  }
}



// ---- Cameras ----

// "camera": {"gltf": MESH, "index": N} is the file's camera N where its node puts
// it, looking down the node's -z, placed by the mesh's first instance; its yfov is
// the vertical field of view.
TEST_F(GltfAssets, ACameraOfTheFileIsChosenByMeshAndIndex) {
  Doc d;
  d.j["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}},
                    {{"type", "orthographic"}, {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 10}}}},
                    {{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.1}}}}};
  // Camera 0 three metres above the quad's centre (looking down -z at it); camera 1
  // on a node too; camera 2 on none.
  d.j["nodes"].push_back({{"camera", 0}, {"translation", {0.5, 0.5, 3}}});
  d.j["nodes"].push_back({{"camera", 1}});
  d.j["scenes"][0]["nodes"] = {0, 1, 2};
  write("cameras.gltf", d.gltf());
  auto scene_with = [&](const std::string& camera) {
    write("scene.json", R"({"camera": )" + camera + R"(, "materials": [], "sky": {"type": "uniform", "radiance": [1, 1, 1]},
      "meshes": [{"name": "m", "file": "cameras.gltf"}], "instances": [{"mesh": "m", "translate": [1, 0, 0]}]})");
    return (folder_.root() / "scene.json").string();
  };
  const Scene scene = load_scene(scene_with(R"({"gltf": "m", "index": 0})"));
  EXPECT_EQ(scene.camera.look_from, vec3(1.5f, 0.5f, 3.0f));
  EXPECT_EQ(scene.camera.look_at, vec3(1.5f, 0.5f, 2.0f));
  EXPECT_EQ(scene.camera.up, vec3(0.0f, 1.0f, 0.0f));
  EXPECT_FLOAT_EQ(scene.camera.vfov_degrees, static_cast<float>(0.5 * 180.0 / kPi));
  // Seen from it, the (white-sky-lit) quad fills the image's centre.
  const RenderResult r = render(scene, test::options_for(Backend::Cpu, Kernel::Megakernel, 8, 8, 4, 2, 100, 1));
  // (The sky seen directly is 1 in every channel; the quad, a grey dielectric-
  // coated surface, less.)
  EXPECT_GT(r.rgb[3 * (4 * 8 + 4)], 0.0f);
  EXPECT_LT(r.rgb[3 * (4 * 8 + 4)], 0.95f * r.samples);

  const std::pair<const char*, const char*> bad[] = {
      {R"({"gltf": "m", "index": 3})", "/camera/index: camera 3 of mesh 'm' is out of range (its file has 3 cameras)"},
      {R"({"gltf": "m", "index": 1})", "/camera/index: camera 1 of mesh 'm' is orthographic"},
      {R"({"gltf": "m", "index": 2})", "/camera/index: camera 2 of mesh 'm' is on no node of the file's scene"},
      {R"({"gltf": "n"})", "/camera/gltf: unknown mesh 'n'"},
      {R"({"gltf": "m", "look_from": [0, 0, 0]})", "/camera"},
      {R"({"gltf": "m", "aperture": 0.1})", "/camera/aperture: needs focus_distance"},
  };
  for (const auto& [camera, message] : bad) {
    const std::string path = scene_with(camera);
    try {
      load_scene(path);
      ADD_FAILURE() << camera << " loaded";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + ": " + message), std::string::npos) << e.what();
    }
  }
}


// ---- Alpha ----

// A 4 x 4 RGBA PNG, white, opaque where (x + y) is even and clear elsewhere.
std::string checker_alpha_png() {
  std::vector<unsigned char> px(4 * 4 * 4, 255);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) px[4 * (4 * y + x) + 3] = (x + y) % 2 == 0 ? 255 : 0;
  }
  return png_of(4, 4, px.data());
}

// alphaMode MASK cuts the quad out texel by texel: a ray down onto it (a camera's or
// a bounce's) and a shadow ray up through it pass where the texel is clear and stop
// where it is opaque, alike.
TEST_F(GltfAssets, AlphaMaskLetsEveryRayThroughCutOutTexelsAlike) {
  write("holes.png", checker_alpha_png());
  Doc d;
  d.base_colour({{"uri", "holes.png"}}, json::object(), {{"magFilter", 9728}, {"minFilter", 9728}});
  d.j["materials"][0]["alphaMode"] = "MASK";
  d.j["materials"][0]["doubleSided"] = true;
  const Scene scene = scene_of(write("mask.gltf", d.gltf()));
  ASSERT_EQ(scene.alpha_tests.size(), 1u);
  EXPECT_EQ(scene.alpha_tests[0].mode, AlphaMode::Mask);
  EXPECT_FLOAT_EQ(scene.alpha_tests[0].cutoff, 0.5f);
  // The kernels that test alpha are the ones with the layers and alpha.
  EXPECT_EQ(scene.kernel_kinds() & (kAlphaTested | kMicrofacet), kAlphaTested | kMicrofacet);
  std::vector<ImageView> views;
  const SceneView view = host_view(scene, 8, 8, views);
  for (int ty = 0; ty < 4; ++ty) {
    for (int tx = 0; tx < 4; ++tx) {
      // Texel (tx, ty)'s centre: u = x, v = 1 - y on the quad.
      const float x = (tx + 0.5f) / 4, y = 1.0f - (ty + 0.5f) / 4;
      const bool opaque = (tx + ty) % 2 == 0;
      const Hit down = intersect_scene(view, Ray{vec3(x, y, 2.0f), vec3(0, 0, -1)});
      EXPECT_EQ(!down.missed(), opaque) << tx << ", " << ty;
      EXPECT_EQ(occluded(view, Ray{vec3(x, y, -1.0f), vec3(0, 0, 1)}, 3.0f), opaque) << tx << ", " << ty;
    }
  }
  // An alpha at the cutoff is there (alpha >= cutoff), and a higher cutoff clears more.
  Doc opaque;
  opaque.j["materials"][0]["alphaMode"] = "MASK";
  opaque.j["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {1, 1, 1, 0.5};
  const Scene there = scene_of(write("at-cutoff.gltf", opaque.gltf()));
  EXPECT_TRUE(there.alpha_tests.empty());  // wholly there: no test
  EXPECT_FALSE(there.kernel_kinds() & kAlphaTested) << "an opaque glTF runs the kernels without alpha";
  opaque.j["materials"][0]["alphaCutoff"] = 0.6;
  const Scene gone = scene_of(write("below-cutoff.gltf", opaque.gltf()));
  ASSERT_EQ(gone.alpha_tests.size(), 1u);
  std::vector<ImageView> gone_views;
  EXPECT_TRUE(intersect_scene(host_view(gone, 8, 8, gone_views), Ray{vec3(0.5f, 0.5f, 2.0f), vec3(0, 0, -1)}).missed());
}

// alphaMode BLEND lets a ray through with the chance of its transparency: over many
// rays the share that meet the quad is its alpha (within 4 standard errors); an
// instance that puts its own material in place of the file's makes it opaque.
TEST_F(GltfAssets, AlphaBlendStopsRaysByItsAlphaOnAverage) {
  Doc d;
  d.j["materials"][0]["alphaMode"] = "BLEND";
  d.j["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {1, 1, 1, 0.3};
  const Scene scene = scene_of(write("blend.gltf", d.gltf()));
  ASSERT_EQ(scene.alpha_tests.size(), 1u);
  std::vector<ImageView> views;
  const SceneView view = host_view(scene, 8, 8, views);
  const int n = 20000;
  int hits = 0;
  Rng rng = Rng::at(1, 2, 3, 0);
  for (int i = 0; i < n; ++i) {
    const Ray ray{vec3(0.05f + 0.9f * rng.uniform(0), 0.05f + 0.9f * rng.uniform(1), 2.0f), vec3(0, 0, -1)};
    rng = Rng::at(1, 2, 3, static_cast<uint32_t>(i + 1));
    hits += intersect_scene(view, ray).missed() ? 0 : 1;
  }
  EXPECT_NEAR(hits / double(n), 0.3, 4.0 * std::sqrt(0.3 * 0.7 / n));

  write("scene.json", R"({"camera": {"look_from": [0.5, 0.5, 2], "look_at": [0.5, 0.5, 0]}, "materials": [
    {"name": "grey", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}],
    "meshes": [{"name": "m", "file": "blend.gltf"}], "instances": [{"mesh": "m", "material": "grey"}]})");
  const Scene over = load_scene((folder_.root() / "scene.json").string());
  std::vector<ImageView> over_views;
  const SceneView ov = host_view(over, 8, 8, over_views);
  for (int i = 0; i < 100; ++i) {
    EXPECT_FALSE(intersect_scene(ov, Ray{vec3(0.01f * i + 0.005f, 0.5f, 2.0f), vec3(0, 0, -1)}).missed()) << i;
  }
}

// A lamp quad whose left half is cut away by MASK lights the floor below on its right
// half only, seen by paths that meet it and by light sampling alike: the floor's
// halves converge to the same means with next-event estimation on and off.
class AlphaLamp : public GltfAssets {
 protected:
  Scene lamp_scene() {
    const unsigned char px[] = {255, 255, 255, 0, 255, 255, 255, 255};  // clear | opaque
    write("half.png", png_of(2, 1, px));
    Doc d;
    d.base_colour({{"uri", "half.png"}}, json::object(), {{"magFilter", 9728}, {"minFilter", 9728}, {"wrapS", 33071}});
    d.j["materials"][0]["alphaMode"] = "MASK";
    d.j["materials"][0]["emissiveFactor"] = {1, 1, 1};
    d.j["materials"][0]["extensions"] = {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}}};
    write("lamp.gltf", d.gltf());
    write("floor.obj", "v -1 -1 0\nv 2 -1 0\nv 2 2 0\nv -1 2 0\nf 1 2 3\nf 1 3 4\n");
    write("scene.json", R"({"camera": {"look_from": [0.5, 0.5, 3], "look_at": [0.5, 0.5, 0], "vfov": 60},
      "sky": {"type": "uniform", "radiance": [0, 0, 0]},
      "materials": [{"name": "floor", "type": "lambertian", "albedo": [0.8, 0.8, 0.8]}],
      "meshes": [{"name": "floor", "file": "floor.obj", "material": "floor"}, {"name": "lamp", "file": "lamp.gltf"}],
      "instances": [{"mesh": "floor"}, {"mesh": "lamp", "translate": [0, 0, 0.8]}]})");
    return load_scene((folder_.root() / "scene.json").string());
  }
};

TEST_F(AlphaLamp, LightSamplingSeesTheCutOutAsPathsDo) {
  const Scene scene = lamp_scene();
  ASSERT_EQ(scene.alpha_tests.size(), 1u);
  const int w = 32, h = 32;
  // The floor's strips under the lamp's two halves, x in [0.1, 0.4] and [0.6, 0.9]
  // (the camera looks straight down from 3 m: the image spans 3.46 m).
  auto strip = [&](const RenderResult& r, float x0, float x1) {
    double sum = 0.0;
    int count = 0;
    for (int py = 0; py < h; ++py) {
      for (int px = 0; px < w; ++px) {
        const float x = 0.5f + ((px + 0.5f) / w - 0.5f) * 3.4641f, y = 0.5f - ((py + 0.5f) / h - 0.5f) * 3.4641f;
        if (x < x0 || x > x1 || y < 0.1f || y > 0.9f) continue;
        sum += r.rgb[3 * (static_cast<size_t>(py) * w + px) + 1];
        ++count;
      }
    }
    return sum / (count * (r.radiance == Radiance::SumOfSamples ? r.samples : 1));
  };
  std::vector<double> left[2], right[2];
  for (int nee = 0; nee < 2; ++nee) {
    for (uint32_t seed = 1; seed <= 16; ++seed) {
      RenderOptions o = test::options_for(Backend::Cpu, Kernel::Megakernel, w, h, 256, 3, 100, seed);
      o.params.nee = nee;
      const RenderResult r = render(scene, o);
      left[nee].push_back(strip(r, 0.1f, 0.4f));
      right[nee].push_back(strip(r, 0.6f, 0.9f));
    }
  }
  // The floor sees the lamp's right half from under both strips, but the lamp itself
  // is seen only where opaque: from above, the left strip is the floor lit from the
  // side, the right strip is the lamp's back (it emits on both faces).
  test::expect_same_expectation(left[1], left[0], 0.05);
  test::expect_same_expectation(right[1], right[0], 0.05);
  EXPECT_GT(test::mean_and_standard_error(right[1]).mean, 2.0 * test::mean_and_standard_error(left[1]).mean);
}

TEST_F(AlphaLamp, CudaAgreesWithCpu) {
  WT_REQUIRE_CUDA();
  const Scene scene = lamp_scene();
  test::expect_cuda_agrees_with_cpu(
      [&](Backend b, Kernel k, uint32_t seed) { return render(scene, test::options_for(b, k, 32, 32, 8, 4, 100, seed)); },
      21);
}

// ---- KHR_lights_punctual ----

// A 20 m square floor in z = 0 (a white-sky-free scene: black) under one light of
// `light` (the extension's object) on a node `node` (its translation, rotation),
// seen from straight above by a narrow camera, the floor Lambertian of albedo 0.5.
class PunctualLights : public GltfAssets {
 protected:
  Scene lit(const json& light, const json& node, const char* sky = "[0, 0, 0]", float vfov = 4.0f) {
    Doc d;
    d.j["nodes"][0]["scale"] = {20, 20, 1};
    d.j["nodes"][0]["translation"] = {-10, -10, 0};
    json n = node;
    n["extensions"] = {{"KHR_lights_punctual", {{"light", 0}}}};
    d.j["nodes"].push_back(n);
    d.j["scenes"][0]["nodes"] = {0, 1};
    d.j["extensions"] = {{"KHR_lights_punctual", {{"lights", {light}}}}};
    d.j["extensionsUsed"] = {"KHR_lights_punctual"};
    write("lit.gltf", d.gltf());
    write("scene.json", std::string(R"({"camera": {"look_from": [0, 0, 3], "look_at": [0, 0, 0], "up": [0, 1, 0],
      "vfov": )") + std::to_string(vfov) + R"(}, "sky": {"type": "uniform", "radiance": )" + sky + R"(},
      "materials": [{"name": "white", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}],
      "meshes": [{"name": "m", "file": "lit.gltf", "material": "white"}], "instances": [{"mesh": "m"}]})");
    return load_scene((folder_.root() / "scene.json").string());
  }
  // The mean of the image's central 2 x 2 pixels' green (all channels alike here).
  static double centre(const RenderResult& r, int w, int h) {
    double sum = 0.0;
    for (int y = h / 2 - 1; y <= h / 2; ++y) {
      for (int x = w / 2 - 1; x <= w / 2; ++x) sum += r.rgb[3 * (static_cast<size_t>(y) * w + x) + 1];
    }
    return sum / (4.0 * (r.radiance == Radiance::SumOfSamples ? r.samples : 1));
  }
  static double pixel(const RenderResult& r, int w, int x, int y) {
    return r.rgb[3 * (static_cast<size_t>(y) * w + x) + 1] / (r.radiance == Radiance::SumOfSamples ? r.samples : 1.0);
  }
};

// Radiance of the floor below: albedo / pi times the irradiance, I cos / d^2 for a
// point (candela as W / sr), E cos for a directional light (lux as W / m^2), with
// next-event estimation on and off (punctual lights are sampled either way) and on
// both CPU kernels.
TEST_F(PunctualLights, GiveTheAnalyticIrradianceOnAPlane) {
  const double albedo_over_pi = 0.5 / kPi;
  const int w = 16, h = 16;
  struct Case {
    json light, node;
    double radiance;  // at the centre
  };
  const double s30 = 0.5, c30 = std::sqrt(3.0) / 2.0;  // the directional light 60 degrees from the vertical
  const Case cases[] = {
      {{{"type", "point"}, {"intensity", 8}, {"color", {1, 1, 1}}}, {{"translation", {0, 0, 2}}}, albedo_over_pi * 8 / 4},
      {{{"type", "point"}, {"intensity", 8}, {"range", 4}}, {{"translation", {0, 0, 2}}},
       albedo_over_pi * 8 / 4 * (1 - std::pow(2.0 / 4.0, 4))},
      {{{"type", "spot"}, {"intensity", 8}, {"spot", {{"innerConeAngle", 0.1}, {"outerConeAngle", 0.2}}}},
       {{"translation", {0, 0, 2}}}, albedo_over_pi * 8 / 4},
      {{{"type", "directional"}, {"intensity", 3}}, {{"rotation", {s30, 0, 0, c30}}}, albedo_over_pi * 3 * 0.5},
  };
  for (const Case& c : cases) {
    const Scene scene = lit(c.light, c.node);
    ASSERT_EQ(scene.punctual_lights.size(), 1u) << c.light;
    for (Kernel k : {Kernel::Megakernel, Kernel::Wavefront}) {
      for (int nee = 0; nee < 2; ++nee) {
        RenderOptions o = test::options_for(Backend::Cpu, k, w, h, 8, 2, 100, 3);
        o.params.nee = nee;
        const RenderResult r = render(scene, o);
        EXPECT_NEAR(centre(r, w, h), c.radiance, 1e-3 * c.radiance) << c.light << " " << kernel_name(k) << " nee " << nee;
      }
    }
  }
}

// A spot lights its inner cone fully, nothing past its outer cone, and the ring
// between by the extension's smooth step: the floor 2 m below, seen 1 m across.
TEST_F(PunctualLights, ASpotLightsItsConeAndNothingPastIt) {
  const Scene scene = lit({{"type", "spot"}, {"intensity", 8}, {"spot", {{"innerConeAngle", 0.1}, {"outerConeAngle", 0.2}}}},
                          {{"translation", {0, 0, 2}}}, "[0, 0, 0]", 2.0f * std::atan(0.5f / 3.0f) * 180.0f / kPi);
  const int w = 32, h = 32;
  const RenderResult r = render(scene, test::options_for(Backend::Cpu, Kernel::Megakernel, w, h, 4, 2, 100, 5));
  // Corners, at 0.7 m from the axis: past the outer cone (2 tan 0.2 = 0.41 m).
  for (int x : {0, w - 1}) {
    for (int y : {0, h - 1}) EXPECT_EQ(pixel(r, w, x, y), 0.0) << x << ", " << y;
  }
  // At the centre, within the inner cone (0.2 m): I / d^2 at d = 2, times albedo / pi.
  EXPECT_NEAR(centre(r, w, h), 0.5 / kPi * 8 / 4, 2e-3);
  // Between the cones (0.3 m out, along x): lit, but less than the centre.
  const double mid = pixel(r, w, w / 2 + static_cast<int>(0.3 / (1.0 / w)), h / 2);
  EXPECT_GT(mid, 0.0);
  EXPECT_LT(mid, 0.9 * centre(r, w, h));
}

// Every CUDA kernel renders a scene of the three kinds of punctual light as the CPU
// does (a grey sky and three bounces for noise to compare by).
TEST_F(PunctualLights, CudaAgreesWithCpu) {
  WT_REQUIRE_CUDA();
  Doc d;
  d.j["nodes"][0]["scale"] = {20, 20, 1};
  d.j["nodes"][0]["translation"] = {-10, -10, 0};
  for (int i = 0; i < 3; ++i) {
    json n = {{"translation", {0.3 * i, 0, 1.5}}, {"extensions", {{"KHR_lights_punctual", {{"light", i}}}}}};
    if (i == 2) n["rotation"] = {0.5, 0, 0, std::sqrt(3.0) / 2.0};
    d.j["nodes"].push_back(n);
  }
  d.j["scenes"][0]["nodes"] = {0, 1, 2, 3};
  d.j["extensions"] = {{"KHR_lights_punctual",
                        {{"lights",
                          {{{"type", "point"}, {"intensity", 4}, {"color", {1, 0.5, 0.25}}},
                           {{"type", "spot"}, {"intensity", 6}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.5}}}},
                           {{"type", "directional"}, {"intensity", 1.5}}}}}}};
  write("three.gltf", d.gltf());
  write("scene.json", R"({"camera": {"look_from": [0, -2, 2], "look_at": [0, 0, 0], "up": [0, 0, 1], "vfov": 60},
    "sky": {"type": "uniform", "radiance": [0.2, 0.2, 0.2]},
    "materials": [{"name": "grey", "type": "lambertian", "albedo": [0.6, 0.6, 0.6]}],
    "meshes": [{"name": "m", "file": "three.gltf", "material": "grey"}], "instances": [{"mesh": "m"}]})");
  const Scene scene = load_scene((folder_.root() / "scene.json").string());
  ASSERT_EQ(scene.punctual_lights.size(), 3u);
  test::expect_cuda_agrees_with_cpu(
      [&](Backend b, Kernel k, uint32_t seed) { return render(scene, test::options_for(b, k, 48, 32, 8, 4, 100, seed)); },
      11);
}

TEST_F(PunctualLights, BadLightsAreOneLineErrors) {
  const std::pair<json, std::string> cases[] = {
      {{{"type", "area"}}, "light 0: type 'area' is not point, spot or directional"},
      {{{"type", "point"}, {"intensity", -1}}, "light 0: intensity must be in [0, 1e9]"},
      {{{"type", "point"}, {"color", {1, 2, 0}}}, "light 0: color must be 3 numbers in [0, 1]"},
      {{{"type", "spot"}, {"spot", {{"innerConeAngle", 0.5}, {"outerConeAngle", 0.4}}}},
       "light 0: spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi / 2"},
  };
  for (const auto& [light, message] : cases) {
    Doc d;
    d.j["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    d.j["scenes"][0]["nodes"] = {0, 1};
    d.j["extensions"] = {{"KHR_lights_punctual", {{"lights", {light}}}}};
    expect_error(write("bad-light.gltf", d.gltf()), message);
  }
  Doc d;
  d.j["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 3}}}}}});
  d.j["scenes"][0]["nodes"] = {0, 1};
  expect_error(write("no-light.gltf", d.gltf()), "node 1: KHR_lights_punctual: light index 3 out of range (0 lights)");
}

}  // namespace
}  // namespace wt

// wavetrace-gltf-tiles OUTDIR
//
// Writes small glTF 2.0 test assets ("tiles"), one glTF feature each, so that
// the glTF reader and the materials can be tested and shown one feature at a
// time (scenes/gltf-tiles.json lays tiles 1-11 out on a grid). Every tile fits
// the unit tile box: x and z in [-0.5, 0.5], y in [0, 1]; metres, +y up.
// Meshes wind counter-clockwise seen from the side they face, carry unit
// NORMALs and TEXCOORD_0 (v = 0 at the image's top row), TANGENT where noted.
// Images are PNGs embedded in the GLB's binary buffer unless noted.
//
//  1 metal-rough-spheres.glb   5 x 5 spheres, metallicFactor 0..1 across x,
//                              roughnessFactor 0..1 along z: the core
//                              metallic-roughness model without textures.
//  2 metal-rough-textured.glb  a floor quad with TANGENT and four texture slots:
//                              baseColorTexture (sRGB checker),
//                              metallicRoughnessTexture (B metallic: left half
//                              0, right half 1; G roughness: a ramp down the
//                              rows; R 1), normalTexture (bumps, scale 0.8),
//                              occlusionTexture (the mr image's R, strength 1).
//    metal-rough-textured.gltf the same model with external PNGs
//                              (metal-rough-textured-{base,mr,normal}.png) and
//                              an external buffer (metal-rough-textured.bin):
//                              must render as the GLB does.
//    metal-rough-textured-datauri.gltf  the same, images and buffer as base64
//                              data URIs.
//  3 alpha-mask.glb            a standing leaf cut out by alphaMode MASK
//                              (cutoff 0.5, double-sided); alpha-mask.png is the
//                              expected coverage (one channel, 255 where
//                              alpha >= cutoff), to compare its shadow against.
//  4 alpha-blend.glb           alphaMode BLEND: a quad of constant alpha 0.5 and
//                              one whose texture alpha ramps 0..1 left to right.
//  5 normal-tangent.glb        the same normal map on two quads, the left with
//                              TANGENT, the right without (the renderer derives
//                              tangents): the two must look alike.
//  6 texture-transform.glb     a checker with one red texel at (4, 4): plain
//                              (left), through KHR_texture_transform (right:
//                              offset (0.25, 0), scale 2), and read through
//                              texCoord 1 = 0.5 TEXCOORD_0 (top).
//  7 emissive-strength.glb     an emissive disc texture times emissiveFactor,
//                              times KHR_materials_emissive_strength 4.
//  8 transmission-volume.glb   KHR_materials_transmission: thin; with
//                              KHR_materials_volume and KHR_materials_ior 1.5;
//                              ior 1.33 and roughness 0.3.
//  9 clearcoat.glb             a red sphere with KHR_materials_clearcoat, one
//                              without, one with KHR_materials_specular.
// 10 punctual-lights.glb       a grey floor under KHR_lights_punctual point,
//                              spot and directional lights.
// 11 camera.glb                a unit cube and two perspective cameras.
// 12 required-unknown.glb      a plain quad whose file requires
//                              KHR_draco_mesh_compression: must be refused.
//
// glTF is written only through tinygltf's writer, PNG only through
// stb_image_write. Every pixel and vertex is a pure function of its position
// (no random state), so two runs write identical files.
#include <stb/stb_image_write.h>

// tinygltf's default image writer (used for the data URIs) calls stb_image_write,
// included above from its Debian path; this tool reads no images.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE_WRITE
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "wavetrace/config.hpp"

namespace {

using wt::kPi;
using wt::vec2;
using wt::vec3;
using wt::vec4;

std::filesystem::path g_outdir;

// ------------------------------------------------------------------ images

struct Pixels {
  int width, height, channels;
  std::vector<unsigned char> data;

  Pixels(int w, int h, int c) : width(w), height(h), channels(c), data(static_cast<size_t>(w) * h * c, 0) {}

  unsigned char* at(int x, int y) { return &data[(static_cast<size_t>(y) * width + x) * channels]; }
};

unsigned char byte_of(float v) { return static_cast<unsigned char>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

void stb_to_vector(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<unsigned char>*>(context);
  const auto* bytes = static_cast<const unsigned char*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

std::vector<unsigned char> encode_png(const Pixels& p) {
  std::vector<unsigned char> png;
  stbi_write_png_to_func(stb_to_vector, &png, p.width, p.height, p.channels, p.data.data(), 0);
  return png;
}

bool write_png(const std::string& name, const Pixels& p) {
  std::string path = (g_outdir / name).string();
  if (!stbi_write_png(path.c_str(), p.width, p.height, p.channels, p.data.data(), 0)) {
    std::fprintf(stderr, "wavetrace-gltf-tiles: cannot write %s\n", path.c_str());
    return false;
  }
  return true;
}

// 8 x 8 cells of two sRGB colours.
Pixels base_checker() {
  Pixels p(64, 64, 3);
  const unsigned char light[3] = {232, 222, 196}, dark[3] = {178, 72, 46};
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) std::memcpy(p.at(x, y), ((x / 8 + y / 8) & 1) ? dark : light, 3);
  return p;
}

// R occlusion 1, G roughness ramp down the rows, B metallic 0 | 1 by halves.
Pixels metal_rough_map() {
  Pixels p(64, 64, 3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      unsigned char* t = p.at(x, y);
      t[0] = 255;
      t[1] = static_cast<unsigned char>(std::lround(255.0 * y / 63.0));
      t[2] = x < 32 ? 0 : 255;
    }
  return p;
}

// A 4 x 4 grid of domes, h = A (1 - (r/R)^2)^2, as a tangent-space normal map:
// +x right, +y up the image, RGB = 0.5 + 0.5 n. The slope is analytic.
Pixels bumps_normal_map() {
  const float cell = 16.0f, radius = 6.0f, height = 3.0f;  // in texels
  Pixels p(64, 64, 3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      float cx = x + 0.5f - (std::floor(x / cell) + 0.5f) * cell;
      float cy = -(y + 0.5f - (std::floor(y / cell) + 0.5f) * cell);  // up the image
      float q = (cx * cx + cy * cy) / (radius * radius);
      float k = q < 1.0f ? -4.0f * height * (1.0f - q) / (radius * radius) : 0.0f;  // dh/dr / r
      vec3 n = glm::normalize(vec3(-k * cx, -k * cy, 1.0f));
      unsigned char* t = p.at(x, y);
      for (int c = 0; c < 3; ++c) t[c] = byte_of(0.5f + 0.5f * n[c]);
    }
  return p;
}

// The leaf: an ellipse with a V notch cut into its top, in [-1, 1]^2 (y up).
bool in_leaf(int x, int y, int size) {
  float u = 2.0f * (x + 0.5f) / size - 1.0f, v = 1.0f - 2.0f * (y + 0.5f) / size;
  bool ellipse = (u / 0.6f) * (u / 0.6f) + (v / 0.9f) * (v / 0.9f) <= 1.0f;
  bool notch = v - 0.5f > 1.5f * std::fabs(u);
  return ellipse && !notch;
}

Pixels leaf_rgba() {
  Pixels p(128, 128, 4);
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 128; ++x) {
      // The colour runs on outside the leaf, so filtering leaves no dark fringe.
      unsigned char* t = p.at(x, y);
      t[0] = 70, t[1] = 150, t[2] = 52;
      t[3] = in_leaf(x, y, 128) ? 255 : 0;
    }
  return p;
}

// The coverage MASK with cutoff 0.5 gives the leaf: alpha is 0 or 255.
Pixels leaf_coverage(const Pixels& rgba) {
  Pixels p(rgba.width, rgba.height, 1);
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x)
      p.at(x, y)[0] = rgba.data[(static_cast<size_t>(y) * rgba.width + x) * 4 + 3] >= 128 ? 255 : 0;
  return p;
}

Pixels alpha_ramp() {
  Pixels p(64, 64, 4);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      unsigned char* t = p.at(x, y);
      t[0] = 230, t[1] = 120, t[2] = 40;
      t[3] = static_cast<unsigned char>(std::lround(255.0 * x / 63.0));
    }
  return p;
}

// Grey and white 4 x 4 squares, and one red texel at (4, 4) to find the origin by.
Pixels marked_checker() {
  Pixels p(32, 32, 3);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      unsigned char g = ((x / 4 + y / 4) & 1) ? 128 : 255;
      unsigned char* t = p.at(x, y);
      t[0] = t[1] = t[2] = g;
    }
  unsigned char* red = p.at(4, 4);
  red[0] = 255, red[1] = 0, red[2] = 0;
  return p;
}

Pixels white_disc() {
  Pixels p(16, 16, 3);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      float dx = x + 0.5f - 8.0f, dy = y + 0.5f - 8.0f;
      unsigned char v = dx * dx + dy * dy <= 36.0f ? 255 : 0;
      unsigned char* t = p.at(x, y);
      t[0] = t[1] = t[2] = v;
    }
  return p;
}

// ---------------------------------------------------------------- geometry

struct Geometry {
  std::vector<vec3> positions, normals;
  std::vector<vec2> uvs;
  std::vector<vec4> tangents;  // empty: none written
  std::vector<uint32_t> indices;
};

// A rectangle centred at c spanning +-right and +-up; it faces right x up.
// u runs along right, v down the up vector, so the image stands upright seen
// from the front; the tangent is right (w = 1: bitangent = up the image).
Geometry quad(const vec3& c, const vec3& right, const vec3& up, bool with_tangent) {
  Geometry g;
  vec3 n = glm::normalize(glm::cross(right, up));
  g.positions = {c - right - up, c + right - up, c + right + up, c - right + up};
  g.normals.assign(4, n);
  g.uvs = {vec2(0, 1), vec2(1, 1), vec2(1, 0), vec2(0, 0)};
  if (with_tangent) g.tangents.assign(4, vec4(glm::normalize(right), 1.0f));
  g.indices = {0, 1, 2, 0, 2, 3};
  return g;
}

// A floor quad (y = 0, facing +y): the image's top row lies towards -z.
Geometry floor_quad(float half_x, float half_z, bool with_tangent) {
  return quad(vec3(0), vec3(half_x, 0, 0), vec3(0, 0, -half_z), with_tangent);
}

// A quad standing in the z = 0 plane, facing +z, from y0 to y1.
Geometry standing_quad(float x0, float x1, float y0, float y1) {
  return quad(vec3(0.5f * (x0 + x1), 0.5f * (y0 + y1), 0), vec3(0.5f * (x1 - x0), 0, 0),
              vec3(0, 0.5f * (y1 - y0), 0), false);
}

// A UV sphere resting on y = 0 (its centre at y = radius, so the lowest pole
// is exactly 0 in float): rings from +y (v = 0) to -y (v = 1), u round from +z
// towards +x. The poles' degenerate triangles are left out.
Geometry uv_sphere(float radius, int segments, int rings) {
  Geometry g;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      float v = static_cast<float>(r) / rings, u = static_cast<float>(s) / segments;
      float theta = kPi * v, phi = 2.0f * kPi * u;
      vec3 n(std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi));
      if (r == 0 || r == rings) n = vec3(0, r == 0 ? 1.0f : -1.0f, 0);  // exact poles
      g.normals.push_back(glm::normalize(n));
      g.positions.push_back(radius * g.normals.back() + vec3(0, radius, 0));
      g.uvs.push_back(vec2(u, v));
    }
  const uint32_t row = static_cast<uint32_t>(segments) + 1;
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      uint32_t a = r * row + s, b = a + row, c = b + 1, d = a + 1;
      if (r != rings - 1) g.indices.insert(g.indices.end(), {a, b, c});
      if (r != 0) g.indices.insert(g.indices.end(), {a, c, d});
    }
  return g;
}

// The unit cube standing on y = 0: six faces of their own normals and full UVs.
Geometry unit_cube() {
  Geometry g;
  const vec3 normals[6] = {vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 0, 1), vec3(0, 0, -1), vec3(0, 1, 0), vec3(0, -1, 0)};
  for (const vec3& n : normals) {
    vec3 up = n.y > 0 ? vec3(0, 0, -1) : n.y < 0 ? vec3(0, 0, 1) : vec3(0, 1, 0);
    Geometry f = quad(vec3(0, 0.5f, 0) + 0.5f * n, 0.5f * glm::cross(up, n), 0.5f * up, false);
    uint32_t base = static_cast<uint32_t>(g.positions.size());
    g.positions.insert(g.positions.end(), f.positions.begin(), f.positions.end());
    g.normals.insert(g.normals.end(), f.normals.begin(), f.normals.end());
    g.uvs.insert(g.uvs.end(), f.uvs.begin(), f.uvs.end());
    for (uint32_t i : f.indices) g.indices.push_back(base + i);
  }
  return g;
}

// ---------------------------------------------------------------- the model

tinygltf::Value number(double v) { return tinygltf::Value(v); }

tinygltf::Value numbers(std::initializer_list<double> vs) {
  tinygltf::Value::Array a;
  for (double v : vs) a.push_back(tinygltf::Value(v));
  return tinygltf::Value(a);
}

tinygltf::Value object(std::initializer_list<std::pair<const std::string, tinygltf::Value>> members) {
  return tinygltf::Value(tinygltf::Value::Object(members));
}

// How a file holds its images: in the GLB buffer, in PNG files beside a .gltf,
// or as data URIs.
enum class ImageStore { kBuffer, kFiles, kDataUri };

class Tile {
 public:
  explicit Tile(ImageStore store = ImageStore::kBuffer) : store_(store) {
    model_.asset.version = "2.0";
    model_.asset.generator = "wavetrace-gltf-tiles";
    model_.buffers.resize(1);
    model_.scenes.resize(1);
    model_.defaultScene = 0;
  }

  void use(const std::string& extension, bool required = false) {
    auto add = [&](std::vector<std::string>& list) {
      if (std::find(list.begin(), list.end(), extension) == list.end()) list.push_back(extension);
    };
    add(model_.extensionsUsed);
    if (required) add(model_.extensionsRequired);
  }

  // The geometry's accessors as a primitive without a material; meshes may share them.
  tinygltf::Primitive primitive(const Geometry& g, const std::vector<vec2>& uv1 = {}) {
    tinygltf::Primitive p;
    p.mode = TINYGLTF_MODE_TRIANGLES;
    size_t n = g.positions.size();
    vec3 lo = g.positions[0], hi = g.positions[0];
    for (const vec3& v : g.positions) lo = glm::min(lo, v), hi = glm::max(hi, v);
    p.attributes["POSITION"] = accessor(g.positions.data(), n, TINYGLTF_TYPE_VEC3, 3, {lo.x, lo.y, lo.z},
                                        {hi.x, hi.y, hi.z});
    p.attributes["NORMAL"] = accessor(g.normals.data(), n, TINYGLTF_TYPE_VEC3, 3);
    p.attributes["TEXCOORD_0"] = accessor(g.uvs.data(), n, TINYGLTF_TYPE_VEC2, 2);
    if (!g.tangents.empty()) p.attributes["TANGENT"] = accessor(g.tangents.data(), n, TINYGLTF_TYPE_VEC4, 4);
    if (!uv1.empty()) p.attributes["TEXCOORD_1"] = accessor(uv1.data(), n, TINYGLTF_TYPE_VEC2, 2);
    int view = buffer_view(g.indices.data(), g.indices.size() * sizeof(uint32_t),
                           TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    a.count = g.indices.size();
    a.type = TINYGLTF_TYPE_SCALAR;
    p.indices = static_cast<int>(model_.accessors.size());
    model_.accessors.push_back(a);
    return p;
  }

  int mesh(const std::string& name, tinygltf::Primitive p, int material) {
    p.material = material;
    tinygltf::Mesh m;
    m.name = name;
    m.primitives.push_back(p);
    model_.meshes.push_back(m);
    return static_cast<int>(model_.meshes.size()) - 1;
  }

  // A root node of the scene (translations in double, so the JSON shows 0.3, not
  // its float).
  tinygltf::Node& node(const std::string& name, const glm::dvec3& translation = glm::dvec3(0)) {
    tinygltf::Node n;
    n.name = name;
    if (translation != glm::dvec3(0)) n.translation = {translation.x, translation.y, translation.z};
    model_.scenes[0].nodes.push_back(static_cast<int>(model_.nodes.size()));
    model_.nodes.push_back(n);
    return model_.nodes.back();
  }

  void mesh_node(const std::string& name, tinygltf::Primitive p, int material,
                 const glm::dvec3& at = glm::dvec3(0)) {
    int m = mesh(name, std::move(p), material);
    node(name, at).mesh = m;
  }

  tinygltf::Material& material(const std::string& name) {
    tinygltf::Material m;
    m.name = name;
    model_.materials.push_back(m);
    return model_.materials.back();
  }
  int last_material() const { return static_cast<int>(model_.materials.size()) - 1; }

  int sampler(int mag, int min) {
    tinygltf::Sampler s;
    s.magFilter = mag;
    s.minFilter = min;
    model_.samplers.push_back(s);
    return static_cast<int>(model_.samplers.size()) - 1;
  }

  // An image and a texture of it; returns the texture's index. file_name names
  // the PNG beside a .gltf (ImageStore::kFiles).
  int texture(const std::string& name, const Pixels& p, int sampler, const std::string& file_name = "") {
    tinygltf::Image image;
    image.name = name;
    image.mimeType = "image/png";
    if (store_ == ImageStore::kBuffer) {
      std::vector<unsigned char> png = encode_png(p);
      image.bufferView = buffer_view(png.data(), png.size(), 0);
    } else {
      // tinygltf encodes these pixels into the data URI; for kFiles it only
      // names the file, which write_png writes.
      image.width = p.width;
      image.height = p.height;
      image.component = p.channels;
      image.bits = 8;
      image.pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
      image.image = p.data;
      if (store_ == ImageStore::kFiles) {
        image.uri = file_name;
        pending_files_.push_back({file_name, p});
      }
    }
    model_.images.push_back(image);
    tinygltf::Texture t;
    t.source = static_cast<int>(model_.images.size()) - 1;
    t.sampler = sampler;
    model_.textures.push_back(t);
    return static_cast<int>(model_.textures.size()) - 1;
  }

  tinygltf::Model& model() { return model_; }

  bool write(const std::string& name, const std::string& buffer_file = "") {
    for (const auto& f : pending_files_)
      if (!write_png(f.first, f.second)) return false;
    model_.buffers[0].uri = buffer_file;
    bool binary = store_ == ImageStore::kBuffer;
    bool embed = store_ == ImageStore::kDataUri;
    std::string path = (g_outdir / name).string();
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToFile(&model_, path, embed, embed, !binary, binary)) {
      std::fprintf(stderr, "wavetrace-gltf-tiles: cannot write %s\n", path.c_str());
      return false;
    }
    return true;
  }

 private:
  // Appends bytes, each view starting 4-byte aligned.
  int buffer_view(const void* data, size_t bytes, int target) {
    std::vector<unsigned char>& buf = model_.buffers[0].data;
    buf.resize((buf.size() + 3) & ~size_t(3), 0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buf.size();
    v.byteLength = bytes;
    v.target = target;
    const auto* b = static_cast<const unsigned char*>(data);
    buf.insert(buf.end(), b, b + bytes);
    model_.bufferViews.push_back(v);
    return static_cast<int>(model_.bufferViews.size()) - 1;
  }

  int accessor(const void* data, size_t count, int type, int components, std::vector<double> lo = {},
               std::vector<double> hi = {}) {
    tinygltf::Accessor a;
    a.bufferView = buffer_view(data, count * components * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.count = count;
    a.type = type;
    a.minValues = std::move(lo);
    a.maxValues = std::move(hi);
    model_.accessors.push_back(a);
    return static_cast<int>(model_.accessors.size()) - 1;
  }

  tinygltf::Model model_;
  ImageStore store_;
  std::vector<std::pair<std::string, Pixels>> pending_files_;
};

void pbr(tinygltf::Material& m, vec4 base, double metallic, double roughness) {
  m.pbrMetallicRoughness.baseColorFactor = {base.x, base.y, base.z, base.w};
  m.pbrMetallicRoughness.metallicFactor = metallic;
  m.pbrMetallicRoughness.roughnessFactor = roughness;
}

// A rotation about +x as a glTF quaternion (x, y, z, w).
std::vector<double> about_x(double degrees) {
  double half = degrees * (3.14159265358979323846 / 360.0);
  return {std::sin(half), 0.0, 0.0, std::cos(half)};
}

const int kLinear = TINYGLTF_TEXTURE_FILTER_LINEAR;
const int kTrilinear = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;

// ------------------------------------------------------------------- tiles

bool metal_rough_spheres() {
  Tile t;
  tinygltf::Primitive sphere = t.primitive(uv_sphere(0.08f, 32, 16));
  for (int i = 0; i < 5; ++i)      // metallic across x
    for (int j = 0; j < 5; ++j) {  // roughness along z
      std::string name = "m" + std::to_string(25 * i) + "-r" + std::to_string(25 * j);
      pbr(t.material(name), vec4(0.9f, 0.6f, 0.3f, 1.0f), 0.25 * i, 0.25 * j);
      t.mesh_node(name, sphere, t.last_material(), glm::dvec3(0.2 * (i - 2), 0, 0.2 * (j - 2)));
    }
  return t.write("metal-rough-spheres.glb");
}

bool metal_rough_textured(ImageStore store, const std::string& name, const std::string& buffer_file = "") {
  Tile t(store);
  int s = t.sampler(kLinear, kTrilinear);
  const std::string stem = "metal-rough-textured-";
  int base = t.texture("base", base_checker(), s, stem + "base.png");
  int mr = t.texture("mr", metal_rough_map(), s, stem + "mr.png");
  int normal = t.texture("normal", bumps_normal_map(), s, stem + "normal.png");
  tinygltf::Material& m = t.material("textured");
  pbr(m, vec4(1.0f), 1.0, 1.0);  // the textures' values as they are
  m.pbrMetallicRoughness.baseColorTexture.index = base;
  m.pbrMetallicRoughness.metallicRoughnessTexture.index = mr;
  m.normalTexture.index = normal;
  m.normalTexture.scale = 0.8;
  m.occlusionTexture.index = mr;
  m.occlusionTexture.strength = 1.0;
  t.mesh_node("quad", t.primitive(floor_quad(0.5f, 0.5f, true)), t.last_material());
  return t.write(name, buffer_file);
}

bool alpha_mask() {
  Tile t;
  Pixels leaf = leaf_rgba();
  int tex = t.texture("leaf", leaf, t.sampler(kLinear, kTrilinear));
  tinygltf::Material& m = t.material("leaf");
  pbr(m, vec4(1.0f), 0.0, 0.8);
  m.pbrMetallicRoughness.baseColorTexture.index = tex;
  m.alphaMode = "MASK";
  m.alphaCutoff = 0.5;
  m.doubleSided = true;
  t.mesh_node("leaf", t.primitive(standing_quad(-0.4f, 0.4f, 0.0f, 0.8f)), t.last_material());
  return t.write("alpha-mask.glb") && write_png("alpha-mask.png", leaf_coverage(leaf));
}

bool alpha_blend() {
  Tile t;
  tinygltf::Material& flat = t.material("half");
  pbr(flat, vec4(0.2f, 0.5f, 0.9f, 0.5f), 0.0, 0.5);
  flat.alphaMode = "BLEND";
  flat.doubleSided = true;
  t.mesh_node("half", t.primitive(standing_quad(-0.45f, -0.05f, 0.0f, 0.8f)), t.last_material());
  int tex = t.texture("ramp", alpha_ramp(), t.sampler(kLinear, kTrilinear));
  tinygltf::Material& ramp = t.material("ramp");
  pbr(ramp, vec4(1.0f), 0.0, 0.5);
  ramp.pbrMetallicRoughness.baseColorTexture.index = tex;
  ramp.alphaMode = "BLEND";
  ramp.doubleSided = true;
  t.mesh_node("ramp", t.primitive(standing_quad(0.05f, 0.45f, 0.0f, 0.8f)), t.last_material());
  return t.write("alpha-blend.glb");
}

bool normal_tangent() {
  Tile t;
  int tex = t.texture("bumps", bumps_normal_map(), t.sampler(kLinear, kTrilinear));
  tinygltf::Material& m = t.material("bumps");
  pbr(m, vec4(0.8f, 0.8f, 0.8f, 1.0f), 0.0, 0.4);
  m.normalTexture.index = tex;
  const vec3 right(0.225f, 0, 0), up(0, 0, -0.225f);
  t.mesh_node("with-tangent", t.primitive(quad(vec3(-0.25f, 0, 0), right, up, true)), 0);
  t.mesh_node("without-tangent", t.primitive(quad(vec3(0.25f, 0, 0), right, up, false)), 0);
  return t.write("normal-tangent.glb");
}

bool texture_transform() {
  Tile t;
  t.use("KHR_texture_transform");
  int tex = t.texture("marked", marked_checker(), t.sampler(TINYGLTF_TEXTURE_FILTER_NEAREST, kTrilinear));
  tinygltf::Material& plain = t.material("plain");
  pbr(plain, vec4(1.0f), 0.0, 1.0);
  plain.pbrMetallicRoughness.baseColorTexture.index = tex;
  t.mesh_node("plain", t.primitive(standing_quad(-0.46f, -0.04f, 0.05f, 0.47f)), t.last_material());

  tinygltf::Material& moved = t.material("transformed");
  pbr(moved, vec4(1.0f), 0.0, 1.0);
  moved.pbrMetallicRoughness.baseColorTexture.index = tex;
  moved.pbrMetallicRoughness.baseColorTexture.extensions["KHR_texture_transform"] =
      object({{"offset", numbers({0.25, 0.0})}, {"rotation", number(0.0)}, {"scale", numbers({2.0, 2.0})}});
  t.mesh_node("transformed", t.primitive(standing_quad(0.04f, 0.46f, 0.05f, 0.47f)), t.last_material());

  tinygltf::Material& second = t.material("texcoord1");
  pbr(second, vec4(1.0f), 0.0, 1.0);
  second.pbrMetallicRoughness.baseColorTexture.index = tex;
  second.pbrMetallicRoughness.baseColorTexture.texCoord = 1;
  Geometry g = standing_quad(-0.21f, 0.21f, 0.52f, 0.94f);
  std::vector<vec2> uv1;
  for (const vec2& uv : g.uvs) uv1.push_back(0.5f * uv);
  t.mesh_node("texcoord1", t.primitive(g, uv1), t.last_material());
  return t.write("texture-transform.glb");
}

bool emissive_strength() {
  Tile t;
  t.use("KHR_materials_emissive_strength");
  int tex = t.texture("disc", white_disc(), t.sampler(kLinear, kTrilinear));
  tinygltf::Material& m = t.material("glow");
  pbr(m, vec4(0, 0, 0, 1), 0.0, 1.0);
  m.emissiveFactor = {1.0, 0.5, 0.25};
  m.emissiveTexture.index = tex;
  m.extensions["KHR_materials_emissive_strength"] = object({{"emissiveStrength", number(4.0)}});
  t.mesh_node("glow", t.primitive(standing_quad(-0.4f, 0.4f, 0.1f, 0.9f)), t.last_material());
  return t.write("emissive-strength.glb");
}

bool transmission_volume() {
  Tile t;
  for (const char* e : {"KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_ior"}) t.use(e);
  tinygltf::Primitive sphere = t.primitive(uv_sphere(0.15f, 32, 16));
  auto transmissive = [&](const std::string& name, double roughness) -> tinygltf::Material& {
    tinygltf::Material& m = t.material(name);
    pbr(m, vec4(1.0f), 0.0, roughness);
    m.extensions["KHR_materials_transmission"] = object({{"transmissionFactor", number(1.0)}});
    return m;
  };
  transmissive("thin", 0.0);
  t.mesh_node("thin", sphere, t.last_material(), glm::dvec3(-0.32, 0, 0));
  tinygltf::Material& volume = transmissive("volume", 0.0);
  volume.extensions["KHR_materials_volume"] =
      object({{"thicknessFactor", number(0.3)}, {"attenuationDistance", number(0.2)},
              {"attenuationColor", numbers({0.9, 0.3, 0.2})}});
  volume.extensions["KHR_materials_ior"] = object({{"ior", number(1.5)}});
  t.mesh_node("volume", sphere, t.last_material(), glm::dvec3(0, 0, 0));
  transmissive("rough-water", 0.3).extensions["KHR_materials_ior"] = object({{"ior", number(1.33)}});
  t.mesh_node("rough-water", sphere, t.last_material(), glm::dvec3(0.32, 0, 0));
  return t.write("transmission-volume.glb");
}

bool clearcoat() {
  Tile t;
  t.use("KHR_materials_clearcoat");
  t.use("KHR_materials_specular");
  tinygltf::Primitive sphere = t.primitive(uv_sphere(0.15f, 32, 16));
  const vec4 red(0.8f, 0.1f, 0.1f, 1.0f);
  tinygltf::Material& coated = t.material("clearcoat");
  pbr(coated, red, 0.0, 0.6);
  coated.extensions["KHR_materials_clearcoat"] =
      object({{"clearcoatFactor", number(1.0)}, {"clearcoatRoughnessFactor", number(0.05)}});
  t.mesh_node("clearcoat", sphere, t.last_material(), glm::dvec3(-0.32, 0, 0));
  pbr(t.material("plain"), red, 0.0, 0.6);
  t.mesh_node("plain", sphere, t.last_material(), glm::dvec3(0, 0, 0));
  tinygltf::Material& specular = t.material("specular");
  pbr(specular, red, 0.0, 0.6);
  specular.extensions["KHR_materials_specular"] =
      object({{"specularFactor", number(0.5)}, {"specularColorFactor", numbers({1.0, 0.8, 0.8})}});
  t.mesh_node("specular", sphere, t.last_material(), glm::dvec3(0.32, 0, 0));
  return t.write("clearcoat.glb");
}

bool punctual_lights() {
  Tile t;
  t.use("KHR_lights_punctual");
  pbr(t.material("ground"), vec4(0.5f, 0.5f, 0.5f, 1.0f), 0.0, 1.0);
  t.mesh_node("ground", t.primitive(floor_quad(0.5f, 0.5f, false)), 0);
  // glTF lights shine along their node's -z; range left out (infinite).
  auto light = [&](const std::string& name, const std::string& type, double intensity, std::vector<double> colour,
                   const glm::dvec3& at, std::vector<double> rotation) {
    tinygltf::Light l;
    l.name = name;
    l.type = type;
    l.intensity = intensity;
    l.color = std::move(colour);
    l.spot.innerConeAngle = 0.2;
    l.spot.outerConeAngle = 0.4;
    t.model().lights.push_back(l);
    tinygltf::Node& n = t.node(name, at);
    n.rotation = std::move(rotation);
    n.extensions["KHR_lights_punctual"] =
        object({{"light", tinygltf::Value(static_cast<int>(t.model().lights.size()) - 1)}});
  };
  light("point", "point", 10.0, {1, 1, 1}, glm::dvec3(0, 0.5, 0), {});
  light("spot", "spot", 20.0, {1, 0.9, 0.8}, glm::dvec3(0.3, 0.6, 0), about_x(-90));  // -z to -y
  light("sun", "directional", 2.0, {1, 1, 1}, glm::dvec3(0, 1, 0), about_x(-45));      // 45 degrees down
  return t.write("punctual-lights.glb");
}

bool camera() {
  Tile t;
  pbr(t.material("grey"), vec4(0.5f, 0.5f, 0.5f, 1.0f), 0.0, 0.8);
  t.mesh_node("cube", t.primitive(unit_cube()), 0);
  // tinygltf always writes zfar, so both get a finite one (100).
  auto add = [&](const std::string& name, double yfov, double aspect, const glm::dvec3& at, std::vector<double> rotation) {
    tinygltf::Camera c;
    c.name = name;
    c.type = "perspective";
    c.perspective.yfov = yfov;
    c.perspective.aspectRatio = aspect;  // 0: not written
    c.perspective.znear = 0.01;
    c.perspective.zfar = 100.0;
    t.model().cameras.push_back(c);
    tinygltf::Node& n = t.node(name, at);
    n.camera = static_cast<int>(t.model().cameras.size()) - 1;
    n.rotation = std::move(rotation);
  };
  add("front", 0.6, 1.5, glm::dvec3(0, 0.5, 2), {});             // looks along -z
  add("top", 0.8, 0.0, glm::dvec3(0, 3, 0), about_x(-90));  // looks down, image up = -z
  return t.write("camera.glb");
}

bool required_unknown() {
  Tile t;
  t.use("KHR_draco_mesh_compression", true);  // named only: the mesh is plain
  pbr(t.material("grey"), vec4(0.5f, 0.5f, 0.5f, 1.0f), 0.0, 1.0);
  t.mesh_node("quad", t.primitive(floor_quad(0.5f, 0.5f, false)), 0);
  return t.write("required-unknown.glb");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: wavetrace-gltf-tiles OUTDIR\n");
    return 2;
  }
  g_outdir = argv[1];
  std::error_code ec;
  std::filesystem::create_directories(g_outdir, ec);
  if (ec) {
    std::fprintf(stderr, "wavetrace-gltf-tiles: cannot create %s: %s\n", argv[1], ec.message().c_str());
    return 1;
  }
  bool ok = metal_rough_spheres() &&
            metal_rough_textured(ImageStore::kBuffer, "metal-rough-textured.glb") &&
            metal_rough_textured(ImageStore::kFiles, "metal-rough-textured.gltf", "metal-rough-textured.bin") &&
            metal_rough_textured(ImageStore::kDataUri, "metal-rough-textured-datauri.gltf") && alpha_mask() &&
            alpha_blend() && normal_tangent() && texture_transform() && emissive_strength() &&
            transmission_volume() && clearcoat() && punctual_lights() && camera() && required_unknown();
  return ok ? 0 : 1;
}

// Mesh files to TriangleMesh. The libraries parse (and tinyobjloader triangulates);
// this file checks what they return (indices, accessor bounds, non-finite values),
// drops degenerate triangles and maps materials (docs/scene-format.md, "Meshes").
#include "scene/mesh_load.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <limits>
#include <map>
#include <sstream>
#include <string_view>
#include <unordered_map>

#include "errors/errors.hpp"
#include "scene/input_file.hpp"
#include "scene/json_reader.hpp"
#include "scene/mesh_libraries.hpp"
#include "scene/scene.hpp"

namespace wt {

namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& path, const std::string& what) { throw InputError(path + ": " + what); }

bool finite(const vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The first non-empty line of a library's message, without its trailing newline.
std::string first_line(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r.") != std::string::npos) return line;
  }
  return text;
}

// Appends vertices and triangles, dropping the triangles that cannot be traced.
class MeshBuilder {
 public:
  explicit MeshBuilder(TriangleMesh& mesh) : m_(mesh) {}

  uint32_t add_vertex(const vec3& p, const vec3* n, const vec2* uv, const vec4* tangent = nullptr) {
    if (tangent) {
      const vec3 t(*tangent);
      if (!finite(t) || glm::length(t) == 0.0f || !(tangent->w == 1.0f || tangent->w == -1.0f)) {
        fail(m_.source, "vertex " + std::to_string(m_.positions.size()) +
                            " has a zero or non-finite TANGENT, or a handedness (w) other than 1 or -1");
      }
      m_.tangents.push_back(vec4(glm::normalize(t), tangent->w));
    } else {
      missing_tangent_ = true;
    }
    if (m_.positions.size() >= std::numeric_limits<uint32_t>::max()) fail(m_.source, "more than 2^32 - 1 vertices");
    if (n) {
      if (!finite(*n) || glm::length(*n) == 0.0f) {
        fail(m_.source, "vertex " + std::to_string(m_.positions.size()) + " has a zero or non-finite normal");
      }
    } else {
      missing_normal_ = true;
    }
    if (uv) {
      if (!std::isfinite(uv->x) || !std::isfinite(uv->y)) {
        fail(m_.source, "vertex " + std::to_string(m_.positions.size()) + " has a non-finite texture coordinate");
      }
    } else {
      missing_uv_ = true;
    }
    m_.positions.push_back(p);
    m_.normals.push_back(n ? glm::normalize(*n) : vec3(0.0f));
    m_.uvs.push_back(uv ? *uv : vec2(0.0f));
    return static_cast<uint32_t>(m_.positions.size() - 1);
  }

  // Whether a triangle over these corners would be kept (counting it if not).
  bool keep(const vec3& a, const vec3& b, const vec3& c) {
    if (!finite(a) || !finite(b) || !finite(c)) {
      ++m_.dropped_nan;
      return false;
    }
    vec3 cross = glm::cross(b - a, c - a);
    if (!finite(cross) || glm::length(cross) == 0.0f) {
      ++m_.dropped_degenerate;
      return false;
    }
    return true;
  }

  void add_triangle(uint32_t a, uint32_t b, uint32_t c, uint32_t material) {
    m_.triangles.push_back({a, b, c});
    m_.triangle_material.push_back(material);
  }

  // Normals and UVs are kept only where every vertex has them; unused materials
  // stay (their indices are the file's).
  void finish() {
    if (missing_normal_) m_.normals.clear();
    if (missing_uv_) m_.uvs.clear();
    if (missing_tangent_ || missing_normal_ || missing_uv_) m_.tangents.clear();
    if (m_.triangles.empty()) {
      size_t dropped = m_.dropped_degenerate + m_.dropped_nan;
      fail(m_.source, dropped ? "no triangles left (" + std::to_string(m_.dropped_degenerate) + " degenerate and " +
                                    std::to_string(m_.dropped_nan) + " non-finite dropped)"
                              : std::string("has no triangles"));
    }
  }

 private:
  TriangleMesh& m_;
  bool missing_normal_ = false;
  bool missing_uv_ = false;
  bool missing_tangent_ = false;
};

// The material appended for faces the file gives none, once.
uint32_t default_material(TriangleMesh& mesh, int64_t& index, const std::function<MeshMaterial()>& make) {
  if (index < 0) {
    index = static_cast<int64_t>(mesh.materials.size());
    mesh.materials.push_back(make());
  }
  return static_cast<uint32_t>(index);
}

// Checks a material's colour and returns it: in [0, 1] for an albedo, >= 0 for an emission.
vec3 checked_colour(const std::string& path, const std::string& material, const char* field, const double* c,
                    bool radiance) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(c[i]) || c[i] < 0.0 || c[i] > (radiance ? kMaxRadiance : 1.0)) {
      fail(path, "material '" + material + "': " + field + " must be 3 numbers " +
                     (radiance ? "in [0, 1e9] (the most radiance a scene may hold)" : "in [0, 1]"));
    }
  }
  return vec3(static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2]));
}

vec3 checked_colour(const std::string& path, const std::string& material, const char* field, const float* c,
                    bool radiance) {
  const double d[3] = {c[0], c[1], c[2]};
  return checked_colour(path, material, field, d, radiance);
}

Material make_material(MaterialKind kind, vec3 albedo, float fuzz, float ior, vec3 emission) {
  Material m{};
  m.kind = kind;
  m.texture = -1;
  m.albedo = kind == MaterialKind::Emissive ? vec3(0.0f) : albedo;
  m.fuzz = kind == MaterialKind::Metal ? std::clamp(fuzz, 0.0f, 1.0f) : 0.0f;
  m.ior = kind == MaterialKind::Dielectric || kind == MaterialKind::Coated ? ior : 1.0f;
  m.emission = kind == MaterialKind::Emissive ? emission : vec3(0.0f);
  m.sort_key = static_cast<uint8_t>(material_sort_key(kind, -1));
  return m;
}

bool textured(MaterialKind kind) {
  return kind == MaterialKind::Lambertian || kind == MaterialKind::Metal || kind == MaterialKind::Coated;
}

// ---- Wavefront OBJ + MTL ----

MeshMaterial map_mtl(const tinyobj::material_t& t, const fs::path& dir, const std::string& path) {
  const std::string& name = t.name;
  vec3 kd = checked_colour(path, name, "Kd", t.diffuse, false);
  vec3 ks = checked_colour(path, name, "Ks", t.specular, false);
  vec3 ke = checked_colour(path, name, "Ke", t.emission, true);
  if (!std::isfinite(t.shininess) || t.shininess < 0.0f) fail(path, "material '" + name + "': Ns must be >= 0");
  if (!std::isfinite(t.ior) || t.ior <= 0.0f) fail(path, "material '" + name + "': Ni must be > 0");
  if (!std::isfinite(t.dissolve) || t.dissolve < 0.0f || t.dissolve > 1.0f) {
    fail(path, "material '" + name + "': d must be in [0, 1]");
  }
  // Ni of 1 (or less) is the MTL default, meaning "not given": a coat or a glass gets 1.5.
  float ior = t.ior > 1.0f ? t.ior : 1.5f;
  auto max3 = [](vec3 v) { return std::max(v.x, std::max(v.y, v.z)); };
  MeshMaterial out;
  out.name = name;
  if (max3(ke) > 0.0f) {
    out.material = make_material(MaterialKind::Emissive, vec3(0.0f), 0.0f, 1.0f, ke);
  } else if (t.dissolve < 1.0f) {
    out.material = make_material(MaterialKind::Dielectric, vec3(1.0f), 0.0f, ior, vec3(0.0f));
  } else if (max3(ks) > 0.0f && max3(kd) == 0.0f) {
    // Phong exponent to roughness: sqrt(2 / (Ns + 2)).
    out.material = make_material(MaterialKind::Metal, ks, std::sqrt(2.0f / (t.shininess + 2.0f)), 1.0f, vec3(0.0f));
  } else if (max3(ks) > 0.0f) {
    out.material = make_material(MaterialKind::Coated, kd, 0.0f, ior, vec3(0.0f));
  } else {
    out.material = make_material(MaterialKind::Lambertian, kd, 0.0f, 1.0f, vec3(0.0f));
  }
  if (!t.diffuse_texname.empty() && textured(out.material.kind)) {
    out.albedo_map = (dir / t.diffuse_texname).lexically_normal().string();
  }
  return out;
}

// (position, normal, uv) indices of an OBJ corner, the key of one mesh vertex.
struct CornerHash {
  size_t operator()(const std::array<int, 3>& k) const {
    auto u = [](int i) { return static_cast<uint64_t>(static_cast<uint32_t>(i)); };  // -1 (absent) included
    return std::hash<uint64_t>()((u(k[0]) << 32) ^ (u(k[1]) << 16) ^ u(k[2]));
  }
};

// MTL files for tinyobjloader, read as every input file is (read_input_file). The
// first that cannot be read is kept, and reported as the mesh's error.
class MaterialLibraries : public tinyobj::MaterialReader {
 public:
  explicit MaterialLibraries(fs::path dir) : dir_(std::move(dir)) {}

  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* names, std::string* warn, std::string* err) override {
    const std::string file = (dir_ / name).lexically_normal().string();
    std::string text;
    try {
      text = read_input_file(file, input::kMaterialLibrary);
    } catch (const InputError& e) {
      if (error_.empty()) error_ = std::string("mtllib ") + name + ": " + e.what();
      if (err) *err += error_ + "\n";
      return false;
    }
    std::istringstream in(text);
    tinyobj::LoadMtl(names, materials, &in, warn, err);
    return true;
  }

  const std::string& error() const { return error_; }

 private:
  fs::path dir_;
  std::string error_;
};

// tinyobjloader reads a number it cannot parse (`v abc 0 0`) as 0, keeps NaN and the
// infinities, and wraps an index past 2^31 to another vertex's. The text is checked
// before it parses it: every number of a v, vt or vn line finite and in float range,
// every index of an f, l or p line a whole number that names an element of the file.
// An error names the line.
class ObjNumbers {
 public:
  explicit ObjNumbers(const std::string& path) : path_(path) {}

  void check(const std::string& text) {
    size_t at = 0;
    std::vector<std::string_view> words;
    while (at < text.size()) {
      const size_t end = std::min(text.find('\n', at), text.size());
      std::string_view rest(text.data() + at, end - at);
      at = end + 1;
      ++line_;
      split(rest.substr(0, rest.find('#')), words);
      if (words.empty()) continue;
      const std::string_view command = words[0];
      const int kind = command == "v" ? kV : command == "vt" ? kVt : command == "vn" ? kVn : -1;
      if (kind >= 0) {
        numbers(kind, words);
      } else if (command == "f" || command == "l" || command == "p") {
        for (size_t w = 1; w < words.size(); ++w) corner(command, words[w]);
      }
    }
    for (int k = 0; k < 3; ++k) {
      if (static_cast<uint64_t>(largest_[k]) > count_[k]) {
        fail_at(largest_line_[k], "index " + std::to_string(largest_[k]) + " is out of range: the file has " +
                                      std::to_string(count_[k]) + " " + kKinds[k] + (count_[k] == 1 ? "" : "s"));
      }
    }
  }

 private:
  enum { kV, kVt, kVn };
  static constexpr const char* kKinds[3] = {"vertex position", "texture coordinate", "normal"};

  [[noreturn]] void fail_at(size_t line, const std::string& what) const {
    fail(path_, "malformed OBJ: line " + std::to_string(line) + ": " + what);
  }

  static void split(std::string_view line, std::vector<std::string_view>& words) {
    words.clear();
    for (size_t i = 0; i < line.size();) {
      const size_t begin = line.find_first_not_of(" \t\r\v\f", i);
      if (begin == std::string_view::npos) break;
      const size_t stop = std::min(line.find_first_of(" \t\r\v\f", begin), line.size());
      words.push_back(line.substr(begin, stop - begin));
      i = stop;
    }
  }

  // A v, vt or vn line: v x y z, then w or r g b (and w); vt u, v, w; vn x y z.
  void numbers(int kind, const std::vector<std::string_view>& words) {
    const std::string command(words[0]);
    const size_t lo = kind == kVt ? 1 : 3, hi = kind == kV ? 7 : 3;
    const size_t n = words.size() - 1;
    if (n < lo || n > hi) {
      fail_at(line_, command + " needs " +
                         (lo == hi ? std::to_string(lo) : std::to_string(lo) + " to " + std::to_string(hi)) +
                         " numbers (got " + std::to_string(n) + ")");
    }
    for (size_t w = 1; w < words.size(); ++w) {
      const std::string word(words[w]);
      char* stop = nullptr;
      const double v = std::strtod(word.c_str(), &stop);
      if (stop != word.c_str() + word.size() || !std::isfinite(v) ||
          std::fabs(v) > static_cast<double>(std::numeric_limits<float>::max())) {
        fail_at(line_, command + ": '" + word + "' is not a finite number");
      }
    }
    ++count_[kind];
  }

  // One corner of an f, l or p line: v, v/vt, v//vn or v/vt/vn.
  void corner(std::string_view command, std::string_view corner) {
    size_t field_begin = 0;
    for (int field = 0; field < 3 && field_begin <= corner.size(); ++field) {
      const size_t slash = std::min(corner.find('/', field_begin), corner.size());
      const std::string word(corner.substr(field_begin, slash - field_begin));
      field_begin = slash + 1;
      if (word.empty() && field > 0) continue;  // v//vn, v/vt/
      const int k = field == 0 ? kV : field == 1 ? kVt : kVn;
      errno = 0;
      char* stop = nullptr;
      const long long v = word.empty() ? 0 : std::strtoll(word.c_str(), &stop, 10);
      if (word.empty() || stop != word.c_str() + word.size() || errno == ERANGE || v == 0) {
        fail_at(line_, std::string(command) + ": '" + std::string(corner) + "' is not a corner of whole, non-zero indices");
      }
      if (v < 0 && static_cast<unsigned long long>(-(v + 1)) >= count_[k]) {
        fail_at(line_, std::string(command) + ": index " + word + " reaches before the first " + kKinds[k] + " (" +
                           std::to_string(count_[k]) + " given so far)");
      }
      if (v > largest_[k]) {
        largest_[k] = v;
        largest_line_[k] = line_;
      }
    }
    if (field_begin <= corner.size()) {
      fail_at(line_, std::string(command) + ": '" + std::string(corner) + "' has more than three indices");
    }
  }

  const std::string& path_;
  size_t line_ = 0;
  size_t count_[3] = {0, 0, 0};
  int64_t largest_[3] = {0, 0, 0};  // the largest index given of each kind, and its line
  size_t largest_line_[3] = {0, 0, 0};
};

void load_obj(const std::string& text, const fs::path& dir, TriangleMesh& mesh) {
  const std::string& path = mesh.source;
  ObjNumbers(path).check(text);
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  std::istringstream in(text);
  MaterialLibraries mtl(dir);
  bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, &mtl, /*triangulate=*/true,
                             /*default_vcols_fallback=*/false);
  if (!mtl.error().empty()) fail(path, mtl.error());
  if (!ok || !err.empty()) fail(path, "malformed OBJ: " + first_line(err.empty() ? warn : err));
  // tinyobjloader reports a missing MTL file, an unknown material name and indices
  // out of range as warnings and goes on; here they are errors. A face of fewer than
  // three corners is a degenerate triangle.
  std::istringstream warnings(warn);
  for (std::string line; std::getline(warnings, line);) {
    while (!line.empty() && line.front() == '.') line.erase(0, 1);  // its "Degenerated face found\n."
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (line.find("Degenerated face found") != std::string::npos) {
      ++mesh.dropped_degenerate;
      continue;
    }
    fail(path, "malformed OBJ: " + line);
  }

  for (const tinyobj::material_t& t : materials) mesh.materials.push_back(map_mtl(t, dir, path));
  int64_t fallback = -1;
  // Faces before any usemtl (or with no MTL at all): white Lambertian, so that a
  // texture paired with the mesh shows as it is.
  auto make_default = [] {
    MeshMaterial d;
    d.name = "default";
    d.material = make_material(MaterialKind::Lambertian, vec3(1.0f), 0.0f, 1.0f, vec3(0.0f));
    return d;
  };

  const size_t nv = attrib.vertices.size() / 3, nn = attrib.normals.size() / 3, nt = attrib.texcoords.size() / 2;
  auto position = [&](int i) { return glm::make_vec3(&attrib.vertices[3 * static_cast<size_t>(i)]); };
  MeshBuilder builder(mesh);
  std::unordered_map<std::array<int, 3>, uint32_t, CornerHash> vertices;
  for (const tinyobj::shape_t& shape : shapes) {
    const auto& idx = shape.mesh.indices;
    for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      // Triangulated: every face has three corners.
      const tinyobj::index_t* c = &idx[3 * f];
      for (int k = 0; k < 3; ++k) {
        if (c[k].vertex_index < 0 || static_cast<size_t>(c[k].vertex_index) >= nv ||
            c[k].normal_index >= static_cast<int>(nn) || c[k].texcoord_index >= static_cast<int>(nt)) {
          fail(path, "face " + std::to_string(f) + " of '" + shape.name + "': index out of range");
        }
      }
      if (!builder.keep(position(c[0].vertex_index), position(c[1].vertex_index), position(c[2].vertex_index))) {
        continue;
      }
      uint32_t corner[3];
      for (int k = 0; k < 3; ++k) {
        std::array<int, 3> key = {c[k].vertex_index, c[k].normal_index, c[k].texcoord_index};
        auto [it, added] = vertices.emplace(key, 0);
        if (added) {
          vec3 n = key[1] >= 0 ? glm::make_vec3(&attrib.normals[3 * static_cast<size_t>(key[1])]) : vec3(0.0f);
          // OBJ puts v = 0 at the image's bottom row; a mesh's UVs, as the images are
          // held (row 0 at the top) and as glTF has them, at its top.
          vec2 uv = key[2] >= 0 ? glm::make_vec2(&attrib.texcoords[2 * static_cast<size_t>(key[2])]) : vec2(0.0f);
          uv.y = 1.0f - uv.y;
          it->second = builder.add_vertex(position(key[0]), key[1] >= 0 ? &n : nullptr, key[2] >= 0 ? &uv : nullptr);
        }
        corner[k] = it->second;
      }
      int id = shape.mesh.material_ids[f];
      uint32_t material = id >= 0 ? static_cast<uint32_t>(id) : default_material(mesh, fallback, make_default);
      builder.add_triangle(corner[0], corner[1], corner[2], material);
    }
  }
  builder.finish();
}

// ---- glTF 2.0 ----

// An accessor's elements, bounds-checked against its buffer view and buffer.
struct Elements {
  const unsigned char* data = nullptr;
  size_t stride = 0, count = 0;
  int component = 0;
  bool normalized = false;
};

Elements elements(const tinygltf::Model& model, int index, const std::string& what, int type,
                  const std::vector<int>& components, const std::string& path) {
  if (index < 0 || static_cast<size_t>(index) >= model.accessors.size()) {
    fail(path, what + ": accessor index " + std::to_string(index) + " out of range");
  }
  const tinygltf::Accessor& a = model.accessors[index];
  const std::string where = what + " (accessor " + std::to_string(index) + ")";
  if (a.sparse.isSparse) fail(path, where + ": sparse accessors are not supported");
  if (a.type != type) fail(path, where + ": wrong element type");
  if (std::find(components.begin(), components.end(), a.componentType) == components.end()) {
    fail(path, where + ": unsupported component type " + std::to_string(a.componentType));
  }
  if (a.bufferView < 0 || static_cast<size_t>(a.bufferView) >= model.bufferViews.size()) {
    fail(path, where + ": buffer view index out of range");
  }
  const tinygltf::BufferView& view = model.bufferViews[a.bufferView];
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model.buffers.size()) {
    fail(path, where + ": buffer index out of range");
  }
  const std::vector<unsigned char>& buffer = model.buffers[view.buffer].data;
  const size_t elem = static_cast<size_t>(tinygltf::GetComponentSizeInBytes(a.componentType)) *
                      static_cast<size_t>(tinygltf::GetNumComponentsInType(a.type));
  Elements e;
  e.stride = view.byteStride ? view.byteStride : elem;
  e.count = a.count;
  e.component = a.componentType;
  e.normalized = a.normalized;
  if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset) {
    fail(path, where + ": buffer view runs past the end of its buffer");
  }
  if (e.stride < elem) fail(path, where + ": byte stride smaller than an element");
  if (e.count > 0 && (a.byteOffset > view.byteLength || elem > view.byteLength - a.byteOffset ||
                      (e.count - 1) > (view.byteLength - a.byteOffset - elem) / e.stride)) {
    fail(path, where + ": elements run past the end of the buffer view");
  }
  e.data = buffer.data() + view.byteOffset + a.byteOffset;
  return e;
}

float component(const Elements& e, size_t i, int c) {
  const unsigned char* p = e.data + i * e.stride;
  switch (e.component) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return e.normalized ? p[c] / 255.0f : p[c];
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p + 2 * c, 2);
      return e.normalized ? v / 65535.0f : v;
    }
    default: {
      float v;
      std::memcpy(&v, p + 4 * c, 4);
      return v;
    }
  }
}

uint32_t index_at(const Elements& e, size_t i) {
  const unsigned char* p = e.data + i * e.stride;
  switch (e.component) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return p[0];
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    default: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

// The file of a material's texture (textureInfo `index`, `texCoord`), resolved
// against the mesh file's folder.
std::string gltf_texture_file(const tinygltf::Model& model, int texture, int tex_coord, const std::string& where,
                              const fs::path& dir, const std::string& path) {
  if (static_cast<size_t>(texture) >= model.textures.size()) fail(path, where + " index out of range");
  if (tex_coord != 0) {
    fail(path, where + ": texCoord " + std::to_string(tex_coord) + " is not supported (only TEXCOORD_0)");
  }
  const int source = model.textures[texture].source;
  if (source < 0 || static_cast<size_t>(source) >= model.images.size()) fail(path, where + ": image index out of range");
  const tinygltf::Image& image = model.images[source];
  if (image.uri.empty()) fail(path, where + " is embedded in the file (only image files are supported)");
  return (dir / image.uri).lexically_normal().string();
}

// A number of a material extension's object, or `fallback` where it gives none.
double extension_number(const tinygltf::Material& g, const char* extension, const char* field, double fallback) {
  auto e = g.extensions.find(extension);
  if (e == g.extensions.end() || !e->second.IsObject() || !e->second.Has(field)) return fallback;
  const tinygltf::Value& v = e->second.Get(field);
  return v.IsNumber() ? v.GetNumberAsDouble() : std::numeric_limits<double>::quiet_NaN();
}

MeshMaterial map_gltf(const tinygltf::Model& model, const tinygltf::Material& g, size_t index, const fs::path& dir,
                      const std::string& path) {
  MeshMaterial out;
  out.name = g.name.empty() ? "material " + std::to_string(index) : g.name;
  const std::string what = "material '" + out.name + "'";
  const tinygltf::PbrMetallicRoughness& pbr = g.pbrMetallicRoughness;
  if (pbr.baseColorFactor.size() != 4) fail(path, what + ": baseColorFactor must be 4 numbers");
  if (g.emissiveFactor.size() != 3) fail(path, what + ": emissiveFactor must be 3 numbers");
  vec3 base = checked_colour(path, out.name, "baseColorFactor", pbr.baseColorFactor.data(), false);
  vec3 emissive = checked_colour(path, out.name, "emissiveFactor", g.emissiveFactor.data(), true);
  auto unit = [&](double v, const char* field) {
    if (!(v >= 0.0 && v <= 1.0)) fail(path, what + ": " + field + " must be in [0, 1]");
    return static_cast<float>(v);
  };
  const double strength = extension_number(g, "KHR_materials_emissive_strength", "emissiveStrength", 1.0);
  if (!(strength >= 0.0 && strength <= kMaxRadiance)) {
    fail(path, what + ": KHR_materials_emissive_strength emissiveStrength must be a number in [0, 1e9]");
  }
  emissive *= static_cast<float>(strength);
  if (std::max(emissive.x, std::max(emissive.y, emissive.z)) > kMaxRadiance) {
    fail(path, what + ": emissiveFactor times emissiveStrength exceeds 1e9 (the most radiance a scene may hold)");
  }
  const double ior = extension_number(g, "KHR_materials_ior", "ior", 1.5);
  if (!(ior == 0.0 || (ior >= 1.0 && ior <= 10.0))) fail(path, what + ": KHR_materials_ior ior must be 0 or in [1, 10]");
  if (std::max(emissive.x, std::max(emissive.y, emissive.z)) > 0.0f) {
    out.material = make_material(MaterialKind::Emissive, vec3(0.0f), 0.0f, 1.0f, emissive);
    if (g.emissiveTexture.index >= 0) {
      out.albedo_map = gltf_texture_file(model, g.emissiveTexture.index, g.emissiveTexture.texCoord,
                                         what + ": emissive texture", dir, path);
    }
    return out;
  }
  out.material = make_material(MaterialKind::Principled, base, 0.0f, 1.0f, vec3(0.0f));
  // ior 0 is the extension's special case of f0 = 1; an index of 1e4 (f0 = 0.9996)
  // stands in for it.
  out.material.ior = ior == 0.0 ? 1e4f : static_cast<float>(ior);
  out.material.flags = kMaterialCompensated | (g.doubleSided ? 0u : static_cast<uint32_t>(kMaterialOneSided));
  out.metallic = unit(pbr.metallicFactor, "metallicFactor");
  out.specular = unit(extension_number(g, "KHR_materials_specular", "specularFactor", 1.0),
                      "KHR_materials_specular specularFactor");
  out.roughness = unit(pbr.roughnessFactor, "roughnessFactor");
  if (pbr.baseColorTexture.index >= 0) {
    out.albedo_map = gltf_texture_file(model, pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                       what + ": base colour texture", dir, path);
  }
  if (pbr.metallicRoughnessTexture.index >= 0) {
    out.metallic_roughness_map =
        gltf_texture_file(model, pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                          what + ": metallic-roughness texture", dir, path);
  }
  if (g.normalTexture.index >= 0) {
    out.normal_map = gltf_texture_file(model, g.normalTexture.index, g.normalTexture.texCoord,
                                       what + ": normal texture", dir, path);
    if (!(g.normalTexture.scale >= 0.0 && g.normalTexture.scale <= 1e3)) {
      fail(path, what + ": normalTexture scale must be in [0, 1000]");
    }
    out.normal_scale = static_cast<float>(g.normalTexture.scale);
  }
  // Occlusion is read and checked, not applied: the paths find the occlusion.
  if (g.occlusionTexture.index >= 0 && static_cast<size_t>(g.occlusionTexture.index) >= model.textures.size()) {
    fail(path, what + ": occlusion texture index out of range");
  }
  return out;
}

// A node's transform relative to its parent.
glm::dmat4 local_transform(const tinygltf::Node& node, const std::string& path) {
  if (!node.matrix.empty()) {
    if (node.matrix.size() != 16) fail(path, "node '" + node.name + "': matrix must be 16 numbers");
    return glm::make_mat4(node.matrix.data());
  }
  glm::dmat4 m(1.0);
  if (!node.translation.empty()) {
    if (node.translation.size() != 3) fail(path, "node '" + node.name + "': translation must be 3 numbers");
    m = glm::translate(m, glm::make_vec3(node.translation.data()));
  }
  if (!node.rotation.empty()) {
    if (node.rotation.size() != 4) fail(path, "node '" + node.name + "': rotation must be 4 numbers");
    const std::vector<double>& q = node.rotation;  // x, y, z, w
    m = m * glm::mat4_cast(glm::dquat(q[3], q[0], q[1], q[2]));
  }
  if (!node.scale.empty()) {
    if (node.scale.size() != 3) fail(path, "node '" + node.name + "': scale must be 3 numbers");
    m = glm::scale(m, glm::make_vec3(node.scale.data()));
  }
  return m;
}

class GltfReader {
 public:
  GltfReader(const tinygltf::Model& model, const fs::path& dir, TriangleMesh& mesh)
      : model_(model), mesh_(mesh), builder_(mesh) {
    for (size_t i = 0; i < model.materials.size(); ++i) {
      mesh.materials.push_back(map_gltf(model, model.materials[i], i, dir, mesh.source));
    }
  }

  void read() {
    const std::vector<tinygltf::Scene>& scenes = model_.scenes;
    if (scenes.empty()) {
      for (size_t m = 0; m < model_.meshes.size(); ++m) read_mesh(static_cast<int>(m), glm::dmat4(1.0));
    } else {
      int s = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      if (static_cast<size_t>(s) >= scenes.size()) fail(mesh_.source, "default scene index out of range");
      check_forest(scenes[s].nodes);
      walk(scenes[s].nodes);
    }
    builder_.finish();
  }

 private:
  // Checks that the nodes form a forest, as the specification requires: no node with
  // two parents (or listed twice by one), no cycle, and the scene's nodes roots, each
  // listed once. A node is then reached once from its scene: the walk is linear in
  // the nodes, whatever the graph.
  void check_forest(const std::vector<int>& roots) const {
    const std::string& path = mesh_.source;
    const size_t n = model_.nodes.size();
    std::vector<int64_t> parent(n, -1);
    for (size_t i = 0; i < n; ++i) {
      for (int child : model_.nodes[i].children) {
        if (child < 0 || static_cast<size_t>(child) >= n) {
          fail(path, "node " + std::to_string(i) + ": child index " + std::to_string(child) + " out of range");
        }
        if (parent[child] == static_cast<int64_t>(i)) {
          fail(path, "node " + std::to_string(child) + " is listed twice as a child of node " + std::to_string(i) +
                         "; glTF nodes form a forest, each node with one parent at most");
        }
        if (parent[child] >= 0) {
          fail(path, "node " + std::to_string(child) + " has two parents (nodes " + std::to_string(parent[child]) +
                         " and " + std::to_string(i) + "); glTF nodes form a forest, each node with one parent at most");
        }
        parent[child] = static_cast<int64_t>(i);
      }
    }
    // Following the parents from every node: a root ends every chain, or there is a cycle.
    std::vector<char> state(n, 0);  // 0: unseen, 1: on the chain being followed, 2: reaches a root
    std::vector<size_t> chain;
    for (size_t start = 0; start < n; ++start) {
      chain.clear();
      int64_t at = static_cast<int64_t>(start);
      while (at >= 0 && state[at] == 0) {
        state[at] = 1;
        chain.push_back(static_cast<size_t>(at));
        at = parent[at];
      }
      if (at >= 0 && state[at] == 1) fail(path, "the node hierarchy has a cycle through node " + std::to_string(at));
      for (size_t c : chain) state[c] = 2;
    }
    std::vector<char> listed(n, 0);
    for (int root : roots) {
      if (root < 0 || static_cast<size_t>(root) >= n) fail(path, "node index " + std::to_string(root) + " out of range");
      if (parent[root] >= 0) {
        fail(path, "node " + std::to_string(root) + " is a root of the scene but a child of node " +
                       std::to_string(parent[root]));
      }
      if (listed[root]) fail(path, "node " + std::to_string(root) + " is listed twice among the scene's nodes");
      listed[root] = 1;
    }
  }

  // Every node under `roots`, depth first in the file's order (a node, then its
  // children), on a stack of its own rather than the call stack.
  void walk(const std::vector<int>& roots) {
    struct Visit {
      int node;
      glm::dmat4 parent;
    };
    std::vector<Visit> stack;
    for (auto r = roots.rbegin(); r != roots.rend(); ++r) stack.push_back({*r, glm::dmat4(1.0)});
    while (!stack.empty()) {
      const Visit v = stack.back();
      stack.pop_back();
      const tinygltf::Node& node = model_.nodes[v.node];
      const glm::dmat4 world = v.parent * local_transform(node, mesh_.source);
      if (node.mesh >= 0) read_mesh(node.mesh, world);
      for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.push_back({*c, world});
    }
  }

  void read_mesh(int index, const glm::dmat4& world) {
    const std::string& path = mesh_.source;
    if (static_cast<size_t>(index) >= model_.meshes.size()) fail(path, "mesh index out of range");
    const tinygltf::Mesh& m = model_.meshes[index];
    const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(glm::dmat3(world)));
    const bool mirrors = glm::determinant(glm::dmat3(world)) < 0.0;
    for (size_t p = 0; p < m.primitives.size(); ++p) {
      const tinygltf::Primitive& prim = m.primitives[p];
      const std::string what = "mesh " + std::to_string(index) + " primitive " + std::to_string(p);
      if (prim.mode != -1 && prim.mode != TINYGLTF_MODE_TRIANGLES) {
        fail(path, what + ": mode " + std::to_string(prim.mode) + " is not supported (only triangles)");
      }
      auto attribute = [&](const char* name) {
        auto it = prim.attributes.find(name);
        return it == prim.attributes.end() ? -1 : it->second;
      };
      const int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
      if (attribute("POSITION") < 0) fail(path, what + ": no POSITION attribute");
      Elements pos = elements(model_, attribute("POSITION"), what + " POSITION", TINYGLTF_TYPE_VEC3, {kFloat}, path);
      Elements nrm, uv, tan;
      if (attribute("TANGENT") >= 0) {
        tan = elements(model_, attribute("TANGENT"), what + " TANGENT", TINYGLTF_TYPE_VEC4, {kFloat}, path);
        if (tan.count != pos.count) fail(path, what + ": TANGENT and POSITION counts differ");
      }
      if (attribute("NORMAL") >= 0) {
        nrm = elements(model_, attribute("NORMAL"), what + " NORMAL", TINYGLTF_TYPE_VEC3, {kFloat}, path);
        if (nrm.count != pos.count) fail(path, what + ": NORMAL and POSITION counts differ");
      }
      if (attribute("TEXCOORD_0") >= 0) {
        uv = elements(model_, attribute("TEXCOORD_0"), what + " TEXCOORD_0", TINYGLTF_TYPE_VEC2,
                      {kFloat, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}, path);
        if (uv.count != pos.count) fail(path, what + ": TEXCOORD_0 and POSITION counts differ");
      }
      uint32_t material;
      if (prim.material >= 0) {
        if (static_cast<size_t>(prim.material) >= model_.materials.size()) fail(path, what + ": material index out of range");
        material = static_cast<uint32_t>(prim.material);
      } else {
        material = default_material(mesh_, default_, [&] {
          // The specification's default material: every property at its default.
          tinygltf::Material g;
          g.name = "default";
          g.emissiveFactor = {0.0, 0.0, 0.0};
          g.pbrMetallicRoughness.baseColorFactor = {1.0, 1.0, 1.0, 1.0};
          g.pbrMetallicRoughness.metallicFactor = 1.0;
          g.pbrMetallicRoughness.roughnessFactor = 1.0;
          return map_gltf(model_, g, 0, fs::path(), path);
        });
      }

      const size_t first = mesh_.positions.size();
      std::vector<vec3> world_pos(pos.count);
      for (size_t i = 0; i < pos.count; ++i) {
        glm::dvec4 p4 = world * glm::dvec4(component(pos, i, 0), component(pos, i, 1), component(pos, i, 2), 1.0);
        world_pos[i] = vec3(p4);
        vec3 n;
        if (nrm.data) n = vec3(normal_matrix * glm::dvec3(component(nrm, i, 0), component(nrm, i, 1), component(nrm, i, 2)));
        // glTF puts v = 0 at the image's top row, as a mesh's UVs do.
        vec2 tc = uv.data ? vec2(component(uv, i, 0), component(uv, i, 1)) : vec2(0.0f);
        // Tangents turn with the node as directions do; a mirroring node flips
        // the handedness.
        vec4 tg(0.0f);
        if (tan.data) {
          tg = vec4(vec3(glm::dmat3(world) * glm::dvec3(component(tan, i, 0), component(tan, i, 1), component(tan, i, 2))),
                    component(tan, i, 3) * (mirrors ? -1.0f : 1.0f));
        }
        builder_.add_vertex(world_pos[i], nrm.data ? &n : nullptr, uv.data ? &tc : nullptr, tan.data ? &tg : nullptr);
      }

      Elements idx;
      size_t corners = pos.count;
      if (prim.indices >= 0) {
        idx = elements(model_, prim.indices, what + " indices", TINYGLTF_TYPE_SCALAR,
                       {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                        TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                       path);
        corners = idx.count;
      }
      if (corners % 3 != 0) fail(path, what + ": " + std::to_string(corners) + " corners is not a multiple of 3");
      for (size_t t = 0; t < corners / 3; ++t) {
        uint32_t c[3];
        for (int k = 0; k < 3; ++k) {
          c[k] = idx.data ? index_at(idx, 3 * t + k) : static_cast<uint32_t>(3 * t + k);
          if (c[k] >= pos.count) {
            fail(path, what + ": index " + std::to_string(c[k]) + " out of range (" + std::to_string(pos.count) +
                           " vertices)");
          }
        }
        if (!builder_.keep(world_pos[c[0]], world_pos[c[1]], world_pos[c[2]])) continue;
        builder_.add_triangle(static_cast<uint32_t>(first + c[0]), static_cast<uint32_t>(first + c[1]),
                              static_cast<uint32_t>(first + c[2]), material);
      }
    }
  }

  const tinygltf::Model& model_;
  TriangleMesh& mesh_;
  MeshBuilder builder_;
  int64_t default_ = -1;
};

// Images are not decoded here: only their file names are kept.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
  return true;
}

// A glTF file's buffers, read as every input file is (read_input_file); the first
// that cannot be read is kept, and reported as the mesh's error.
struct GltfFiles {
  std::string error;

  static bool exists(const std::string& path, void*) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0;  // whatever it is: reading it says what is wrong
  }
  static std::string expand(const std::string& path, void*) { return path; }
  static bool read(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    auto& files = *static_cast<GltfFiles*>(user);
    try {
      const std::string bytes = read_input_file(path, input::kGltfBuffer);
      out->assign(bytes.begin(), bytes.end());
      return true;
    } catch (const InputError& e) {
      if (files.error.empty()) files.error = e.what();
      if (err) *err += std::string(e.what()) + "\n";
      return false;
    }
  }
  static bool write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "wavetrace writes no glTF files\n";
    return false;
  }
};

void load_gltf(const std::string& bytes, bool binary, const fs::path& dir, TriangleMesh& mesh) {
  if (bytes.size() > std::numeric_limits<unsigned int>::max()) fail(mesh.source, "file too large for tinygltf");
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(skip_image, nullptr);
  GltfFiles files;
  loader.SetFsCallbacks({&GltfFiles::exists, &GltfFiles::expand, &GltfFiles::read, &GltfFiles::write, &files});
  tinygltf::Model model;
  std::string err, warn;
  const unsigned int size = static_cast<unsigned int>(bytes.size());
  bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn,
                                                 reinterpret_cast<const unsigned char*>(bytes.data()), size,
                                                 dir.string())
                   : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(), size, dir.string());
  if (!files.error.empty()) fail(mesh.source, files.error);
  if (!ok || !err.empty()) fail(mesh.source, "malformed glTF: " + first_line(err.empty() ? warn : err));
  GltfReader(model, dir, mesh).read();
}

}  // namespace

TriangleMesh load_mesh(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext != ".obj" && ext != ".gltf" && ext != ".glb") {
    fail(path, "unknown mesh format '" + ext + "' (expected .obj, .gltf, .glb)");
  }
  const std::string bytes = read_input_file(path, input::kMesh);
  const fs::path dir = fs::path(path).parent_path();
  TriangleMesh mesh;
  mesh.source = path;
  if (ext == ".obj") {
    load_obj(bytes, dir, mesh);
  } else {
    load_gltf(bytes, ext == ".glb", dir, mesh);
  }
  return mesh;
}

}  // namespace wt

// Mesh files to TriangleMesh. The libraries parse (and tinyobjloader triangulates);
// this file checks what they return (indices, accessor bounds, non-finite values),
// drops degenerate triangles and maps materials (docs/scene-format.md, "Meshes").
// PLY and Mitsuba's serialized meshes are read in mesh_ply.cpp and
// mesh_serialized.cpp, and built here (add_indexed_mesh).
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
#include "scene/mesh_formats.hpp"
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

// The material of faces the file gives none (OBJ faces before any usemtl or with no
// MTL at all; every PLY and serialized triangle): white Lambertian, so that a
// texture paired with the mesh shows as it is.
MeshMaterial white_default_material() {
  MeshMaterial d;
  d.name = "default";
  d.material = make_material(MaterialKind::Lambertian, vec3(1.0f), 0.0f, 1.0f, vec3(0.0f));
  return d;
}

// ---- Wavefront OBJ + MTL ----

// The keys an MTL material writes, each with its value as written (the rest of its
// line), and the library that holds it. tinyobjloader gives an absent key its default
// (Pr 0, Pm 0, illum 0, Kd 0.6 beside a map_Kd), which a key written as that value
// cannot be told from, and reads a value it cannot parse as that default too; what a
// material becomes depends on which keys it writes, so they are read from the text.
struct MtlKeys {
  std::string library;  // the mtllib name, as the OBJ file writes it
  std::map<std::string, std::string> values;
  bool has(const char* key) const { return values.count(key) != 0; }
};

// The keys of each material of an MTL file, in the order tinyobjloader's LoadMtl
// appends the materials: one per newmtl, or one (unnamed) for a file with none. Lines
// are split and trimmed as LoadMtl splits them; those before the first newmtl belong
// to a material it drops.
std::vector<MtlKeys> mtl_keys(const std::string& text, const std::string& library) {
  std::vector<MtlKeys> out;
  MtlKeys current{library, {}};
  bool named = false;
  for (size_t at = 0; at < text.size();) {
    const size_t end = std::min(text.find_first_of("\r\n", at), text.size());
    std::string line = text.substr(at, end - at);
    at = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
    line.erase(line.find_last_not_of(" \t") + 1);
    const size_t begin = line.find_first_not_of(" \t");
    if (begin == std::string::npos || line[begin] == '#') continue;
    const size_t space = line.find_first_of(" \t", begin);
    const std::string key = line.substr(begin, space - begin);
    if (key == "newmtl" && space != std::string::npos) {
      if (named) out.push_back(std::move(current));
      current = MtlKeys{library, {}};
      named = true;
      continue;
    }
    current.values[key] = space == std::string::npos ? "" : line.substr(line.find_first_not_of(" \t", space));
  }
  out.push_back(std::move(current));
  return out;
}

// Whether a scalar key's value is one finite number (a trailing comment aside).
bool one_number(std::string text) {
  text.erase(std::min(text.find('#'), text.size()));
  text.erase(text.find_last_not_of(" \t") + 1);
  char* stop = nullptr;
  const double v = std::strtod(text.c_str(), &stop);
  return !text.empty() && stop == text.c_str() + text.size() && std::isfinite(v);
}

// The keys of the MTL PBR extension; a material that writes any of them is
// `principled`. Ps, map_Ps and anisor among them are not rendered (a warning each).
const char* const kMtlPbrKeys[] = {"Pr",     "Pm",   "Pc", "Pcr",    "aniso", "map_Pr",
                                   "map_Pm", "norm", "Ps", "map_Ps", "anisor"};

MeshMaterial map_mtl(const tinyobj::material_t& t, const MtlKeys& k, const fs::path& dir, TriangleMesh& mesh) {
  const std::string& name = t.name;
  const std::string& path = mesh.source;
  // Errors and warnings name the library the material is in, after the OBJ file.
  const std::string where = k.library.empty() ? path : path + ": mtllib " + k.library;
  const std::string what = (k.library.empty() ? "" : "mtllib " + k.library + ": ") + "material '" + name + "'";
  auto warn = [&](const std::string& line) { mesh.warnings.push_back(what + ": " + line); };
  // A scalar key: one number (checked on the text, which tinyobjloader would read as
  // the key's default where it is not one) for which `ok` holds.
  auto number = [&](const char* key, float value, bool ok, const char* range) {
    if ((k.has(key) && !one_number(k.values.at(key))) || !std::isfinite(value) || !ok) {
      fail(path, what + ": " + key + " must be a number " + range);
    }
    return value;
  };
  auto unit = [&](const char* key, float value) {
    return number(key, value, value >= 0.0f && value <= 1.0f, "in [0, 1]");
  };
  vec3 kd = checked_colour(where, name, "Kd", t.diffuse, false);
  vec3 ks = checked_colour(where, name, "Ks", t.specular, false);
  vec3 ke = checked_colour(where, name, "Ke", t.emission, true);
  vec3 tf = checked_colour(where, name, k.has("Kt") && !k.has("Tf") ? "Kt" : "Tf", t.transmittance, false);
  number("Ns", t.shininess, t.shininess >= 0.0f, ">= 0");
  number("Ni", t.ior, t.ior > 0.0f, "> 0");
  // tinyobjloader reads Tr as 1 - d where the material has no d.
  number(k.has("Tr") && !k.has("d") ? "Tr" : "d", t.dissolve, t.dissolve >= 0.0f && t.dissolve <= 1.0f, "in [0, 1]");
  number("illum", static_cast<float>(t.illum), t.illum >= 0 && t.illum <= 10, "in [0, 10]");
  const float pr = unit("Pr", t.roughness), pm = unit("Pm", t.metallic);
  const float pc = unit("Pc", t.clearcoat_thickness), pcr = unit("Pcr", t.clearcoat_roughness);
  const float aniso = unit("aniso", t.anisotropy);
  // A map key that names no image (only options, or nothing) is an error.
  const std::pair<const char*, const std::string*> maps[] = {
      {"map_Kd", &t.diffuse_texname}, {"map_Ke", &t.emissive_texname}, {"map_Pr", &t.roughness_texname},
      {"map_Pm", &t.metallic_texname}, {"norm", &t.normal_texname},     {"map_d", &t.alpha_texname},
      {"map_Bump", &t.bump_texname},   {"map_bump", &t.bump_texname},   {"bump", &t.bump_texname}};
  for (const auto& [key, image] : maps) {
    if (k.has(key) && image->empty()) fail(path, what + ": " + key + " names no image");
  }
  auto texture = [&](const std::string& image) {
    MeshTexture out;
    out.image = (dir / image).lexically_normal().string();
    return out;
  };
  // The renderer reads roughness from a map's G channel, metallic from B and alpha
  // from A; an -imfchan naming another is not honoured. tinyobjloader's default is m
  // (none written); l (luminance) is G or B alike in the grey images these usually are.
  auto channel = [&](const char* key, const tinyobj::texture_option_t& o, char reads, const char* read) {
    if (o.imfchan != reads && o.imfchan != 'm' && !(o.imfchan == 'l' && reads != 'm')) {
      const std::string from = reads == 'm' ? "A" : std::string(1, static_cast<char>(std::toupper(reads)));
      warn(std::string(key) + " -imfchan " + o.imfchan + " is not honoured: its " + read + " is read from the image's " +
           from + " channel");
    }
  };
  // Ni of 1 (or less) is the MTL default, meaning "not given": a coat or a glass gets 1.5.
  const float ior = t.ior > 1.0f ? t.ior : 1.5f;
  auto max3 = [](vec3 v) { return std::max(v.x, std::max(v.y, v.z)); };
  bool pbr = false;
  for (const char* key : kMtlPbrKeys) pbr = pbr || k.has(key);
  // Glass is what the illumination models with refraction (4, 6, 7, 9) describe, or a
  // transmission filter where no model is written; a model without refraction leaves
  // Tf unread (exporters write Tf 1 1 1 on opaque materials).
  const bool glass = k.has("illum") ? t.illum == 4 || t.illum == 6 || t.illum == 7 || t.illum == 9 : max3(tf) > 0.0f;
  // map_Kd is multiplied by Kd (as every MTL map by its key); where Kd is not written
  // the map is the colour itself, not tinyobjloader's 0.6 grey times it.
  if (!k.has("Kd") && !t.diffuse_texname.empty()) kd = vec3(1.0f);
  MeshMaterial out;
  out.name = name;
  if (max3(ke) > 0.0f) {
    out.material = make_material(MaterialKind::Emissive, vec3(0.0f), 0.0f, 1.0f, ke);
    // An emitter's albedo texture is its emission's (Ke times map_Ke).
    if (!t.emissive_texname.empty()) out.albedo_map = texture(t.emissive_texname);
  } else if (glass || pbr) {
    // A glass's colour is its filter (white where Tf is black: a filter that passes
    // nothing is no glass), its surface smooth unless Pr says otherwise; an opaque
    // material's colour is Kd, its roughness 1 (matte) where Pr is not written.
    out.material = make_material(MaterialKind::Principled, glass ? (max3(tf) > 0.0f ? tf : vec3(1.0f)) : kd, 0.0f, 1.0f,
                                 vec3(0.0f));
    out.material.ior = ior;
    out.material.flags = kMaterialCompensated;  // MTL has no sidedness: both sides reflect
    // A map scales its value (Pr, Pm), which is 1 where the map is written alone.
    out.roughness = k.has("Pr") ? pr : !t.roughness_texname.empty() ? 1.0f : glass ? 0.0f : 1.0f;
    out.metallic = k.has("Pm") ? pm : !t.metallic_texname.empty() ? 1.0f : 0.0f;
    out.clearcoat = pc;
    out.clearcoat_roughness = pcr;
    out.anisotropy = aniso;
    if (glass) {
      out.transmission = 1.0f;
      out.thin = false;  // a volume, refracting at Ni
      if (!t.diffuse_texname.empty()) warn("map_Kd is not read: a glass's colour is its Tf");
    } else if (!t.diffuse_texname.empty()) {
      out.albedo_map = texture(t.diffuse_texname);
    }
    if (!t.roughness_texname.empty()) {
      out.roughness_map = texture(t.roughness_texname);
      channel("map_Pr", t.roughness_texopt, 'g', "roughness");
    }
    if (!t.metallic_texname.empty()) {
      out.metallic_map = texture(t.metallic_texname);
      channel("map_Pm", t.metallic_texopt, 'b', "metallic");
    }
  } else if (max3(ks) > 0.0f && max3(kd) == 0.0f) {
    // Phong exponent to roughness: sqrt(2 / (Ns + 2)).
    out.material = make_material(MaterialKind::Metal, ks, std::sqrt(2.0f / (t.shininess + 2.0f)), 1.0f, vec3(0.0f));
  } else if (max3(ks) > 0.0f) {
    out.material = make_material(MaterialKind::Coated, kd, 0.0f, ior, vec3(0.0f));
  } else {
    out.material = make_material(MaterialKind::Lambertian, kd, 0.0f, 1.0f, vec3(0.0f));
  }
  if (!t.diffuse_texname.empty() && textured(out.material.kind)) out.albedo_map = texture(t.diffuse_texname);
  if (!t.emissive_texname.empty() && out.material.kind != MaterialKind::Emissive) {
    warn("map_Ke is not read: its Ke is black (no emission to texture)");
  }

  // Normal and bump maps. norm is a tangent-space normal map (of a PBR material:
  // norm is a PBR key). MTL's bump (map_Bump) is a height map, times -bm in the
  // scene's units; exporters also write tangent-space normal maps there (with -bm
  // their strength), which the scene tells by the image's texels where no -imfchan
  // names a channel of heights. norm wins over a bump map.
  const bool emits = out.material.kind == MaterialKind::Emissive;
  const char* bump_key = k.has("map_Bump") ? "map_Bump" : k.has("map_bump") ? "map_bump" : "bump";
  if (!t.normal_texname.empty()) {
    if (emits) {
      warn("norm is not read: an emitter is not shaded");
    } else {
      out.normal_map = texture(t.normal_texname);
      const float bm = t.normal_texopt.bump_multiplier;
      if (!(bm >= 0.0f && bm <= 1e3f)) fail(path, what + ": norm -bm must be in [0, 1000]");
      out.normal_scale = bm;
    }
  }
  if (!t.bump_texname.empty()) {
    if (!t.normal_texname.empty()) {
      warn("its bump map is not read: norm gives its normal map");
    } else if (emits) {
      warn(std::string(bump_key) + " is not read: an emitter is not shaded");
    } else {
      out.bump_map = texture(t.bump_texname);
      const float bm = t.bump_texopt.bump_multiplier;
      if (!(bm >= -1e3f && bm <= 1e3f)) fail(path, what + ": " + bump_key + " -bm must be in [-1000, 1000]");
      out.bump_scale = bm;
      // tinyobjloader's default channel for a bump map is l (luminance).
      const char c = t.bump_texopt.imfchan;
      if (c == 'z') warn(std::string(bump_key) + " -imfchan z is not honoured: its heights are the image's luminance");
      out.bump_channel = c == 'r' || c == 'g' || c == 'b' || c == 'm' ? c : 'l';
    }
  }

  // Alpha: MTL's dissolve is coverage, d times map_d (read from the image's A
  // channel), so a ray passes a point with probability 1 - alpha (BLEND).
  if (!t.alpha_texname.empty() || t.dissolve < 1.0f) {
    out.alpha_mode = static_cast<uint32_t>(AlphaMode::Blend);
    out.alpha_factor = t.dissolve;
    if (!t.alpha_texname.empty()) {
      out.alpha_map = texture(t.alpha_texname);
      channel("map_d", t.alpha_texopt, 'm', "coverage");
    } else if (t.dissolve == 0.0f) {
      warn(std::string(k.has("d") ? "d 0" : "Tr 1") + ": wholly transparent, its triangles are never seen");
    }
  }

  // Keys read and not rendered, one line each.
  if (!t.specular_texname.empty()) warn("map_Ks is not read: wavetrace has no specular-colour texture");
  if (!t.specular_highlight_texname.empty()) {
    warn("map_Ns is not read: wavetrace has no texture of the specular exponent");
  }
  if (k.has("Ps")) warn("Ps (sheen) is not rendered");
  if (!t.sheen_texname.empty()) warn("map_Ps (sheen) is not rendered");
  if (k.has("anisor")) {
    warn("anisor (anisotropy rotation) is not rendered: the anisotropy follows the surface's tangent");
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
    const size_t first = materials->size();
    std::istringstream in(text);
    tinyobj::LoadMtl(names, materials, &in, warn, err);
    std::vector<MtlKeys> keys = mtl_keys(text, name);
    if (keys.size() != materials->size() - first) {  // mtl_keys splits as LoadMtl does: not expected
      if (error_.empty()) error_ = "mtllib " + name + ": its materials could not be matched to their keys";
      return false;
    }
    keys_.resize(first);
    for (MtlKeys& k : keys) keys_.push_back(std::move(k));
    return true;
  }

  const std::string& error() const { return error_; }
  // By material index: the keys each material writes.
  const std::vector<MtlKeys>& keys() const { return keys_; }

 private:
  fs::path dir_;
  std::string error_;
  std::vector<MtlKeys> keys_;
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

  for (size_t i = 0; i < materials.size(); ++i) {
    mesh.materials.push_back(map_mtl(materials[i], i < mtl.keys().size() ? mtl.keys()[i] : MtlKeys{}, dir, mesh));
  }
  int64_t fallback = -1;

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
      uint32_t material = id >= 0 ? static_cast<uint32_t>(id) : default_material(mesh, fallback, white_default_material);
      builder.add_triangle(corner[0], corner[1], corner[2], material);
    }
  }
  builder.finish();
}

// ---- glTF 2.0 ----

// Elements in a buffer view, bounds-checked against the view and its buffer.
struct Elements {
  const unsigned char* data = nullptr;
  size_t stride = 0, count = 0;
  int component = 0;
  bool normalized = false;
};

// `count` elements of `elem` bytes from `offset` into buffer view `view_index`, the
// view's byteStride apart (packed where it has none).
Elements view_elements(const tinygltf::Model& model, int view_index, size_t offset, size_t count, size_t elem,
                       const std::string& where, const std::string& path) {
  if (view_index < 0 || static_cast<size_t>(view_index) >= model.bufferViews.size()) {
    fail(path, where + ": buffer view index out of range");
  }
  const tinygltf::BufferView& view = model.bufferViews[view_index];
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model.buffers.size()) {
    fail(path, where + ": buffer index out of range");
  }
  const std::vector<unsigned char>& buffer = model.buffers[view.buffer].data;
  if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset) {
    fail(path, where + ": buffer view runs past the end of its buffer");
  }
  Elements e;
  e.stride = view.byteStride ? view.byteStride : elem;
  e.count = count;
  if (e.stride < elem) fail(path, where + ": byte stride smaller than an element");
  if (count > 0 && (offset > view.byteLength || elem > view.byteLength - offset ||
                    (count - 1) > (view.byteLength - offset - elem) / e.stride)) {
    fail(path, where + ": elements run past the end of the buffer view");
  }
  e.data = buffer.data() + view.byteOffset + offset;
  return e;
}

// Component `c` of element `i`, as a number: normalized integers as the
// specification maps them (unsigned to [0, 1], signed to [-1, 1]).
double component(const Elements& e, size_t i, int c) {
  const unsigned char* p = e.data + i * e.stride;
  auto read = [&](auto v) {
    std::memcpy(&v, p + sizeof(v) * c, sizeof(v));
    return v;
  };
  switch (e.component) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const double v = read(int8_t{});
      return e.normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      const double v = read(uint8_t{});
      return e.normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const double v = read(int16_t{});
      return e.normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const double v = read(uint16_t{});
      return e.normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return read(uint32_t{});
    default:
      return read(float{});
  }
}

// An accessor's elements, `n` components each, as type T: read from its buffer view
// (or zeros, where it has none), then its sparse substitutions applied. Component
// types: `components` (KHR_mesh_quantization's among them for attributes).
template <class T>
std::vector<T> read_accessor(const tinygltf::Model& model, int index, const std::string& what, int type,
                             const std::vector<int>& components, const std::string& path) {
  if (index < 0 || static_cast<size_t>(index) >= model.accessors.size()) {
    fail(path, what + ": accessor index " + std::to_string(index) + " out of range");
  }
  const tinygltf::Accessor& a = model.accessors[index];
  const std::string where = what + " (accessor " + std::to_string(index) + ")";
  if (a.type != type) fail(path, where + ": wrong element type");
  if (std::find(components.begin(), components.end(), a.componentType) == components.end()) {
    fail(path, where + ": unsupported component type " + std::to_string(a.componentType));
  }
  const int n = tinygltf::GetNumComponentsInType(a.type);
  const size_t elem = static_cast<size_t>(tinygltf::GetComponentSizeInBytes(a.componentType)) * n;
  if (a.count > (size_t{1} << 32)) fail(path, where + ": more than 2^32 elements");
  std::vector<T> out(a.count * n, T{});
  auto copy = [&](const Elements& e, size_t from, size_t to) {
    for (int c = 0; c < n; ++c) out[to * n + c] = static_cast<T>(component(e, from, c));
  };
  if (a.bufferView >= 0) {
    Elements e = view_elements(model, a.bufferView, a.byteOffset, a.count, elem, where, path);
    e.component = a.componentType;
    e.normalized = a.normalized;
    for (size_t i = 0; i < a.count; ++i) copy(e, i, i);
  } else if (!a.sparse.isSparse) {
    fail(path, where + ": no buffer view and no sparse values");
  }
  if (a.sparse.isSparse) {
    const std::string sparse = where + " sparse";
    if (a.sparse.count < 1 || static_cast<size_t>(a.sparse.count) > a.count) {
      fail(path, sparse + ": count must be in [1, the accessor's count]");
    }
    const size_t count = static_cast<size_t>(a.sparse.count);
    const int ic = a.sparse.indices.componentType;
    if (ic != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ic != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        ic != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
      fail(path, sparse + " indices: unsupported component type " + std::to_string(ic));
    }
    if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0) fail(path, sparse + ": negative byteOffset");
    Elements idx = view_elements(model, a.sparse.indices.bufferView, static_cast<size_t>(a.sparse.indices.byteOffset),
                                 count, static_cast<size_t>(tinygltf::GetComponentSizeInBytes(ic)), sparse + " indices",
                                 path);
    idx.stride = static_cast<size_t>(tinygltf::GetComponentSizeInBytes(ic));  // sparse views are packed
    idx.component = ic;
    Elements values = view_elements(model, a.sparse.values.bufferView, static_cast<size_t>(a.sparse.values.byteOffset),
                                    count, elem, sparse + " values", path);
    values.stride = elem;
    values.component = a.componentType;
    values.normalized = a.normalized;
    double previous = -1.0;
    for (size_t i = 0; i < count; ++i) {
      const double at = component(idx, i, 0);
      if (at <= previous || at >= static_cast<double>(a.count)) {
        fail(path, sparse + ": index " + std::to_string(static_cast<uint64_t>(at)) +
                       (at >= static_cast<double>(a.count) ? " out of range" : " not increasing"));
      }
      previous = at;
      copy(values, i, static_cast<size_t>(at));
    }
  }
  return out;
}

// The extensions this reader reads; any other one a file requires is refused, and
// any other it uses is a warning (what it adds is not rendered).
const char* const kReadExtensions[] = {"KHR_materials_emissive_strength", "KHR_materials_ior",
                                       "KHR_materials_specular",          "KHR_texture_transform",
                                       "KHR_mesh_quantization",           "KHR_lights_punctual",
                                       "KHR_materials_clearcoat",         "KHR_materials_transmission",
                                       "KHR_materials_volume"};

bool read_extension(const std::string& name) {
  return std::find(std::begin(kReadExtensions), std::end(kReadExtensions), name) != std::end(kReadExtensions);
}

void check_extensions(const tinygltf::Model& model, TriangleMesh& mesh) {
  for (const std::string& e : model.extensionsRequired) {
    if (read_extension(e)) continue;
    const std::string what = e == "KHR_texture_basisu" ? " (KTX2 / Basis Universal textures)"
                             : e == "KHR_draco_mesh_compression" || e == "EXT_meshopt_compression"
                                 ? " (compressed geometry)"
                                 : "";
    fail(mesh.source, "the file requires the extension " + e + what + ", which wavetrace does not read");
  }
  for (const std::string& e : model.extensionsUsed) {
    if (!read_extension(e)) mesh.warnings.push_back("the extension " + e + " is used but not read; what it adds is not rendered");
  }
}

// The number of an extension object's field, or `fallback` where it has none (NaN
// where it is not a number).
double extension_number(const tinygltf::ExtensionMap& extensions, const char* extension, const char* field,
                        double fallback) {
  auto e = extensions.find(extension);
  if (e == extensions.end() || !e->second.IsObject() || !e->second.Has(field)) return fallback;
  const tinygltf::Value& v = e->second.Get(field);
  return v.IsNumber() ? v.GetNumberAsDouble() : std::numeric_limits<double>::quiet_NaN();
}

// The pair of an extension object's field, or `fallback`; false where it is not two
// finite numbers.
bool extension_pair(const tinygltf::ExtensionMap& extensions, const char* extension, const char* field, vec2& out) {
  auto e = extensions.find(extension);
  if (e == extensions.end() || !e->second.IsObject() || !e->second.Has(field)) return true;
  const tinygltf::Value& v = e->second.Get(field);
  if (!v.IsArray() || v.ArrayLen() != 2) return false;
  for (int i = 0; i < 2; ++i) {
    if (!v.Get(i).IsNumber() || !std::isfinite(v.Get(i).GetNumberAsDouble())) return false;
    out[i] = static_cast<float>(v.Get(i).GetNumberAsDouble());
  }
  return true;
}

// An extension's textureInfo (index, texCoord, scale, and its own extensions:
// KHR_texture_transform) as the core's; false where the field is absent. A
// malformed one is an error naming the field.
bool extension_texture(const tinygltf::ExtensionMap& extensions, const char* extension, const char* field,
                       const std::string& path, const std::string& what, tinygltf::NormalTextureInfo& out) {
  auto e = extensions.find(extension);
  if (e == extensions.end() || !e->second.IsObject() || !e->second.Has(field)) return false;
  const tinygltf::Value& v = e->second.Get(field);
  const std::string where = what + ": " + extension + " " + field;
  auto whole = [&](const char* key, double fallback) {
    if (!v.Has(key)) return fallback;
    const tinygltf::Value& n = v.Get(key);
    const double d = n.IsNumber() ? n.GetNumberAsDouble() : std::numeric_limits<double>::quiet_NaN();
    if (!(d >= 0.0 && d <= 1e6 && d == std::floor(d))) fail(path, where + " " + key + " must be a whole number >= 0");
    return d;
  };
  if (!v.IsObject() || !v.Has("index")) fail(path, where + " must be an object with an index");
  out.index = static_cast<int>(whole("index", -1.0));
  out.texCoord = static_cast<int>(whole("texCoord", 0.0));
  if (v.Has("scale")) {
    const tinygltf::Value& n = v.Get("scale");
    out.scale = n.IsNumber() ? n.GetNumberAsDouble() : std::numeric_limits<double>::quiet_NaN();
  }
  if (v.Has("extensions") && v.Get("extensions").IsObject()) {
    const tinygltf::Value& x = v.Get("extensions");
    for (const std::string& key : x.Keys()) out.extensions[key] = x.Get(key);
  }
  return true;
}

// An extension's colour field (3 numbers, each in [0, most]) into `out`, where the
// field is given; otherwise an error naming it.
void extension_colour(const tinygltf::ExtensionMap& extensions, const char* extension, const char* field, double most,
                      const std::string& path, const std::string& what, vec3& out) {
  auto e = extensions.find(extension);
  if (e == extensions.end() || !e->second.IsObject() || !e->second.Has(field)) return;
  const tinygltf::Value& c = e->second.Get(field);
  double rgb[3] = {-1.0, -1.0, -1.0};
  if (c.IsArray() && c.ArrayLen() == 3) {
    for (int i = 0; i < 3; ++i) rgb[i] = c.Get(i).IsNumber() ? c.Get(i).GetNumberAsDouble() : -1.0;
  }
  for (double v : rgb) {
    if (!(v >= 0.0 && v <= most)) {
      std::ostringstream bound;
      bound << most;
      fail(path, what + ": " + extension + " " + field + " must be 3 numbers in [0, " + bound.str() + "]");
    }
  }
  out = vec3(static_cast<float>(rgb[0]), static_cast<float>(rgb[1]), static_cast<float>(rgb[2]));
}

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

// KTX2's file identifier, the first 12 bytes of every KTX2 file.
bool is_ktx2(const std::string& bytes) {
  static const unsigned char kId[12] = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};
  return bytes.size() >= 12 && std::memcmp(bytes.data(), kId, 12) == 0;
}

// What the glTF reader resolves textures against: the model, the mesh file's folder,
// and the images already resolved (by image index: their MeshTexture::image).
struct GltfImages {
  const tinygltf::Model& model;
  const fs::path& dir;
  TriangleMesh& mesh;
  std::map<int, std::string> keys;

  // The image of texture `texture`: a file beside the mesh, or an embedded image
  // (a buffer view, a data URI) kept in the mesh by its key.
  std::string image_of(int texture, const std::string& where) {
    const std::string& path = mesh.source;
    const tinygltf::Texture& t = model.textures[texture];
    int source = t.source;
    if (source < 0) {
      for (const char* e : {"KHR_texture_basisu", "EXT_texture_webp", "MSFT_texture_dds"}) {
        if (t.extensions.count(e)) fail(path, where + ": its image is given only through " + e + ", which wavetrace does not read");
      }
      fail(path, where + ": the texture has no source image");
    }
    if (static_cast<size_t>(source) >= model.images.size()) fail(path, where + ": image index out of range");
    auto known = keys.find(source);
    if (known != keys.end()) return known->second;
    const tinygltf::Image& image = model.images[source];
    const std::string what = where + ": image " + std::to_string(source);
    const char* const kKtx2 = ": KTX2 / Basis Universal textures are not supported (PNG, JPEG, BMP, TGA, HDR, EXR are)";
    if (image.mimeType == "image/ktx2") fail(path, what + kKtx2);
    std::string key;
    if (image.bufferView >= 0 || !image.image.empty()) {
      EmbeddedImage e;
      e.key = path + "#images[" + std::to_string(source) + "]";
      if (image.bufferView >= 0) {
        const tinygltf::BufferView& view = model.bufferViews[image.bufferView];  // tinygltf checked the index
        const Elements bytes = view_elements(model, image.bufferView, 0, 1, view.byteLength, what, path);
        e.bytes.assign(reinterpret_cast<const char*>(bytes.data), view.byteLength);
      } else {
        e.bytes.assign(image.image.begin(), image.image.end());  // a data URI's, decoded from base64
      }
      if (e.bytes.empty()) fail(path, what + ": the embedded image is empty");
      if (is_ktx2(e.bytes)) fail(path, what + kKtx2);
      key = e.key;
      mesh.embedded.push_back(std::move(e));
    } else if (starts_with(image.uri, "data:")) {
      // tinygltf decodes the data URIs of the image types it knows; this is another.
      const std::string type = image.uri.substr(5, image.uri.find_first_of(";,") - 5);
      if (type == "image/ktx2") fail(path, what + kKtx2);
      fail(path, what + ": a data URI of type '" + type + "' is not an image wavetrace reads (PNG, JPEG, BMP, GIF are)");
    } else if (image.uri.empty()) {
      fail(path, what + " has neither a uri nor a buffer view");
    } else {
      key = (dir / gltf_uri_decode(image.uri)).lexically_normal().string();
      const std::string ext = lower_extension(key);
      if (ext == ".ktx2" || ext == ".basis") fail(path, what + kKtx2);
    }
    keys.emplace(source, key);
    return key;
  }

  // A material's texture (a textureInfo: `index`, `texCoord`, and
  // KHR_texture_transform), with its sampler's wrap and filters; `uv_set` is the
  // TEXCOORD set it reads.
  template <class Info>
  MeshTexture texture(const Info& info, const std::string& where, int& uv_set) {
    const std::string& path = mesh.source;
    if (info.index < 0 || static_cast<size_t>(info.index) >= model.textures.size()) fail(path, where + " index out of range");
    MeshTexture out;
    out.image = image_of(info.index, where);
    const int sampler = model.textures[info.index].sampler;
    if (sampler >= 0) {
      if (static_cast<size_t>(sampler) >= model.samplers.size()) fail(path, where + ": sampler index out of range");
      const tinygltf::Sampler& s = model.samplers[sampler];
      auto wrap = [&](int mode, const char* field) {
        switch (mode) {
          case TINYGLTF_TEXTURE_WRAP_REPEAT: return Wrap::Repeat;
          case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return Wrap::Clamp;
          case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return Wrap::Mirror;
        }
        fail(path, where + ": sampler " + std::to_string(sampler) + " " + field + " " + std::to_string(mode) +
                       " is not a wrap mode (10497, 33071, 33648)");
      };
      out.wrap_u = wrap(s.wrapS, "wrapS");
      out.wrap_v = wrap(s.wrapT, "wrapT");
      switch (s.magFilter) {
        case -1: case TINYGLTF_TEXTURE_FILTER_LINEAR: out.magnify = Filter::Bilinear; break;
        case TINYGLTF_TEXTURE_FILTER_NEAREST: out.magnify = Filter::Nearest; break;
        default: fail(path, where + ": sampler " + std::to_string(sampler) + " magFilter " + std::to_string(s.magFilter) +
                                " is not a filter (9728, 9729)");
      }
      // The mip-mapped minifications are all trilinear here.
      switch (s.minFilter) {
        case TINYGLTF_TEXTURE_FILTER_NEAREST: out.filter = Filter::Nearest; break;
        case TINYGLTF_TEXTURE_FILTER_LINEAR: out.filter = Filter::Bilinear; break;
        case -1: case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST: case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST:
        case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR: case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR:
          out.filter = Filter::Trilinear;
          break;
        default: fail(path, where + ": sampler " + std::to_string(sampler) + " minFilter " + std::to_string(s.minFilter) +
                                " is not a filter (9728, 9729, 9984-9987)");
      }
    }
    int set = info.texCoord;
    const char* kTransform = "KHR_texture_transform";
    if (info.extensions.count(kTransform)) {
      const std::string field = where + ": " + kTransform + " ";
      if (!extension_pair(info.extensions, kTransform, "offset", out.uv_offset)) fail(path, field + "offset must be 2 numbers");
      if (!extension_pair(info.extensions, kTransform, "scale", out.uv_scale)) fail(path, field + "scale must be 2 numbers");
      const double r = extension_number(info.extensions, kTransform, "rotation", 0.0);
      if (!std::isfinite(r)) fail(path, field + "rotation must be a number");
      out.uv_rotation = static_cast<float>(r);
      const double tc = extension_number(info.extensions, kTransform, "texCoord", set);
      if (!(tc == std::floor(tc))) fail(path, field + "texCoord must be a whole number");
      set = static_cast<int>(std::clamp(tc, -1.0, 1e6));
    }
    if (set != 0 && set != 1) {
      fail(path, where + ": texCoord " + std::to_string(set) + " is not supported (TEXCOORD_0 and TEXCOORD_1 are)");
    }
    uv_set = set;
    return out;
  }
};

MeshMaterial map_gltf(GltfImages& images, const tinygltf::Material& g, size_t index) {
  const std::string& path = images.mesh.source;
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
  const double strength = extension_number(g.extensions, "KHR_materials_emissive_strength", "emissiveStrength", 1.0);
  if (!(strength >= 0.0 && strength <= kMaxRadiance)) {
    fail(path, what + ": KHR_materials_emissive_strength emissiveStrength must be a number in [0, 1e9]");
  }
  emissive *= static_cast<float>(strength);
  if (std::max(emissive.x, std::max(emissive.y, emissive.z)) > kMaxRadiance) {
    fail(path, what + ": emissiveFactor times emissiveStrength exceeds 1e9 (the most radiance a scene may hold)");
  }
  const double ior = extension_number(g.extensions, "KHR_materials_ior", "ior", 1.5);
  if (!(ior == 0.0 || (ior >= 1.0 && ior <= 10.0))) fail(path, what + ": KHR_materials_ior ior must be 0 or in [1, 10]");
  // The texture coordinates of the material's first texture; another texture of it
  // naming the other set is a warning (every texture reads the first's).
  int first_set = -1;
  auto texture = [&](const auto& info, const std::string& where) {
    int set = 0;
    MeshTexture t = images.texture(info, what + ": " + where, set);
    if (first_set < 0) {
      first_set = set;
    } else if (set != first_set) {
      images.mesh.warnings.push_back(what + ": its " + where + " reads TEXCOORD_" + std::to_string(set) +
                                     ", another of its textures TEXCOORD_" + std::to_string(first_set) +
                                     "; all read TEXCOORD_" + std::to_string(first_set));
    }
    out.uv_set = first_set;
    return t;
  };
  // Alpha: the base colour's, where the mode reads it.
  if (g.alphaMode == "MASK" || g.alphaMode == "BLEND") {
    out.alpha_factor = static_cast<float>(pbr.baseColorFactor[3]);
    if (!(out.alpha_factor >= 0.0f && out.alpha_factor <= 1.0f)) {
      fail(path, what + ": baseColorFactor's alpha must be in [0, 1]");
    }
    if (g.alphaMode == "MASK") {
      if (!(g.alphaCutoff >= 0.0 && g.alphaCutoff <= 1e9)) fail(path, what + ": alphaCutoff must be a number >= 0");
      out.alpha_cutoff = static_cast<float>(g.alphaCutoff);
    }
    // Without a texture a constant alpha decides once: wholly there, or (MASK)
    // wholly not; BLEND keeps its chance.
    const bool textured = pbr.baseColorTexture.index >= 0;
    const bool opaque = !textured && (g.alphaMode == "MASK" ? out.alpha_factor >= out.alpha_cutoff : out.alpha_factor >= 1.0f);
    if (!opaque) out.alpha_mode = static_cast<uint32_t>(g.alphaMode == "MASK" ? AlphaMode::Mask : AlphaMode::Blend);
  } else if (g.alphaMode != "OPAQUE") {
    fail(path, what + ": alphaMode '" + g.alphaMode + "' is not OPAQUE, MASK or BLEND");
  }
  // What lets light through (transmission) or layers the surface (a coat) makes it
  // more than an emitter: it reflects, and emits too.
  const double transmission = extension_number(g.extensions, "KHR_materials_transmission", "transmissionFactor", 0.0);
  const double clearcoat = extension_number(g.extensions, "KHR_materials_clearcoat", "clearcoatFactor", 0.0);
  // (A black base's 4% specular layer alone is left out: such a material is an
  // emitter, as it was before materials could emit.)
  auto max3 = [](vec3 v) { return std::max(v.x, std::max(v.y, v.z)); };
  const bool reflects = max3(base) > 0.0f || pbr.baseColorTexture.index >= 0 || transmission != 0.0 || clearcoat != 0.0;
  if (max3(emissive) > 0.0f && !reflects) {
    out.material = make_material(MaterialKind::Emissive, vec3(0.0f), 0.0f, 1.0f, emissive);
    if (g.emissiveTexture.index >= 0) out.albedo_map = texture(g.emissiveTexture, "emissive texture");
    if (out.alpha_mode != 0 && pbr.baseColorTexture.index >= 0) {
      out.alpha_map = texture(pbr.baseColorTexture, "base colour texture");
    }
    return out;
  }
  out.material = make_material(MaterialKind::Principled, base, 0.0f, 1.0f, vec3(0.0f));
  // ior 0 is the extension's special case of f0 = 1; an index of 1e4 (f0 = 0.9996)
  // stands in for it.
  out.material.ior = ior == 0.0 ? 1e4f : static_cast<float>(ior);
  out.material.flags = kMaterialCompensated | (g.doubleSided ? 0u : static_cast<uint32_t>(kMaterialOneSided));
  out.metallic = unit(pbr.metallicFactor, "metallicFactor");
  out.specular = unit(extension_number(g.extensions, "KHR_materials_specular", "specularFactor", 1.0),
                      "KHR_materials_specular specularFactor");
  extension_colour(g.extensions, "KHR_materials_specular", "specularColorFactor", 1e3, path, what, out.specular_color);
  {
    tinygltf::NormalTextureInfo info;
    if (extension_texture(g.extensions, "KHR_materials_specular", "specularTexture", path, what, info)) {
      out.specular_map = texture(info, "specular texture");
    }
    info = {};
    if (extension_texture(g.extensions, "KHR_materials_specular", "specularColorTexture", path, what, info)) {
      out.specular_color_map = texture(info, "specular colour texture");
    }
  }
  out.roughness = unit(pbr.roughnessFactor, "roughnessFactor");
  if (max3(emissive) > 0.0f) {
    out.material.emission = emissive;
    out.material.flags |= kMaterialEmits;
    if (g.emissiveTexture.index >= 0) out.emission_map = texture(g.emissiveTexture, "emissive texture");
  }
  // KHR_materials_clearcoat.
  tinygltf::NormalTextureInfo info;
  const char* kCoat = "KHR_materials_clearcoat";
  out.clearcoat = unit(clearcoat, "KHR_materials_clearcoat clearcoatFactor");
  out.clearcoat_roughness =
      unit(extension_number(g.extensions, kCoat, "clearcoatRoughnessFactor", 0.0), "KHR_materials_clearcoat clearcoatRoughnessFactor");
  if (extension_texture(g.extensions, kCoat, "clearcoatTexture", path, what, info = {})) {
    out.clearcoat_map = texture(info, "clearcoat texture");
  }
  if (extension_texture(g.extensions, kCoat, "clearcoatRoughnessTexture", path, what, info = {})) {
    out.clearcoat_roughness_map = texture(info, "clearcoat roughness texture");
  }
  if (extension_texture(g.extensions, kCoat, "clearcoatNormalTexture", path, what, info = {})) {
    out.clearcoat_normal_map = texture(info, "clearcoat normal texture");
    if (!(info.scale >= 0.0 && info.scale <= 1e3)) fail(path, what + ": KHR_materials_clearcoat clearcoatNormalTexture scale must be in [0, 1000]");
    out.clearcoat_normal_scale = static_cast<float>(info.scale);
  }
  // KHR_materials_transmission, and KHR_materials_volume: a volume where its
  // thickness is not 0 (the thickness itself is a rasteriser's stand-in for the
  // distance a path tracer measures).
  out.transmission = unit(transmission, "KHR_materials_transmission transmissionFactor");
  if (extension_texture(g.extensions, "KHR_materials_transmission", "transmissionTexture", path, what, info = {})) {
    out.transmission_map = texture(info, "transmission texture");
  }
  const char* kVolume = "KHR_materials_volume";
  const double thickness = extension_number(g.extensions, kVolume, "thicknessFactor", 0.0);
  if (!(thickness >= 0.0 && thickness <= 1e9)) fail(path, what + ": KHR_materials_volume thicknessFactor must be a number >= 0");
  out.thin = thickness == 0.0;
  const double distance = extension_number(g.extensions, kVolume, "attenuationDistance", 0.0);
  if (!(distance >= 0.0 && distance <= 1e30)) {
    fail(path, what + ": KHR_materials_volume attenuationDistance must be a number > 0");
  }
  auto volume = g.extensions.find(kVolume);
  if (volume != g.extensions.end() && volume->second.IsObject()) {
    if (volume->second.Has("attenuationDistance") && distance == 0.0) {
      fail(path, what + ": KHR_materials_volume attenuationDistance must be a number > 0");
    }
    out.attenuation_distance = static_cast<float>(distance);
    extension_colour(g.extensions, kVolume, "attenuationColor", 1.0, path, what, out.attenuation_color);
  }
  if (pbr.baseColorTexture.index >= 0) out.albedo_map = texture(pbr.baseColorTexture, "base colour texture");
  if (out.alpha_mode != 0) out.alpha_map = out.albedo_map;
  if (pbr.metallicRoughnessTexture.index >= 0) {
    out.roughness_map = out.metallic_map = texture(pbr.metallicRoughnessTexture, "metallic-roughness texture");
  }
  if (g.normalTexture.index >= 0) {
    out.normal_map = texture(g.normalTexture, "normal texture");
    if (!(g.normalTexture.scale >= 0.0 && g.normalTexture.scale <= 1e3)) {
      fail(path, what + ": normalTexture scale must be in [0, 1000]");
    }
    out.normal_scale = static_cast<float>(g.normalTexture.scale);
  }
  // Occlusion is read and checked, not applied: the paths find the occlusion.
  if (g.occlusionTexture.index >= 0 && static_cast<size_t>(g.occlusionTexture.index) >= images.model.textures.size()) {
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
      : model_(model), mesh_(mesh), builder_(mesh), images_{model, dir, mesh, {}} {
    check_extensions(model, mesh);
    for (size_t i = 0; i < model.cameras.size(); ++i) {
      const tinygltf::Camera& g = model.cameras[i];
      MeshCamera c;
      c.name = g.name;
      c.perspective = g.type != "orthographic";
      if (c.perspective) {
        if (g.type != "perspective") {
          fail(mesh.source, "camera " + std::to_string(i) + ": type '" + g.type + "' is not perspective or orthographic");
        }
        if (!(g.perspective.yfov > 0.0 && g.perspective.yfov < kPi)) {
          fail(mesh.source, "camera " + std::to_string(i) + ": yfov must be in (0, pi) radians");
        }
        c.yfov = static_cast<float>(g.perspective.yfov);
      }
      mesh.cameras.push_back(c);
    }
    for (size_t i = 0; i < model.materials.size(); ++i) {
      mesh.materials.push_back(map_gltf(images_, model.materials[i], i));
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
      read_light(node, v.node, world);
      if (node.camera >= 0) place_camera(node, v.node, world);
      for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.push_back({*c, world});
    }
  }

  // The node's camera at the node's origin, looking down its -z, +y up (the first
  // node that names a camera places it).
  void place_camera(const tinygltf::Node& node, int index, const glm::dmat4& world) {
    if (static_cast<size_t>(node.camera) >= mesh_.cameras.size()) {
      fail(mesh_.source, "node " + std::to_string(index) + ": camera index " + std::to_string(node.camera) +
                             " out of range (" + std::to_string(mesh_.cameras.size()) + " cameras)");
    }
    MeshCamera& c = mesh_.cameras[node.camera];
    if (c.placed) return;
    const glm::dvec3 forward = glm::dmat3(world) * glm::dvec3(0.0, 0.0, -1.0);
    const glm::dvec3 up = glm::dmat3(world) * glm::dvec3(0.0, 1.0, 0.0);
    if (!(glm::length(glm::cross(forward, up)) > 0.0)) {
      fail(mesh_.source, "node " + std::to_string(index) + ": the node's transform collapses its camera's view");
    }
    c.position = vec3(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
    c.forward = vec3(glm::normalize(forward));
    c.up = vec3(glm::normalize(up));
    c.placed = true;
  }

  // The node's KHR_lights_punctual light, at its origin and shining down its -z.
  void read_light(const tinygltf::Node& node, int index, const glm::dmat4& world) {
    auto e = node.extensions.find("KHR_lights_punctual");
    if (e == node.extensions.end()) return;
    const std::string& path = mesh_.source;
    const std::string where = "node " + std::to_string(index) + ": KHR_lights_punctual";
    if (!e->second.IsObject() || !e->second.Has("light") || !e->second.Get("light").IsInt()) {
      fail(path, where + ": light must be a light's index");
    }
    const int i = e->second.Get("light").GetNumberAsInt();
    if (i < 0 || static_cast<size_t>(i) >= model_.lights.size()) {
      fail(path, where + ": light index " + std::to_string(i) + " out of range (" +
                     std::to_string(model_.lights.size()) + " lights)");
    }
    const tinygltf::Light& g = model_.lights[i];
    const std::string what = "light " + std::to_string(i) + (g.name.empty() ? "" : " '" + g.name + "'");
    PunctualLight l{};
    if (g.type == "point") {
      l.kind = PunctualKind::Point;
    } else if (g.type == "spot") {
      l.kind = PunctualKind::Spot;
    } else if (g.type == "directional") {
      l.kind = PunctualKind::Directional;
    } else {
      fail(path, what + ": type '" + g.type + "' is not point, spot or directional");
    }
    vec3 colour(1.0f);
    if (!g.color.empty()) {
      for (size_t c = 0; c < 3; ++c) {
        if (g.color.size() != 3 || !(g.color[c] >= 0.0 && g.color[c] <= 1.0)) {
          fail(path, what + ": color must be 3 numbers in [0, 1]");
        }
        colour[static_cast<int>(c)] = static_cast<float>(g.color[c]);
      }
    }
    if (!(g.intensity >= 0.0 && g.intensity <= kMaxRadiance)) fail(path, what + ": intensity must be in [0, 1e9]");
    l.intensity = colour * static_cast<float>(g.intensity);
    if (!(g.range >= 0.0 && std::isfinite(g.range))) fail(path, what + ": range must be a positive number");
    l.range = l.kind == PunctualKind::Directional ? 0.0f : static_cast<float>(g.range);
    if (l.kind == PunctualKind::Spot) {
      const double inner = g.spot.innerConeAngle, outer = g.spot.outerConeAngle;
      if (!(inner >= 0.0 && inner < outer && outer <= 0.5 * kPi + 1e-6)) {
        fail(path, what + ": spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi / 2");
      }
      set_spot_cones(l, inner, outer);
    }
    l.position = vec3(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
    const glm::dvec3 d = glm::dmat3(world) * glm::dvec3(0.0, 0.0, -1.0);
    if (!(glm::length(d) > 0.0)) fail(path, where + ": the node's transform collapses the light's direction");
    l.direction = vec3(glm::normalize(d));
    mesh_.lights.push_back(l);
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
      const int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT, kByte = TINYGLTF_COMPONENT_TYPE_BYTE,
                kUbyte = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, kShort = TINYGLTF_COMPONENT_TYPE_SHORT,
                kUshort = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
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
          return map_gltf(images_, g, 0);
        });
      }
      // Component types: the core's, and KHR_mesh_quantization's.
      if (attribute("POSITION") < 0) fail(path, what + ": no POSITION attribute");
      const std::vector<float> pos = read_accessor<float>(model_, attribute("POSITION"), what + " POSITION",
                                                          TINYGLTF_TYPE_VEC3, {kFloat, kByte, kUbyte, kShort, kUshort}, path);
      const size_t count = pos.size() / 3;
      auto optional = [&](const std::string& name, int type, const std::vector<int>& components) {
        std::vector<float> v;
        if (attribute(name.c_str()) < 0) return v;
        v = read_accessor<float>(model_, attribute(name.c_str()), what + " " + name, type, components, path);
        if (v.size() / tinygltf::GetNumComponentsInType(type) != count) {
          fail(path, what + ": " + name + " and POSITION counts differ");
        }
        return v;
      };
      const std::vector<float> tan = optional("TANGENT", TINYGLTF_TYPE_VEC4, {kFloat, kByte, kShort});
      const std::vector<float> nrm = optional("NORMAL", TINYGLTF_TYPE_VEC3, {kFloat, kByte, kShort});
      // The set of texture coordinates the material's textures read.
      const int set = mesh_.materials[material].uv_set;
      const std::string uv_name = "TEXCOORD_" + std::to_string(set);
      const std::vector<float> uv = optional(uv_name, TINYGLTF_TYPE_VEC2, {kFloat, kByte, kUbyte, kShort, kUshort});
      if (set != 0 && uv.empty()) {
        fail(path, what + ": its material's textures read " + uv_name + ", which the primitive does not have");
      }

      const size_t first = mesh_.positions.size();
      std::vector<vec3> world_pos(count);
      for (size_t i = 0; i < count; ++i) {
        glm::dvec4 p4 = world * glm::dvec4(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2], 1.0);
        world_pos[i] = vec3(p4);
        vec3 n;
        if (!nrm.empty()) n = vec3(normal_matrix * glm::dvec3(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]));
        // glTF puts v = 0 at the image's top row, as a mesh's UVs do.
        vec2 tc = uv.empty() ? vec2(0.0f) : vec2(uv[2 * i], uv[2 * i + 1]);
        // Tangents turn with the node as directions do; a mirroring node flips
        // the handedness.
        vec4 tg(0.0f);
        if (!tan.empty()) {
          tg = vec4(vec3(glm::dmat3(world) * glm::dvec3(tan[4 * i], tan[4 * i + 1], tan[4 * i + 2])),
                    tan[4 * i + 3] * (mirrors ? -1.0f : 1.0f));
        }
        builder_.add_vertex(world_pos[i], nrm.empty() ? nullptr : &n, uv.empty() ? nullptr : &tc,
                            tan.empty() ? nullptr : &tg);
      }

      std::vector<uint32_t> idx;
      if (prim.indices >= 0) {
        idx = read_accessor<uint32_t>(model_, prim.indices, what + " indices", TINYGLTF_TYPE_SCALAR,
                                      {kUbyte, kUshort, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT}, path);
      }
      const size_t corners = prim.indices >= 0 ? idx.size() : count;
      if (corners % 3 != 0) fail(path, what + ": " + std::to_string(corners) + " corners is not a multiple of 3");
      for (size_t t = 0; t < corners / 3; ++t) {
        uint32_t c[3];
        for (int k = 0; k < 3; ++k) {
          c[k] = prim.indices >= 0 ? idx[3 * t + k] : static_cast<uint32_t>(3 * t + k);
          if (c[k] >= count) {
            fail(path, what + ": index " + std::to_string(c[k]) + " out of range (" + std::to_string(count) +
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
  GltfImages images_;
  int64_t default_ = -1;
};

// tinygltf's image callback, given a data URI's bytes (decoded from base64) or a
// buffer view's. Nothing is decoded here: a data URI's bytes are kept in the image
// for GltfImages; a buffer view's are taken there, once its range is checked
// (tinygltf hands them over unchecked, and they are not read here).
bool keep_image(tinygltf::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes,
                int size, void*) {
  if (image->bufferView < 0 && size > 0) image->image.assign(bytes, bytes + size);
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
  loader.SetImageLoader(keep_image, nullptr);
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

void add_indexed_mesh(const IndexedMesh& in, TriangleMesh& mesh) {
  constexpr uint32_t kUnused = std::numeric_limits<uint32_t>::max();
  MeshBuilder builder(mesh);
  std::vector<size_t> kept;
  std::vector<uint32_t> index(in.positions.size(), kUnused);  // the file's vertex -> the mesh's
  for (size_t t = 0; t < in.triangles.size(); ++t) {
    const std::array<uint32_t, 3>& c = in.triangles[t];
    if (!builder.keep(in.positions[c[0]], in.positions[c[1]], in.positions[c[2]])) continue;
    kept.push_back(t);
    for (uint32_t v : c) index[v] = 0;
  }
  const bool normals = !in.normals.empty(), uvs = !in.uvs.empty();
  for (size_t v = 0; v < index.size(); ++v) {
    if (index[v] == kUnused) continue;
    // Checked here, so that the message names the vertex as the file numbers it.
    if (normals && (!finite(in.normals[v]) || glm::length(in.normals[v]) == 0.0f)) {
      fail(mesh.source, "vertex " + std::to_string(v) + " has a zero or non-finite normal");
    }
    if (uvs && !(std::isfinite(in.uvs[v].x) && std::isfinite(in.uvs[v].y))) {
      fail(mesh.source, "vertex " + std::to_string(v) + " has a non-finite texture coordinate");
    }
    index[v] = builder.add_vertex(in.positions[v], normals ? &in.normals[v] : nullptr, uvs ? &in.uvs[v] : nullptr);
  }
  if (!kept.empty()) {
    int64_t fallback = -1;
    const uint32_t material = default_material(mesh, fallback, white_default_material);
    for (size_t t : kept) {
      const std::array<uint32_t, 3>& c = in.triangles[t];
      builder.add_triangle(index[c[0]], index[c[1]], index[c[2]], material);
    }
  }
  builder.finish();
}

TriangleMesh load_mesh(const std::string& path, uint32_t shape_index) {
  const std::string ext = lower_extension(path);
  if (ext != ".obj" && ext != ".gltf" && ext != ".glb" && ext != ".ply" && ext != ".serialized") {
    fail(path, "unknown mesh format '" + ext + "' (expected .obj, .gltf, .glb, .ply, .serialized)");
  }
  const std::string bytes = read_input_file(path, input::kMesh);
  const fs::path dir = fs::path(path).parent_path();
  TriangleMesh mesh;
  mesh.source = path;
  if (ext == ".obj") {
    load_obj(bytes, dir, mesh);
  } else if (ext == ".ply") {
    load_ply(bytes, mesh);
  } else if (ext == ".serialized") {
    load_serialized(bytes, shape_index, mesh);
  } else {
    load_gltf(bytes, ext == ".glb", dir, mesh);
  }
  return mesh;
}

void set_spot_cones(PunctualLight& l, double inner, double outer) {
  // KHR_lights_punctual's smooth step between the cones' cosines.
  const float cos_inner = static_cast<float>(std::cos(inner)), cos_outer = static_cast<float>(std::cos(outer));
  l.spot_scale = 1.0f / std::max(0.001f, cos_inner - cos_outer);
  l.spot_offset = -cos_outer * l.spot_scale;
}

}  // namespace wt

// Scene files: meshes (files of triangles, read once) and instances (placements of
// a mesh by a transform, with an optional material).
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <future>
#include <limits>
#include <optional>

#include "scene/input_file.hpp"
#include "scene/mesh_formats.hpp"
#include "scene/mesh_load.hpp"
#include "scene/mesh_shapes.hpp"
#include "errors/errors.hpp"
#include "scene/scene_reader.hpp"

namespace wt {

namespace {

// The other side out: each triangle's winding reversed, its normals turned round.
void flip_normals(TriangleMesh& m) {
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  for (vec3& n : m.normals) n = -n;
}

Affine affine_of(const glm::dmat4& m) {
  Affine a;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) a.m[4 * r + c] = static_cast<float>(m[c][r]);  // glm is column-major
  }
  return a;
}

}  // namespace

void SceneReader::read_meshes(const json& list, const JsonPath& path) {
  // Every file is read on a thread of its own; the scene takes them in file order,
  // so the first bad one (in the scene file's order) is the one reported.
  struct Spec {
    std::string name, file, shape;
    uint32_t shape_index = 0;
    int32_t material = -1;
    bool face_normals = false, flip_normals = false;
    std::optional<AlphaTest> alpha;
    std::optional<IndexedMesh> data;  // the entry's own arrays ("positions", "indices", ...)
  };
  std::vector<Spec> specs;
  for (size_t i = 0; i < list.size(); ++i) {
    const JsonPath at = path / i;
    const json& j = list[i];
    object(j, at);
    check_keys(j, at, {"name", "file", "shape", "shape_index", "material", "face_normals", "flip_normals", "alpha",
                       "positions", "indices", "normals", "uvs"});
    Spec s;
    s.name = name(j, at);
    remember(mesh_names_, s.name, i, "mesh", at);
    const int sources = (j.contains("file") ? 1 : 0) + (j.contains("shape") ? 1 : 0) + (j.contains("positions") ? 1 : 0);
    if (sources != 1) fail_at(at, "give one of \"file\", \"shape\" or \"positions\" (with \"indices\")");
    for (const char* key : {"indices", "normals", "uvs"}) {
      if (j.contains(key) && !j.contains("positions")) fail_at(at / key, "belongs to a mesh given by \"positions\"");
    }
    if (j.contains("positions")) {
      s.data = read_mesh_arrays(j, at);
    } else if (j.contains("shape")) {
      s.shape = string(j["shape"], at / "shape");
      if (std::find(shape_names().begin(), shape_names().end(), s.shape) == shape_names().end()) {
        fail_at(at / "shape", "unknown shape '" + s.shape + "' (expected " + listed(shape_names()) + ")");
      }
    } else {
      s.file = (base_dir_ / string(j["file"], at / "file")).lexically_normal().string();
    }
    if (j.contains("shape_index")) {
      s.shape_index = static_cast<uint32_t>(integer(j["shape_index"], at / "shape_index", 0, 0xffffffffLL));
      if (lower_extension(s.file) != ".serialized") fail_at(at / "shape_index", "selects a shape of a .serialized file only");
    }
    s.material = j.contains("material") ? material_named(j["material"], at / "material") : -1;
    if (j.contains("face_normals")) s.face_normals = boolean(j["face_normals"], at / "face_normals");
    if (j.contains("flip_normals")) s.flip_normals = boolean(j["flip_normals"], at / "flip_normals");
    if (j.contains("alpha")) {
      if (s.material < 0) fail_at(at / "alpha", "needs the mesh's \"material\" (a file's own materials carry their own alpha)");
      s.alpha = read_alpha(j["alpha"], at / "alpha");
    }
    specs.push_back(std::move(s));
  }
  const auto start = Clock::now();
  std::vector<std::future<TriangleMesh>> loading;
  for (const Spec& s : specs) {
    if (s.data) {
      loading.push_back(std::async(std::launch::deferred, [&s, this] {
        TriangleMesh mesh;
        mesh.source = "mesh '" + s.name + "'";
        add_indexed_mesh(*s.data, mesh);
        return mesh;
      }));
    } else if (!s.shape.empty()) {
      loading.push_back(std::async(std::launch::deferred, shape_mesh, s.shape));
    } else {
      loading.push_back(std::async(std::launch::async, [file = s.file, index = s.shape_index] { return load_mesh(file, index); }));
    }
  }
  // A mesh file's error names the scene file and the field that names the mesh
  // file, then the mesh file and what is wrong in it.
  std::vector<TriangleMesh> meshes;
  std::string first_error;
  for (size_t i = 0; i < loading.size(); ++i) {
    try {
      meshes.push_back(loading[i].get());
      if (specs[i].face_normals) {
        meshes.back().normals.clear();
        meshes.back().tangents.clear();
      }
      if (specs[i].flip_normals) flip_normals(meshes.back());
    } catch (const InputError& e) {
      if (first_error.empty()) {
        first_error = source() + ": " + (path / i / (specs[i].data ? "positions" : "file")).str() + ": " + e.what();
      }
    }
  }
  if (!first_error.empty()) throw InputError(first_error);
  mesh_seconds_ += seconds_since(start);
  for (size_t i = 0; i < meshes.size(); ++i) {
    try {
      add_mesh(meshes[i], specs[i].name, specs[i].material, specs[i].alpha ? &*specs[i].alpha : nullptr);
    } catch (const InputError& e) {  // a texture its materials name, its size
      throw InputError(source() + ": " + (path / i / (specs[i].data ? "positions" : "file")).str() + ": " + e.what());
    }
  }
}

// A mesh entry's own arrays: "positions" (rows of x, y, z), "indices" (rows of three
// vertex indices, each below the vertex count), and "normals" (x, y, z) and "uvs"
// (u, v; v = 0 the image's bottom row, as OBJ's) of every vertex where given.
IndexedMesh SceneReader::read_mesh_arrays(const json& j, const JsonPath& path) const {
  auto rows = [&](const char* key, size_t width, auto&& take) {
    const JsonPath at = path / key;
    const json& list = j[key];
    if (!list.is_array()) fail_at(at, "must be a list of rows of " + std::to_string(width) + " numbers");
    for (size_t r = 0; r < list.size(); ++r) {
      const json& row = list[r];
      if (!row.is_array() || row.size() != width) {
        fail_at(at / r, "must be a row of " + std::to_string(width) + " numbers");
      }
      take(row, at / r);
    }
  };
  IndexedMesh m;
  rows("positions", 3, [&](const json& row, const JsonPath& at) { m.positions.push_back(position(row, at)); });
  if (m.positions.empty()) fail_at(path / "positions", "holds no vertex");
  if (!j.contains("indices")) fail_at(path, "a mesh given by \"positions\" needs \"indices\"");
  const int64_t last = static_cast<int64_t>(m.positions.size()) - 1;
  rows("indices", 3, [&](const json& row, const JsonPath& at) {
    m.triangles.push_back({static_cast<uint32_t>(integer(row[0], at / 0, 0, last)),
                           static_cast<uint32_t>(integer(row[1], at / 1, 0, last)),
                           static_cast<uint32_t>(integer(row[2], at / 2, 0, last))});
  });
  if (j.contains("normals")) {
    rows("normals", 3, [&](const json& row, const JsonPath& at) { m.normals.push_back(triple(row, at)); });
  }
  if (j.contains("uvs")) {
    rows("uvs", 2, [&](const json& row, const JsonPath& at) {
      const vec2 uv = pair(row, at);
      m.uvs.push_back(vec2(uv.x, 1.0f - uv.y));
    });
  }
  for (const auto& [key, count] : {std::pair<const char*, size_t>{"normals", m.normals.size()}, {"uvs", m.uvs.size()}}) {
    if (j.contains(key) && count != m.positions.size()) {
      fail_at(path / key, "has " + std::to_string(count) + " rows for " + std::to_string(m.positions.size()) +
                              " positions (one a vertex)");
    }
  }
  return m;
}

AlphaTest SceneReader::read_alpha(const json& j, const JsonPath& path) {
  object(j, path);
  check_keys(j, path, {"mode", "opacity", "texture", "channel", "cutoff"});
  AlphaTest a{};
  a.mode = choice(required(j, path, "mode"), path / "mode", {"blend", "mask"}) == 0 ? AlphaMode::Blend : AlphaMode::Mask;
  a.factor = j.contains("opacity") ? unit_interval(j["opacity"], path / "opacity") : 1.0f;
  a.cutoff = 0.5f;
  if (j.contains("cutoff")) {
    if (a.mode != AlphaMode::Mask) fail_at(path / "cutoff", "applies to \"mode\": \"mask\" only");
    a.cutoff = unit_interval(j["cutoff"], path / "cutoff");
  }
  a.texture = -1;
  if (j.contains("texture")) {
    const JsonPath at = path / "texture";
    a.texture = texture_named(j["texture"], at);
    const Texture t = scene_.textures[static_cast<size_t>(a.texture)];
    if (t.kind != TextureKind::Image) fail_at(at, "must be an image texture (its A channel, or its luminance, is the alpha)");
    if (j.contains("channel") && choice(j["channel"], path / "channel", {"alpha", "luminance"}) == 1) {
      // The image's luminance (Rec. 709 weights of its linear colour) as its alpha, in
      // an image of its own.
      Image im = scene_.images[static_cast<size_t>(t.image)];
      for (size_t k = 0; k + 3 < im.texels.size(); k += 4) {
        im.texels[k + 3] = channel_of(&im.texels[k], HeightChannel::Luminance);
      }
      im.path += "#luminance";
      scene_.images.push_back(std::move(im));
      Texture lum = t;
      lum.image = static_cast<int32_t>(scene_.images.size() - 1);
      scene_.textures.push_back(lum);
      a.texture = static_cast<int32_t>(scene_.textures.size() - 1);
    }
  } else if (j.contains("channel")) {
    fail_at(path / "channel", "reads the alpha's \"texture\": give one");
  }
  return a;
}

void SceneReader::add_mesh(const TriangleMesh& mesh, const std::string& name, int32_t material_override,
                           const AlphaTest* alpha) {
  const size_t total = scene_.triangles.size() + mesh.triangles.size();
  if (total > static_cast<size_t>(std::numeric_limits<int32_t>::max()) ||
      scene_.normals.size() + mesh.positions.size() > std::numeric_limits<uint32_t>::max()) {
    throw InputError(mesh.source + ": the scene's meshes hold more than 2^31 - 1 triangles");
  }
  // The file's materials join the scene's, named "<mesh>/<material>", unless overridden.
  std::vector<uint32_t> material_of(mesh.materials.size());
  std::vector<uint32_t> alpha_of(mesh.materials.size(), 0u);  // TriangleGeom::alpha of each
  if (material_override < 0) {
    for (size_t i = 0; i < mesh.materials.size(); ++i) {
      const MeshMaterial& mm = mesh.materials[i];
      Material m = mm.material;
      // As the file samples it (OBJ's maps, and glTF's default sampler, repeat on
      // both axes), its image a file or one the mesh file holds.
      auto texture_for = [&](const MeshTexture& mt, bool srgb) {
        const std::string* embedded = nullptr;
        for (const EmbeddedImage& e : mesh.embedded) embedded = e.key == mt.image ? &e.bytes : embedded;
        Texture t = image_texture(image_file(mt.image, srgb, mesh.source, embedded), mt.wrap_u, mt.wrap_v);
        t.filter = mt.filter;
        t.magnify = mt.magnify;
        t.uv_offset = mt.uv_offset;
        t.uv_scale = mt.uv_scale;
        t.uv_cos = std::cos(mt.uv_rotation);
        t.uv_sin = std::sin(mt.uv_rotation);
        return t;
      };
      auto texture_of = [&](const MeshTexture& mt, bool srgb) {
        scene_.textures.push_back(texture_for(mt, srgb));
        return static_cast<int32_t>(scene_.textures.size() - 1);
      };
      // A linear map read as another already is (glTF's metallic with its roughness,
      // a coat's roughness with its strength) is that texture, which bsdf_at then
      // looks up once; the same image under another transform or sampler is its own.
      auto shared_or_new = [&](const MeshTexture& mt, const MeshTexture& other, int32_t other_texture) {
        return other_texture >= 0 && mt.same_lookup(other) ? other_texture : texture_of(mt, false);
      };
      // MTL's bump map: heights, or a normal map where its texels read as one.
      auto add_bump = [&](MaterialParams& p) {
        if (mm.bump_map.empty()) return;
        const Texture heights = texture_for(mm.bump_map, false);
        if (mm.bump_may_be_normal_map() && reads_as_normal_map(scene_.images[static_cast<size_t>(heights.image)])) {
          scene_.textures.push_back(heights);
          p.normal_texture = static_cast<int32_t>(scene_.textures.size() - 1);
          p.normal_strength = mm.bump_scale;
          return;
        }
        const char c = mm.bump_channel;
        p.bump_texture = bump_texture(heights, c == 'r'   ? HeightChannel::Red
                                               : c == 'g' ? HeightChannel::Green
                                               : c == 'b' ? HeightChannel::Blue
                                               : c == 'm' ? HeightChannel::Alpha
                                                          : HeightChannel::Luminance);
        p.bump_scale = mm.bump_scale;
      };
      if (!mm.albedo_map.empty()) {
        m.texture = texture_of(mm.albedo_map, true);
        m.sort_key = static_cast<uint8_t>(material_sort_key(m.kind, static_cast<int>(TextureKind::Image)));
      }
      if (m.kind == MaterialKind::Principled) {
        MaterialParams p{};
        p.table_rows = 1;
        p.roughness_texture = p.normal_texture = -1;
        p.normal_strength = mm.normal_scale;
        const Ggx g = ggx_from_roughness(mm.roughness, mm.anisotropy);
        p.ax = g.ax;
        p.ay = g.ay;
        p.metallic = mm.metallic;
        p.specular = mm.specular;
        set_principled_layers(p, m, PrincipledLayers{mm.clearcoat, mm.clearcoat_roughness, mm.clearcoat_normal_scale,
                                                     mm.transmission, mm.thin, mm.attenuation_color,
                                                     mm.attenuation_distance});
        if (!mm.clearcoat_map.empty()) p.clearcoat_texture = texture_of(mm.clearcoat_map, false);
        if (!mm.clearcoat_roughness_map.empty()) {
          p.coat_roughness_texture = shared_or_new(mm.clearcoat_roughness_map, mm.clearcoat_map, p.clearcoat_texture);
        }
        if (!mm.clearcoat_normal_map.empty()) p.coat_normal_texture = texture_of(mm.clearcoat_normal_map, false);
        if (!mm.transmission_map.empty()) p.transmission_texture = texture_of(mm.transmission_map, false);
        if (!mm.emission_map.empty()) p.emission_texture = texture_of(mm.emission_map, true);
        p.specular_color = mm.specular_color;
        if (!mm.specular_map.empty()) p.specular_texture = texture_of(mm.specular_map, false);
        if (!mm.specular_color_map.empty()) p.specular_color_texture = texture_of(mm.specular_color_map, true);
        if (!mm.roughness_map.empty()) p.roughness_texture = texture_of(mm.roughness_map, false);
        if (!mm.metallic_map.empty()) {
          p.metallic_texture = shared_or_new(mm.metallic_map, mm.roughness_map, p.roughness_texture);
        }
        if (!mm.normal_map.empty()) p.normal_texture = texture_of(mm.normal_map, false);
        add_bump(p);
        prepare_microfacet(m, p, scene_.bsdf_tables, shared_tables_);
        m.params = static_cast<int32_t>(scene_.material_params.size());
        scene_.material_params.push_back(p);
      } else if (!mm.bump_map.empty()) {
        // Another kind with a bump map: parameters of its own, which only the
        // kernels with them (kMicrofacet) read.
        MaterialParams p{};
        add_bump(p);
        m.params = static_cast<int32_t>(scene_.material_params.size());
        scene_.material_params.push_back(p);
      }
      if (mm.alpha_mode != 0) {
        AlphaTest a{static_cast<AlphaMode>(mm.alpha_mode), -1, mm.alpha_factor, mm.alpha_cutoff};
        if (!mm.alpha_map.empty()) {
          a.texture = mm.alpha_map.image == mm.albedo_map.image && m.texture >= 0 ? m.texture : texture_of(mm.alpha_map, true);
        }
        alpha_of[i] = static_cast<uint32_t>(scene_.alpha_tests.size()) + 1u;
        scene_.alpha_tests.push_back(a);
      }
      material_of[i] = static_cast<uint32_t>(scene_.materials.size());
      scene_.materials.push_back(m);
      scene_.material_names.push_back(name + "/" + mm.name);
    }
  }
  SceneMesh sm;
  sm.name = name;
  sm.file = mesh.source;
  sm.first_triangle = static_cast<uint32_t>(scene_.triangles.size());
  sm.triangle_count = static_cast<uint32_t>(mesh.triangles.size());
  sm.dropped_degenerate = mesh.dropped_degenerate;
  sm.dropped_nan = mesh.dropped_nan;
  sm.warnings = mesh.warnings;
  sm.lights = mesh.lights;
  mesh_cameras_.push_back(mesh.cameras);
  // Normals and UVs are stored per vertex where the mesh has them; a triangle's
  // indices point into whichever the mesh has (both arrays grow alike).
  const bool normals = !mesh.normals.empty(), uvs = !mesh.uvs.empty();
  const uint32_t base = static_cast<uint32_t>(scene_.normals.size());
  if (normals || uvs) {
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
      scene_.normals.push_back(normals ? mesh.normals[v] : vec3(0.0f));
      scene_.uvs.push_back(uvs ? mesh.uvs[v] : vec2(0.0f));
      file_tangents_.push_back(mesh.tangents.empty() ? vec4(0.0f) : mesh.tangents[v]);
    }
  }
  const uint32_t flags = (normals ? kTriangleHasNormals : 0u) | (uvs ? kTriangleHasUvs : 0u);
  // The scene's alpha for the mesh under its scene material (an instance's material
  // replaces it, as it replaces a file's).
  uint32_t override_alpha = 0u;
  if (alpha != nullptr && material_override >= 0) {
    override_alpha = static_cast<uint32_t>(scene_.alpha_tests.size()) + 1u;
    scene_.alpha_tests.push_back(*alpha);
  }
  scene_.triangles.reserve(total);
  scene_.triangle_shadings.reserve(total);
  scene_.triangle_materials.reserve(total);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& v = mesh.triangles[t];
    TriangleGeom g{};
    g.alpha = material_override >= 0 ? override_alpha : alpha_of[mesh.triangle_material[t]];
    for (int c = 0; c < 3; ++c) {
      const vec3& p = mesh.positions[v[c]];
      float* dst = c == 0 ? g.p0 : (c == 1 ? g.p1 : g.p2);
      dst[0] = p.x;
      dst[1] = p.y;
      dst[2] = p.z;
    }
    scene_.triangles.push_back(g);
    TriangleShading sh{};
    for (int c = 0; c < 3; ++c) sh.vertex[c] = flags ? base + v[c] : 0u;
    sh.flags = flags;
    scene_.triangle_shadings.push_back(sh);
    scene_.triangle_materials.push_back(material_override >= 0 ? static_cast<uint32_t>(material_override)
                                                              : material_of[mesh.triangle_material[t]]);
  }
  scene_.meshes.push_back(std::move(sm));
}

void SceneReader::read_instance(const json& j, const JsonPath& path) {
  object(j, path);
  check_keys(j, path, {"mesh", "material", "translate", "rotate", "scale", "matrix"});
  const std::string& mesh = string(required(j, path, "mesh"), path / "mesh");
  auto found = mesh_names_.find(mesh);
  if (found == mesh_names_.end()) fail_at(path / "mesh", "unknown mesh '" + mesh + "'");
  Placement p;
  p.mesh = static_cast<int32_t>(found->second.first);
  p.material = j.contains("material") ? material_named(j["material"], path / "material") : -1;

  glm::dmat4 m(1.0);
  if (j.contains("matrix")) {
    for (const char* other : {"translate", "rotate", "scale"}) {
      if (j.contains(other)) fail_at(path / other, "cannot be given with 'matrix'");
    }
    const JsonPath at = path / "matrix";
    const json& rows = array(j["matrix"], at);
    if (rows.size() != 16) fail_at(at, "must be an array of 16 numbers (got " + std::to_string(rows.size()) + ")");
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) m[c][r] = number(rows[4 * r + c], at / (4 * r + c));
    }
    if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0) {
      fail_at(at, "the last row must be 0 0 0 1 (an affine transform)");
    }
  } else {
    if (j.contains("translate")) m = glm::translate(m, glm::dvec3(triple(j["translate"], path / "translate")));
    if (j.contains("rotate")) {
      const vec3 degrees = triple(j["rotate"], path / "rotate");
      m = glm::rotate(m, glm::radians(double(degrees.z)), glm::dvec3(0, 0, 1));
      m = glm::rotate(m, glm::radians(double(degrees.y)), glm::dvec3(0, 1, 0));
      m = glm::rotate(m, glm::radians(double(degrees.x)), glm::dvec3(1, 0, 0));
    }
    if (j.contains("scale")) {
      const JsonPath at = path / "scale";
      glm::dvec3 s = j["scale"].is_number() ? glm::dvec3(number(j["scale"], at)) : glm::dvec3(triple(j["scale"], at));
      if (s.x == 0.0 || s.y == 0.0 || s.z == 0.0) fail_at(at, "must not be zero");
      m = glm::scale(m, s);
    }
  }
  const double det = glm::determinant(glm::dmat3(m));
  if (!std::isfinite(det) || std::fabs(det) < 1e-18) {
    fail_at(path, "the transform is singular (determinant " + std::to_string(det) + ")");
  }
  p.identity = m == glm::dmat4(1.0);
  p.world_from_object = affine_of(m);
  p.object_from_world = affine_of(glm::inverse(m));
  scene_.placements.push_back(p);
}

int32_t SceneReader::material_named(const json& j, const JsonPath& path) const {
  const std::string& m = string(j, path);
  auto found = material_names_.find(m);
  if (found == material_names_.end()) fail_at(path, "unknown material '" + m + "'");
  return static_cast<int32_t>(found->second.first);
}

}  // namespace wt

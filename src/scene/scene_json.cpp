// Scene files (docs/scene-format.md) to a validated Scene. Every error names the
// file and the JSON path of the offending field, so that one message is enough to
// find and fix it.
#include <stb/stb_image.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <thread>
#include <utility>

#include "render/settings.hpp"
#include "scene/json_reader.hpp"
#include "scene/scene.hpp"
#include "wavetrace/film.hpp"

namespace wt {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Reads one scene document; holds what later sections look up in earlier ones.
class SceneReader : JsonReader {
 public:
  SceneReader(const std::string& source, Scene& scene) : JsonReader(source), scene_(scene) {
    base_dir_ = std::filesystem::path(source).parent_path();
  }

  void read(const json& root) {
    const JsonPath top;
    check_keys(root, top, {"camera", "sky", "render", "textures", "materials", "spheres"});
    read_camera(required(root, top, "camera"), top / "camera");
    if (root.contains("sky")) read_sky(root["sky"], top / "sky");
    if (root.contains("render")) read_render(root["render"], top / "render");
    if (root.contains("textures")) {
      const JsonPath path = top / "textures";
      const json& list = array(root["textures"], path);
      for (size_t i = 0; i < list.size(); ++i) read_texture(list[i], path / i);
    }
    const JsonPath materials_path = top / "materials";
    const json& materials = array(required(root, top, "materials"), materials_path);
    for (size_t i = 0; i < materials.size(); ++i) read_material(materials[i], materials_path / i);
    const JsonPath spheres_path = top / "spheres";
    const json& spheres = array(required(root, top, "spheres"), spheres_path);
    if (spheres.empty()) fail_at(spheres_path, "must contain at least one sphere");
    scene_.spheres.reserve(spheres.size());
    scene_.sphere_material.reserve(spheres.size());
    for (size_t i = 0; i < spheres.size(); ++i) read_sphere(spheres[i], spheres_path / i);
  }

  double texture_seconds() const { return texture_seconds_; }

 private:
  const std::string& name(const json& obj, const JsonPath& path) const {
    const std::string& n = string(required(obj, path, "name"), path / "name");
    if (n.empty()) fail_at(path / "name", "must not be empty");
    return n;
  }

  vec3 triple(const json& j, const JsonPath& path) const {
    if (!j.is_array() || j.size() != 3) {
      fail_at(path, "must be an array of 3 numbers (got " +
                        (j.is_array() ? std::to_string(j.size()) + " elements" : std::string(j.type_name())) + ")");
    }
    return vec3(number(j[0], path / 0), number(j[1], path / 1), number(j[2], path / 2));
  }

  vec3 colour(const json& j, const JsonPath& path) const {
    vec3 c = triple(j, path);
    for (size_t i = 0; i < 3; ++i) unit_interval(j[i], path / i);
    return c;
  }

  vec3 radiance(const json& j, const JsonPath& path) const {
    vec3 c = triple(j, path);
    for (size_t i = 0; i < 3; ++i) non_negative(j[i], path / i);
    return c;
  }

  // Reads obj["type"] and returns its index in `types`.
  size_t type_of(const json& obj, const JsonPath& path, const std::string& what,
                 const std::vector<std::string>& types) const {
    object(obj, path);
    std::string t = string(required(obj, path, "type"), path / "type");
    for (size_t i = 0; i < types.size(); ++i) {
      if (types[i] == t) return i;
    }
    fail_at(path / "type", "unknown " + what + " type '" + t + "' (expected " + listed(types) + ")");
  }

  void read_camera(const json& j, const JsonPath& path) {
    check_keys(j, path, {"look_from", "look_at", "up", "vfov", "aperture", "focus_distance"});
    CameraSpec& c = scene_.camera;
    c.look_from = triple(required(j, path, "look_from"), path / "look_from");
    c.look_at = triple(required(j, path, "look_at"), path / "look_at");
    if (j.contains("up")) c.up = triple(j["up"], path / "up");
    if (j.contains("vfov")) {
      c.vfov_degrees = number(j["vfov"], path / "vfov");
      if (!(c.vfov_degrees > 0.0f && c.vfov_degrees < 180.0f)) {
        fail_at(path / "vfov", "must be in (0, 180) degrees (got " + j["vfov"].dump() + ")");
      }
    }
    if (j.contains("aperture")) c.aperture = non_negative(j["aperture"], path / "aperture");
    if (j.contains("focus_distance")) c.focus_distance = positive(j["focus_distance"], path / "focus_distance");

    // The camera frame is built from cross(up, view); it is undefined when they are
    // parallel and numerically meaningless when nearly so.
    glm::dvec3 view = glm::dvec3(c.look_at) - glm::dvec3(c.look_from);
    glm::dvec3 up(c.up);
    if (glm::length(view) == 0.0) fail_at(path / "look_at", "must differ from look_from");
    if (glm::length(up) == 0.0) fail_at(path / "up", "must not be the zero vector");
    if (glm::length(glm::cross(up, view)) <= 1e-4 * glm::length(up) * glm::length(view)) {
      fail_at(path / "up", std::string("must not be parallel to the view direction look_at - look_from") +
                                     (j.contains("up") ? "" : " (up defaults to [0, 1, 0])"));
    }
  }

  void read_sky(const json& j, const JsonPath& path) {
    size_t type = type_of(j, path, "sky", {"gradient", "uniform"});
    if (type == 0) {
      check_keys(j, path, {"type", "horizon", "zenith"}, "gradient");
      scene_.sky.kind = SkyKind::Gradient;
      if (j.contains("horizon")) scene_.sky.horizon = radiance(j["horizon"], path / "horizon");
      if (j.contains("zenith")) scene_.sky.zenith = radiance(j["zenith"], path / "zenith");
    } else {
      check_keys(j, path, {"type", "radiance"}, "uniform");
      scene_.sky.kind = SkyKind::Uniform;
      scene_.sky.horizon = radiance(required(j, path, "radiance"), path / "radiance");
      scene_.sky.zenith = scene_.sky.horizon;
    }
  }

  void read_render(const json& j, const JsonPath& path) {
    std::vector<std::string> keys;
    for (SettingId id : render_settings()) keys.push_back(setting(id).key);
    check_keys(j, path, keys);
    for (SettingId id : render_settings()) {
      const Setting& s = setting(id);
      auto it = j.find(s.key);
      if (it != j.end()) set_param(scene_.render, id, integer(*it, path / s.key, s.lo, s.hi));
    }
  }

  void read_texture(const json& j, const JsonPath& path) {
    object(j, path);
    remember(texture_names_, name(j, path), scene_.textures.size(), "texture", path);
    size_t type = type_of(j, path, "texture", {"checker", "noise", "image"});
    Texture t{};
    t.image = -1;
    if (type == 0) {
      check_keys(j, path, {"name", "type", "size", "even", "odd"}, "checker");
      t.kind = TextureKind::Checker;
      t.scale = positive(required(j, path, "size"), path / "size");
      t.a = colour(required(j, path, "even"), path / "even");
      t.b = colour(required(j, path, "odd"), path / "odd");
    } else if (type == 1) {
      check_keys(j, path, {"name", "type", "scale", "octaves", "high", "low"}, "noise");
      t.kind = TextureKind::Noise;
      t.scale = positive(required(j, path, "scale"), path / "scale");
      t.octaves = j.contains("octaves") ? static_cast<int32_t>(integer(j["octaves"], path / "octaves", 1, 16)) : 7;
      t.a = colour(required(j, path, "high"), path / "high");
      t.b = colour(required(j, path, "low"), path / "low");
    } else {
      check_keys(j, path, {"name", "type", "file", "colorspace"}, "image");
      t.kind = TextureKind::Image;
      bool srgb = true;
      if (j.contains("colorspace")) {
        std::string cs = string(j["colorspace"], path / "colorspace");
        if (cs != "srgb" && cs != "linear") {
          fail_at(path / "colorspace", "unknown colorspace '" + cs + "' (expected srgb, linear)");
        }
        srgb = cs == "srgb";
      }
      t.image = image(string(required(j, path, "file"), path / "file"), srgb, path / "file");
    }
    scene_.textures.push_back(t);
  }

  // Textures that name the same file in the same colorspace share one image.
  int32_t image(const std::string& file, bool srgb, const JsonPath& path) {
    std::string resolved = (base_dir_ / file).lexically_normal().string();
    auto known = images_.find({resolved, srgb});
    if (known != images_.end()) return known->second;

    const auto start = Clock::now();
    // Read in the file's own channels and widened to RGBA here: stb 2.27 (Debian
    // bookworm) reads past its buffer when it converts a 16-bit PNM to 4 channels.
    int w = 0, h = 0, channels = 0;
    stbi_uc* data = stbi_load(resolved.c_str(), &w, &h, &channels, 0);
    if (!data) fail_at(path, "cannot read image '" + resolved + "' (" + stbi_failure_reason() + ")");
    Image im;
    im.path = resolved;
    im.width = w;
    im.height = h;
    im.texels.resize(static_cast<size_t>(w) * h * 4);
    for (size_t i = 0; i < im.texels.size(); ++i) {
      const stbi_uc* texel = data + i / 4 * channels;
      bool alpha = i % 4 == 3;
      // grey: g g g 1; grey + alpha: g g g a; RGB: r g b 1; RGBA.
      float v = alpha ? (channels % 2 == 0 ? texel[channels - 1] / 255.0f : 1.0f)
                      : texel[channels >= 3 ? i % 4 : 0] / 255.0f;
      im.texels[i] = srgb && !alpha ? decode_srgb(v) : v;
    }
    stbi_image_free(data);
    texture_seconds_ += seconds_since(start);

    int32_t index = static_cast<int32_t>(scene_.images.size());
    scene_.images.push_back(std::move(im));
    images_.emplace(std::make_pair(resolved, srgb), index);
    return index;
  }

  void read_material(const json& j, const JsonPath& path) {
    static const std::vector<std::string> kTypes = {"lambertian", "metal", "dielectric", "coated", "emissive"};
    static const std::vector<std::vector<std::string>> kKeys = {
        {"name", "type", "albedo", "texture"},
        {"name", "type", "albedo", "fuzz", "texture"},
        {"name", "type", "ior", "albedo"},
        {"name", "type", "albedo", "ior", "texture"},
        {"name", "type", "emission"},
    };
    object(j, path);
    std::string n = name(j, path);
    remember(material_names_, n, scene_.materials.size(), "material", path);
    size_t type = type_of(j, path, "material", kTypes);
    check_keys(j, path, kKeys[type], kTypes[type]);

    Material m{};
    m.kind = static_cast<MaterialKind>(type);
    m.texture = -1;
    m.ior = 1.0f;
    m.albedo = j.contains("albedo") ? colour(j["albedo"], path / "albedo") : vec3(1.0f);
    if (j.contains("fuzz")) m.fuzz = unit_interval(j["fuzz"], path / "fuzz");
    if (m.kind == MaterialKind::Dielectric || m.kind == MaterialKind::Coated) {
      m.ior = positive(required(j, path, "ior"), path / "ior");
    }
    if (m.kind == MaterialKind::Emissive) {
      m.albedo = vec3(0.0f);
      m.emission = radiance(required(j, path, "emission"), path / "emission");
    }
    int texture_kind = -1;
    if (j.contains("texture")) {
      std::string t = string(j["texture"], path / "texture");
      auto found = texture_names_.find(t);
      if (found == texture_names_.end()) fail_at(path / "texture", "unknown texture '" + t + "'");
      m.texture = static_cast<int32_t>(found->second.first);
      texture_kind = static_cast<int>(scene_.textures[m.texture].kind);
    }
    m.sort_key = material_sort_key(m.kind, texture_kind);
    scene_.materials.push_back(m);
    scene_.material_names.push_back(n);
  }

  void read_sphere(const json& j, const JsonPath& path) {
    check_keys(j, path, {"center", "radius", "material"});
    vec3 c = triple(required(j, path, "center"), path / "center");
    float r = positive(required(j, path, "radius"), path / "radius");
    const std::string& m = string(required(j, path, "material"), path / "material");
    auto found = material_names_.find(m);
    if (found == material_names_.end()) fail_at(path / "material", "unknown material '" + m + "'");
    scene_.spheres.push_back(SphereGeom{c.x, c.y, c.z, r});
    scene_.sphere_material.push_back(static_cast<uint32_t>(found->second.first));
  }

  // Name -> (index, JSON path of the definition).
  using Names = std::map<std::string, std::pair<size_t, std::string>>;

  void remember(Names& names, const std::string& n, size_t index, const char* what, const JsonPath& path) const {
    auto [it, inserted] = names.emplace(n, std::make_pair(index, path.str()));
    if (!inserted) {
      fail_at(path / "name", std::string("duplicate ") + what + " name '" + n + "' (first defined at " +
                                       it->second.second + ")");
    }
  }

  Scene& scene_;
  std::filesystem::path base_dir_;
  Names texture_names_;
  Names material_names_;
  std::map<std::pair<std::string, bool>, int32_t> images_;
  double texture_seconds_ = 0;
};

}  // namespace

namespace {

// Validates the parsed document into a Scene and builds its BVH, timing each phase.
// Validates `root` into a scene and builds its BVH. The document is no longer needed
// once read: a big one (a million spheres is ten million small allocations) is
// freed on a thread of its own while the BVH is built.
Scene prepare(json root, const std::string& source, double parse_seconds) {
  Scene scene;
  scene.source = source;
  scene.load_times.parse = parse_seconds;
  auto start = Clock::now();
  SceneReader reader(source, scene);
  reader.read(root);
  scene.load_times.texture_load = reader.texture_seconds();
  scene.load_times.validate = seconds_since(start) - scene.load_times.texture_load;
  std::thread release([document = std::move(root)]() mutable { json().swap(document); });
  start = Clock::now();
  try {
    build_bvh(scene);
  } catch (...) {
    release.join();
    throw;
  }
  scene.load_times.bvh_build = seconds_since(start);
  release.join();
  return scene;
}

}  // namespace

Scene parse_scene(const std::string& json_text, const std::string& source) {
  const auto start = Clock::now();
  json root = parse_json(json_text, source);
  return prepare(std::move(root), source, seconds_since(start));
}

Scene load_scene(const std::string& path) {
  const auto start = Clock::now();
  json root = read_json_file(path, "scene file");
  return prepare(std::move(root), path, seconds_since(start));
}

// Compact drops the misses before the sort, so only the materials' keys count.
int Scene::sort_key_bits() const {
  uint32_t largest = 0;
  for (const Material& m : materials) largest = std::max(largest, m.sort_key);
  int bits = 0;
  while ((largest >> bits) != 0) ++bits;
  return std::max(bits, 1);
}

SceneView host_view(const Scene& scene, int width, int height, std::vector<ImageView>& image_views) {
  image_views.clear();
  for (const Image& im : scene.images) image_views.push_back(ImageView{0, im.texels.data(), im.width, im.height});
  SceneView v{};
  v.spheres = scene.spheres.data();
  v.sphere_material = scene.sphere_material.data();
  v.nodes = scene.nodes.data();
  v.materials = scene.materials.data();
  v.textures = scene.textures.data();
  v.images = image_views.data();
  v.sphere_count = static_cast<int32_t>(scene.spheres.size());
  v.node_total = static_cast<int32_t>(scene.nodes.size());
  v.sky = scene.sky;
  v.camera = Camera::make(scene.camera, width, height);
  return v;
}

}  // namespace wt

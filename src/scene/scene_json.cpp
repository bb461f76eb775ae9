// Scene files (docs/scene-format.md) to a validated Scene. Every error names the
// file and the JSON path of the offending field, so that one message is enough to
// find and fix it.
#include <stb/stb_image.h>

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <utility>

#include "scene/scene.hpp"
#include "wavetrace/film.hpp"

namespace wt {

namespace {

using json = nlohmann::json;

std::string pointer_token(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
  return out;
}

std::string child(const std::string& path, const std::string& key) { return path + "/" + pointer_token(key); }
std::string child(const std::string& path, size_t index) { return path + "/" + std::to_string(index); }

std::string listed(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

[[noreturn]] void fail(const std::string& source, const std::string& path, const std::string& what) {
  throw SceneError(source + ": " + (path.empty() ? "/" : path) + ": " + what);
}

// nlohmann keeps the last of repeated keys without a word; a repeated key in a
// scene file is a mistake (two values, one silently lost), so the parse stops there.
class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(std::string source) : source_(std::move(source)) {}

  bool operator()(int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
        frames_.push_back(Frame{false, 0, {}, {}});
        break;
      case json::parse_event_t::array_start:
        frames_.push_back(Frame{true, 0, {}, {}});
        break;
      case json::parse_event_t::key: {
        Frame& f = frames_.back();
        f.key = parsed.get<std::string>();
        if (!f.keys.insert(f.key).second) fail(source_, path(), "duplicate key");
        break;
      }
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        frames_.pop_back();
        element_done();
        break;
      case json::parse_event_t::value:
        element_done();
        break;
    }
    return true;
  }

 private:
  struct Frame {
    bool array;
    size_t index;
    std::string key;
    std::set<std::string> keys;
  };

  void element_done() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }

  std::string path() const {
    std::string p;
    for (const Frame& f : frames_) p = f.array ? child(p, f.index) : child(p, f.key);
    return p;
  }

  std::string source_;
  std::vector<Frame> frames_;
};

json parse_json(const std::string& text, const std::string& source) {
  try {
    return json::parse(text, DuplicateKeyCheck(source));
  } catch (const json::exception& e) {
    // Drop nlohmann's "[json.exception.parse_error.101] " tag; the rest says what and
    // where (line and column) in words.
    std::string what = e.what();
    size_t tag_end = what.find("] ");
    if (what.rfind("[json.exception.", 0) == 0 && tag_end != std::string::npos) what = what.substr(tag_end + 2);
    throw SceneError(source + ": malformed JSON: " + what);
  }
}

// Reads one scene document; holds what later sections look up in earlier ones.
class SceneReader {
 public:
  SceneReader(std::string source, Scene& scene) : source_(std::move(source)), scene_(scene) {
    base_dir_ = std::filesystem::path(source_).parent_path();
  }

  void read(const json& root) {
    check_keys(root, "", {"camera", "sky", "render", "textures", "materials", "spheres"});
    read_camera(required(root, "", "camera"), "/camera");
    if (root.contains("sky")) read_sky(root["sky"], "/sky");
    if (root.contains("render")) read_render(root["render"], "/render");
    if (root.contains("textures")) {
      const json& list = array(root["textures"], "/textures");
      for (size_t i = 0; i < list.size(); ++i) read_texture(list[i], child("/textures", i));
    }
    const json& materials = array(required(root, "", "materials"), "/materials");
    for (size_t i = 0; i < materials.size(); ++i) read_material(materials[i], child("/materials", i));
    const json& spheres = array(required(root, "", "spheres"), "/spheres");
    if (spheres.empty()) fail_at("/spheres", "must contain at least one sphere");
    for (size_t i = 0; i < spheres.size(); ++i) read_sphere(spheres[i], child("/spheres", i));
  }

 private:
  [[noreturn]] void fail_at(const std::string& path, const std::string& what) const { fail(source_, path, what); }

  void object(const json& j, const std::string& path) const {
    if (!j.is_object()) fail_at(path, std::string("must be an object (got ") + j.type_name() + ")");
  }

  // `type`: the object's type where the allowed keys depend on it.
  void check_keys(const json& obj, const std::string& path, const std::vector<std::string>& allowed,
                  const std::string& type = "") const {
    object(obj, path);
    for (const auto& item : obj.items()) {
      if (std::find(allowed.begin(), allowed.end(), item.key()) == allowed.end()) {
        fail_at(child(path, item.key()), "unknown key" + (type.empty() ? "" : " for type '" + type + "'") +
                                             " (expected " + listed(allowed) + ")");
      }
    }
  }

  const json& required(const json& obj, const std::string& path, const std::string& key) const {
    if (!obj.contains(key)) fail_at(child(path, key), "required key is missing");
    return obj[key];
  }

  const json& array(const json& j, const std::string& path) const {
    if (!j.is_array()) fail_at(path, std::string("must be an array (got ") + j.type_name() + ")");
    return j;
  }

  std::string string(const json& j, const std::string& path) const {
    if (!j.is_string()) fail_at(path, std::string("must be a string (got ") + j.type_name() + ")");
    return j.get<std::string>();
  }

  std::string name(const json& obj, const std::string& path) const {
    std::string n = string(required(obj, path, "name"), child(path, "name"));
    if (n.empty()) fail_at(child(path, "name"), "must not be empty");
    return n;
  }

  // Every number ends up in a float; one that a float cannot hold is an error here
  // rather than an infinity in the renderer.
  float number(const json& j, const std::string& path) const {
    if (!j.is_number()) fail_at(path, std::string("must be a number (got ") + j.type_name() + ")");
    double v = j.get<double>();
    if (!(std::fabs(v) <= FLT_MAX)) fail_at(path, "must be a finite number within float range (got " + j.dump() + ")");
    return static_cast<float>(v);
  }

  float positive(const json& j, const std::string& path) const {
    float v = number(j, path);
    if (!(v > 0.0f)) fail_at(path, "must be > 0 (got " + j.dump() + ")");
    return v;
  }

  float non_negative(const json& j, const std::string& path) const {
    float v = number(j, path);
    if (!(v >= 0.0f)) fail_at(path, "must be >= 0 (got " + j.dump() + ")");
    return v;
  }

  float unit_interval(const json& j, const std::string& path) const {
    float v = number(j, path);
    if (!(v >= 0.0f && v <= 1.0f)) fail_at(path, "must be in [0, 1] (got " + j.dump() + ")");
    return v;
  }

  int64_t integer(const json& j, const std::string& path, int64_t lo, int64_t hi) const {
    std::string range = "must be an integer in " + std::to_string(lo) + ".." + std::to_string(hi);
    if (!j.is_number()) fail_at(path, range + " (got " + j.type_name() + ")");
    bool representable = true;
    int64_t v = 0;
    if (j.is_number_unsigned()) {
      representable = j.get<uint64_t>() <= static_cast<uint64_t>(INT64_MAX);
      v = representable ? j.get<int64_t>() : 0;
    } else if (j.is_number_integer()) {
      v = j.get<int64_t>();
    } else {
      // 1e3 and 2.0 are integers written as floats; accept them.
      double d = j.get<double>();
      representable = std::floor(d) == d && d >= static_cast<double>(lo) && d <= static_cast<double>(hi);
      v = representable ? static_cast<int64_t>(d) : 0;
    }
    if (!representable || v < lo || v > hi) fail_at(path, range + " (got " + j.dump() + ")");
    return v;
  }

  vec3 triple(const json& j, const std::string& path) const {
    if (!j.is_array() || j.size() != 3) {
      fail_at(path, "must be an array of 3 numbers (got " +
                        (j.is_array() ? std::to_string(j.size()) + " elements" : std::string(j.type_name())) + ")");
    }
    return vec3(number(j[0], child(path, 0)), number(j[1], child(path, 1)), number(j[2], child(path, 2)));
  }

  vec3 colour(const json& j, const std::string& path) const {
    vec3 c = triple(j, path);
    for (size_t i = 0; i < 3; ++i) unit_interval(j[i], child(path, i));
    return c;
  }

  vec3 radiance(const json& j, const std::string& path) const {
    vec3 c = triple(j, path);
    for (size_t i = 0; i < 3; ++i) non_negative(j[i], child(path, i));
    return c;
  }

  // Reads obj["type"] and returns its index in `types`.
  size_t type_of(const json& obj, const std::string& path, const std::string& what,
                 const std::vector<std::string>& types) const {
    object(obj, path);
    std::string t = string(required(obj, path, "type"), child(path, "type"));
    for (size_t i = 0; i < types.size(); ++i) {
      if (types[i] == t) return i;
    }
    fail_at(child(path, "type"), "unknown " + what + " type '" + t + "' (expected " + listed(types) + ")");
  }

  void read_camera(const json& j, const std::string& path) {
    check_keys(j, path, {"look_from", "look_at", "up", "vfov", "aperture", "focus_distance"});
    CameraSpec& c = scene_.camera;
    c.look_from = triple(required(j, path, "look_from"), child(path, "look_from"));
    c.look_at = triple(required(j, path, "look_at"), child(path, "look_at"));
    if (j.contains("up")) c.up = triple(j["up"], child(path, "up"));
    if (j.contains("vfov")) {
      c.vfov_degrees = number(j["vfov"], child(path, "vfov"));
      if (!(c.vfov_degrees > 0.0f && c.vfov_degrees < 180.0f)) {
        fail_at(child(path, "vfov"), "must be in (0, 180) degrees (got " + j["vfov"].dump() + ")");
      }
    }
    if (j.contains("aperture")) c.aperture = non_negative(j["aperture"], child(path, "aperture"));
    if (j.contains("focus_distance")) c.focus_distance = positive(j["focus_distance"], child(path, "focus_distance"));

    // The camera frame is built from cross(up, view); it is undefined when they are
    // parallel and numerically meaningless when nearly so.
    glm::dvec3 view = glm::dvec3(c.look_at) - glm::dvec3(c.look_from);
    glm::dvec3 up(c.up);
    if (glm::length(view) == 0.0) fail_at(child(path, "look_at"), "must differ from look_from");
    if (glm::length(up) == 0.0) fail_at(child(path, "up"), "must not be the zero vector");
    if (glm::length(glm::cross(up, view)) <= 1e-4 * glm::length(up) * glm::length(view)) {
      fail_at(child(path, "up"), std::string("must not be parallel to the view direction look_at - look_from") +
                                     (j.contains("up") ? "" : " (up defaults to [0, 1, 0])"));
    }
  }

  void read_sky(const json& j, const std::string& path) {
    size_t type = type_of(j, path, "sky", {"gradient", "uniform"});
    if (type == 0) {
      check_keys(j, path, {"type", "horizon", "zenith"}, "gradient");
      scene_.sky.kind = SkyKind::Gradient;
      if (j.contains("horizon")) scene_.sky.horizon = radiance(j["horizon"], child(path, "horizon"));
      if (j.contains("zenith")) scene_.sky.zenith = radiance(j["zenith"], child(path, "zenith"));
    } else {
      check_keys(j, path, {"type", "radiance"}, "uniform");
      scene_.sky.kind = SkyKind::Uniform;
      scene_.sky.horizon = radiance(required(j, path, "radiance"), child(path, "radiance"));
      scene_.sky.zenith = scene_.sky.horizon;
    }
  }

  void read_render(const json& j, const std::string& path) {
    check_keys(j, path, {"width", "height", "spp", "depth", "roulette_depth", "seed"});
    RenderDefaults& r = scene_.render;
    auto field = [&](const char* key, int64_t lo, int64_t hi, int64_t fallback) {
      return j.contains(key) ? integer(j[key], child(path, key), lo, hi) : fallback;
    };
    r.width = static_cast<int>(field("width", 1, kMaxImageSide, r.width));
    r.height = static_cast<int>(field("height", 1, kMaxImageSide, r.height));
    r.spp = static_cast<int>(field("spp", 1, kMaxSpp, r.spp));
    r.depth = static_cast<int>(field("depth", 1, kMaxPathDepth, r.depth));
    r.roulette_depth = static_cast<int>(field("roulette_depth", 0, INT32_MAX, r.roulette_depth));
    r.seed = static_cast<uint32_t>(field("seed", 0, UINT32_MAX, r.seed));
  }

  void read_texture(const json& j, const std::string& path) {
    object(j, path);
    remember(texture_names_, name(j, path), scene_.textures.size(), "texture", path);
    size_t type = type_of(j, path, "texture", {"checker", "noise", "image"});
    Texture t{};
    t.image = -1;
    if (type == 0) {
      check_keys(j, path, {"name", "type", "size", "even", "odd"}, "checker");
      t.kind = TextureKind::Checker;
      t.scale = positive(required(j, path, "size"), child(path, "size"));
      t.a = colour(required(j, path, "even"), child(path, "even"));
      t.b = colour(required(j, path, "odd"), child(path, "odd"));
    } else if (type == 1) {
      check_keys(j, path, {"name", "type", "scale", "octaves", "high", "low"}, "noise");
      t.kind = TextureKind::Noise;
      t.scale = positive(required(j, path, "scale"), child(path, "scale"));
      t.octaves = j.contains("octaves") ? static_cast<int32_t>(integer(j["octaves"], child(path, "octaves"), 1, 16)) : 7;
      t.a = colour(required(j, path, "high"), child(path, "high"));
      t.b = colour(required(j, path, "low"), child(path, "low"));
    } else {
      check_keys(j, path, {"name", "type", "file", "colorspace"}, "image");
      t.kind = TextureKind::Image;
      bool srgb = true;
      if (j.contains("colorspace")) {
        std::string cs = string(j["colorspace"], child(path, "colorspace"));
        if (cs != "srgb" && cs != "linear") {
          fail_at(child(path, "colorspace"), "unknown colorspace '" + cs + "' (expected srgb, linear)");
        }
        srgb = cs == "srgb";
      }
      t.image = image(string(required(j, path, "file"), child(path, "file")), srgb, child(path, "file"));
    }
    scene_.textures.push_back(t);
  }

  // Textures that name the same file in the same colorspace share one image.
  int32_t image(const std::string& file, bool srgb, const std::string& path) {
    std::string resolved = (base_dir_ / file).lexically_normal().string();
    auto known = images_.find({resolved, srgb});
    if (known != images_.end()) return known->second;

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

    int32_t index = static_cast<int32_t>(scene_.images.size());
    scene_.images.push_back(std::move(im));
    images_.emplace(std::make_pair(resolved, srgb), index);
    return index;
  }

  void read_material(const json& j, const std::string& path) {
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
    m.albedo = j.contains("albedo") ? colour(j["albedo"], child(path, "albedo")) : vec3(1.0f);
    if (j.contains("fuzz")) m.fuzz = unit_interval(j["fuzz"], child(path, "fuzz"));
    if (m.kind == MaterialKind::Dielectric || m.kind == MaterialKind::Coated) {
      m.ior = positive(required(j, path, "ior"), child(path, "ior"));
    }
    if (m.kind == MaterialKind::Emissive) {
      m.albedo = vec3(0.0f);
      m.emission = radiance(required(j, path, "emission"), child(path, "emission"));
    }
    int texture_kind = -1;
    if (j.contains("texture")) {
      std::string t = string(j["texture"], child(path, "texture"));
      auto found = texture_names_.find(t);
      if (found == texture_names_.end()) fail_at(child(path, "texture"), "unknown texture '" + t + "'");
      m.texture = static_cast<int32_t>(found->second.first);
      texture_kind = static_cast<int>(scene_.textures[m.texture].kind);
    }
    m.sort_key = material_sort_key(m.kind, texture_kind);
    scene_.materials.push_back(m);
    scene_.material_names.push_back(n);
  }

  void read_sphere(const json& j, const std::string& path) {
    check_keys(j, path, {"center", "radius", "material"});
    vec3 c = triple(required(j, path, "center"), child(path, "center"));
    float r = positive(required(j, path, "radius"), child(path, "radius"));
    std::string m = string(required(j, path, "material"), child(path, "material"));
    auto found = material_names_.find(m);
    if (found == material_names_.end()) fail_at(child(path, "material"), "unknown material '" + m + "'");
    scene_.spheres.push_back(SphereGeom{c.x, c.y, c.z, r});
    scene_.sphere_material.push_back(static_cast<uint32_t>(found->second.first));
  }

  // Name -> (index, JSON path of the definition).
  using Names = std::map<std::string, std::pair<size_t, std::string>>;

  void remember(Names& names, const std::string& n, size_t index, const char* what, const std::string& path) const {
    auto [it, inserted] = names.emplace(n, std::make_pair(index, path));
    if (!inserted) {
      fail_at(child(path, "name"), std::string("duplicate ") + what + " name '" + n + "' (first defined at " +
                                       it->second.second + ")");
    }
  }

  std::string source_;
  Scene& scene_;
  std::filesystem::path base_dir_;
  Names texture_names_;
  Names material_names_;
  std::map<std::pair<std::string, bool>, int32_t> images_;
};

}  // namespace

Scene parse_scene(const std::string& json_text, const std::string& source) {
  json root = parse_json(json_text, source);
  Scene scene;
  scene.source = source;
  SceneReader(source, scene).read(root);
  build_bvh(scene);
  return scene;
}

Scene load_scene(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw SceneError(path + ": cannot open scene file (" + std::strerror(errno) + ")");
  std::string text;
  char buf[1 << 16];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
  bool failed = std::ferror(f) != 0;
  int err = errno;
  std::fclose(f);
  if (failed) throw SceneError(path + ": cannot read scene file (" + std::strerror(err) + ")");
  return parse_scene(text, path);
}

// Compact drops the misses before the sort, so only the materials' keys count.
int Scene::sort_key_bits() const {
  uint32_t largest = 0;
  for (const Material& m : materials) largest = std::max(largest, m.sort_key);
  int bits = 0;
  while ((largest >> bits) != 0) ++bits;
  return std::max(bits, 1);
}

SceneView host_view(const Scene& scene, std::vector<ImageView>& image_views) {
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
  v.camera = Camera::make(scene.camera, scene.render.width, scene.render.height);
  return v;
}

}  // namespace wt

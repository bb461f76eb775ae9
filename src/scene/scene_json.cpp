// Scene files (docs/scene-format.md) to a validated Scene. Every error names the
// file and the JSON path of the offending field, so that one message is enough to
// find and fix it.
#include <algorithm>
#include <cmath>
#include <thread>
#include <utility>

#include "errors/errors.hpp"
#include "scene/image_mips.hpp"
#include "scene/mesh_tangents.hpp"
#include "scene/mitsuba_scene.hpp"
#include "scene/scene_file.hpp"
#include "scene/scene_reader.hpp"

namespace wt {

void SceneReader::read(const json& root) {
  const JsonPath top;
  check_keys(root, top,
             {"camera", "sky", "render", "textures", "materials", "spheres", "meshes", "instances", "lights", "warnings"});
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
  if (root.contains("spheres")) {
    const JsonPath path = top / "spheres";
    const json& spheres = array(root["spheres"], path);
    scene_.spheres.reserve(spheres.size());
    scene_.sphere_materials.reserve(spheres.size());
    for (size_t i = 0; i < spheres.size(); ++i) read_sphere(spheres[i], path / i);
    if (!spheres.empty()) scene_.placements.push_back(Placement{kSpheres, kIdentityTransform, kIdentityTransform, true, -1});
  }
  if (root.contains("meshes")) read_meshes(array(root["meshes"], top / "meshes"), top / "meshes");
  if (root.contains("instances")) {
    const JsonPath path = top / "instances";
    const json& instances = array(root["instances"], path);
    for (size_t i = 0; i < instances.size(); ++i) read_instance(instances[i], path / i);
  }
  if (root.contains("lights")) {
    const JsonPath path = top / "lights";
    const json& lights = array(root["lights"], path);
    for (size_t i = 0; i < lights.size(); ++i) read_light(lights[i], path / i);
  }
  if (root.contains("warnings")) {
    const JsonPath path = top / "warnings";
    const json& warnings = array(root["warnings"], path);
    for (size_t i = 0; i < warnings.size(); ++i) scene_.warnings.push_back(string(warnings[i], path / i));
  }
  if (scene_.placements.empty()) {
    fail_at(top / "spheres", "the scene has nothing to render: it needs at least one sphere or one instance");
  }
  place_mesh_camera();
  // An image that nothing reads (a bump map's heights, whose derivatives are what
  // its texture reads) keeps one black texel, not its texels on the device.
  std::vector<bool> read(scene_.images.size(), false);
  for (const Texture& t : scene_.textures) {
    if (t.kind == TextureKind::Image) read[static_cast<size_t>(t.image)] = true;
  }
  if (scene_.sky.image >= 0) read[static_cast<size_t>(scene_.sky.image)] = true;
  for (size_t i = 0; i < read.size(); ++i) {
    if (read[i]) continue;
    Image& im = scene_.images[i];
    im.width = im.height = 1;
    im.texels.assign(4, 0.0f);
  }
  const auto start = Clock::now();
  build_texture_mips(scene_);
  texture_seconds_ += seconds_since(start);
  // Tangents per vertex only where a normal or bump map needs them.
  for (const MaterialParams& p : scene_.material_params) {
    if (p.normal_texture >= 0 || p.bump_texture >= 0) {
      build_tangents(scene_, file_tangents_);
      break;
    }
  }
}

const std::string& SceneReader::name(const json& obj, const JsonPath& path) const {
  const std::string& n = string(required(obj, path, "name"), path / "name");
  if (n.empty()) fail_at(path / "name", "must not be empty");
  return n;
}

vec3 SceneReader::triple(const json& j, const JsonPath& path) const {
  if (!j.is_array() || j.size() != 3) {
    fail_at(path, "must be an array of 3 numbers (got " +
                    (j.is_array() ? std::to_string(j.size()) + " elements" : std::string(j.type_name())) + ")");
  }
  return vec3(number(j[0], path / 0), number(j[1], path / 1), number(j[2], path / 2));
}

vec2 SceneReader::pair(const json& j, const JsonPath& path) const {
  if (!j.is_array() || j.size() != 2) {
    fail_at(path, "must be an array of 2 numbers (got " +
                    (j.is_array() ? std::to_string(j.size()) + " elements" : std::string(j.type_name())) + ")");
  }
  return vec2(number(j[0], path / 0), number(j[1], path / 1));
}

vec3 SceneReader::colour(const json& j, const JsonPath& path) const {
  vec3 c = triple(j, path);
  for (size_t i = 0; i < 3; ++i) unit_interval(j[i], path / i);
  return c;
}

vec3 SceneReader::radiance(const json& j, const JsonPath& path) const {
  vec3 c = triple(j, path);
  for (size_t i = 0; i < 3; ++i) {
    if (non_negative(j[i], path / i) > kMaxRadiance) {
      fail_at(path / i, "must be at most 1e9, the most radiance a scene may hold (got " + j[i].dump() + ")");
    }
  }
  return c;
}

vec3 SceneReader::position(const json& j, const JsonPath& path) const {
  vec3 c = triple(j, path);
  for (size_t i = 0; i < 3; ++i) {
    if (std::fabs(c[static_cast<int>(i)]) > kMaxCoordinate) {
      fail_at(path / i, "must be within +-1e15, the largest coordinate a scene may hold (got " + j[i].dump() + ")");
    }
  }
  return c;
}

size_t SceneReader::type_of(const json& obj, const JsonPath& path, const std::string& what,
                            const std::vector<std::string>& types) const {
  object(obj, path);
  std::string t = string(required(obj, path, "type"), path / "type");
  for (size_t i = 0; i < types.size(); ++i) {
    if (types[i] == t) return i;
  }
  fail_at(path / "type", "unknown " + what + " type '" + t + "' (expected " + listed(types) + ")");
}

void SceneReader::remember(Names& names, const std::string& n, size_t index, const char* what,
                           const JsonPath& path) const {
  auto [it, inserted] = names.emplace(n, std::make_pair(index, path.str()));
  if (!inserted) {
    fail_at(path / "name", std::string("duplicate ") + what + " name '" + n + "' (first defined at " +
                               it->second.second + ")");
  }
}

namespace {

// Validates `root` into a scene and builds its BVH, timing each phase. The document is no longer needed
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
  scene.load_times.mesh_load = reader.mesh_seconds();
  scene.load_times.validate = seconds_since(start) - scene.load_times.texture_load - scene.load_times.mesh_load;
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

Scene load_scene(const std::string& path, const std::map<std::string, std::string>& defines) {
  const auto start = Clock::now();
  if (mitsuba::is_mitsuba_scene(path)) {
    json root = mitsuba::read_mitsuba_scene(path, defines);
    return prepare(std::move(root), path, seconds_since(start));
  }
  if (!defines.empty()) {
    throw InputError(path + ": parameters (-D " + defines.begin()->first + "=...) apply to a Mitsuba scene (.xml) only");
  }
  json root = read_json_file(path, input::kScene);
  return prepare(std::move(root), path, seconds_since(start));
}

Scene load_scene(const std::string& path) { return load_scene(path, {}); }

Scene scene_from_document(json document, const std::string& source) { return prepare(std::move(document), source, 0.0); }

// Compact drops the misses before the sort, so only the materials' keys count.
int Scene::sort_key_bits() const {
  uint32_t largest = 0;
  for (const Material& m : materials) largest = std::max(largest, static_cast<uint32_t>(m.sort_key));
  int bits = 0;
  while ((largest >> bits) != 0) ++bits;
  return std::max(bits, 1);
}

SceneScalars scene_scalars(const Scene& scene, int width, int height, const PiecewiseConstant2D& environment) {
  SceneScalars v{};
  v.node_total = static_cast<int32_t>(scene.nodes.size());
  v.light_total = static_cast<int32_t>(scene.lights.size());
  v.punctual_total = static_cast<int32_t>(scene.punctual_lights.size());
  v.light_power = scene.light_power;
  v.sky_pick = scene.sky_pick;
  v.environment = environment;
  v.kinds = scene.kernel_kinds();
  v.sky = scene.sky;
  v.camera = Camera::make(scene.camera, width, height);
  return v;
}

SceneView host_view(const Scene& scene, int width, int height, std::vector<ImageView>& image_views) {
  image_views.clear();
  for (const Image& im : scene.images) {
    image_views.push_back(ImageView{0, im.texels.data(), im.width, im.height, 0, im.mip_texels.data(), im.levels});
  }
  SceneView v{};
  static_cast<SceneScalars&>(v) = scene_scalars(scene, width, height, scene.environment.view());
#define WT_HOST_POINTER(T, array, at, Return, Index) v.array = scene.array.data();
  WT_SCENE_ARRAYS(WT_HOST_POINTER)
#undef WT_HOST_POINTER
  v.images = image_views.data();
  return v;
}

}  // namespace wt

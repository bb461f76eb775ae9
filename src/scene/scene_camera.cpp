// Scene files: the camera, the sky and the render settings (docs/scene-format.md).
#include <algorithm>
#include <cmath>

#include "render/settings.hpp"
#include "scene/scene_reader.hpp"

namespace wt {

void SceneReader::read_camera(const json& j, const JsonPath& path) {
  CameraSpec& c = scene_.camera;
  object(j, path);
  if (j.contains("gltf")) {
    // A mesh file's camera: placed when the meshes are read (place_mesh_camera).
    check_keys(j, path, {"gltf", "index", "aperture", "focus_distance"});
    mesh_camera_.chosen = true;
    mesh_camera_.mesh = string(j["gltf"], path / "gltf");
    mesh_camera_.index = j.contains("index") ? static_cast<size_t>(integer(j["index"], path / "index", 0, 1 << 30)) : 0;
    if (j.contains("aperture")) c.aperture = non_negative(j["aperture"], path / "aperture");
    if (j.contains("focus_distance")) c.focus_distance = positive(j["focus_distance"], path / "focus_distance");
    if (c.aperture > 0.0f && !j.contains("focus_distance")) {
      fail_at(path / "aperture", "needs focus_distance with a mesh file's camera (it has no look_at)");
    }
    return;
  }
  check_keys(j, path, {"look_from", "look_at", "up", "vfov", "aperture", "focus_distance"});
  c.look_from = position(required(j, path, "look_from"), path / "look_from");
  c.look_at = position(required(j, path, "look_at"), path / "look_at");
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

void SceneReader::place_mesh_camera() {
  if (!mesh_camera_.chosen) return;
  const JsonPath root;  // (a path points at its parent: the root must outlive it)
  const JsonPath path = root / "camera";
  auto found = mesh_names_.find(mesh_camera_.mesh);
  if (found == mesh_names_.end()) fail_at(path / "gltf", "unknown mesh '" + mesh_camera_.mesh + "'");
  const size_t mesh = found->second.first;
  const std::vector<MeshCamera>& cameras = mesh_cameras_.at(mesh);
  const std::string which = "camera " + std::to_string(mesh_camera_.index) + " of mesh '" + mesh_camera_.mesh + "'";
  if (mesh_camera_.index >= cameras.size()) {
    fail_at(path / "index", which + " is out of range (its file has " + std::to_string(cameras.size()) + " cameras)");
  }
  const MeshCamera& mc = cameras[mesh_camera_.index];
  if (!mc.perspective) fail_at(path / "index", which + " is orthographic; wavetrace renders perspective cameras");
  if (!mc.placed) fail_at(path / "index", which + " is on no node of the file's scene");
  // Placed by the mesh's first instance, as its lights are by each.
  Affine world = kIdentityTransform;
  for (const Placement& p : scene_.placements) {
    if (p.mesh == static_cast<int32_t>(mesh)) {
      world = p.world_from_object;
      break;
    }
  }
  CameraSpec& c = scene_.camera;
  c.look_from = world.point(mc.position);
  const vec3 forward = world.vector(mc.forward), up = world.vector(mc.up);
  const float focus = c.focus_distance > 0.0f ? c.focus_distance : 1.0f;
  c.look_at = c.look_from + focus * glm::normalize(forward);
  c.up = glm::normalize(up);
  c.vfov_degrees = mc.yfov * (180.0f / kPi);
}

void SceneReader::read_sky(const json& j, const JsonPath& path) {
  size_t type = type_of(j, path, "sky", {"gradient", "uniform", "environment"});
  if (type == 2) {
    check_keys(j, path, {"type", "file", "mapping", "rotation", "intensity", "colorspace"}, "environment");
    Sky& sky = scene_.sky;
    sky.kind = SkyKind::Environment;
    sky.mapping = EnvironmentMapping::LatLong;
    if (j.contains("mapping")) {
      const std::string m = string(j["mapping"], path / "mapping");
      if (m == "latlong") {
        sky.mapping = EnvironmentMapping::LatLong;
      } else if (m == "angular") {
        sky.mapping = EnvironmentMapping::Angular;
      } else if (m == "mirror_ball") {
        sky.mapping = EnvironmentMapping::MirrorBall;
      } else {
        fail_at(path / "mapping", "unknown mapping '" + m + "' (expected latlong, angular, mirror_ball)");
      }
    }
    const float degrees = j.contains("rotation") ? number(j["rotation"], path / "rotation") : 0.0f;
    const double radians = static_cast<double>(degrees) * 3.14159265358979323846 / 180.0;
    sky.turn_cos = static_cast<float>(std::cos(radians));
    sky.turn_sin = static_cast<float>(std::sin(radians));
    sky.intensity = j.contains("intensity") ? non_negative(j["intensity"], path / "intensity") : 1.0f;
    // 8-bit images are sRGB-encoded unless said otherwise, as image textures are;
    // Radiance .hdr and OpenEXR images hold linear values.
    bool srgb = true;
    if (j.contains("colorspace")) {
      const std::string cs = string(j["colorspace"], path / "colorspace");
      if (cs != "srgb" && cs != "linear") {
        fail_at(path / "colorspace", "unknown colorspace '" + cs + "' (expected srgb, linear)");
      }
      srgb = cs == "srgb";
    }
    sky.image = image(string(required(j, path, "file"), path / "file"), srgb, path / "file");
    float brightest = 0.0f;
    const std::vector<float>& texels = scene_.images[static_cast<size_t>(sky.image)].texels;
    for (size_t i = 0; i < texels.size(); ++i) {
      if (i % 4 != 3) brightest = std::max(brightest, texels[i]);
    }
    if (static_cast<double>(brightest) * sky.intensity > kMaxRadiance) {
      fail_at(j.contains("intensity") ? path / "intensity" : path / "file",
              "the environment's brightest texel (" + std::to_string(brightest) + ") times its intensity (" +
                  std::to_string(sky.intensity) + ") is more than 1e9, the most radiance a scene may hold");
    }
  } else if (type == 0) {
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

void SceneReader::read_render(const json& j, const JsonPath& path) {
  std::vector<std::string> keys;
  for (SettingId id : scene_settings()) keys.push_back(setting(id).key);
  check_keys(j, path, keys);
  for (SettingId id : render_settings()) {
    const Setting& s = setting(id);
    auto it = j.find(s.key);
    if (it != j.end()) set_param(scene_.render, id, integer_setting(*it, path / s.key, id));
  }
  // Adaptive sampling, asked for by the scene (a job's own settings come first).
  const char* min_spp = setting(SettingId::MinSpp).key;
  const char* threshold = setting(SettingId::NoiseThreshold).key;
  if (j.contains(min_spp)) {
    scene_.render.min_spp = static_cast<int32_t>(integer_setting(j[min_spp], path / min_spp, SettingId::MinSpp));
  }
  if (j.contains(threshold)) {
    scene_.render.noise_threshold = real_setting(j[threshold], path / threshold, SettingId::NoiseThreshold);
  }
}

}  // namespace wt

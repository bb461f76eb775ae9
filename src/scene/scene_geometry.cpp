// Scene files: spheres.
#include "scene/scene_reader.hpp"

namespace wt {

void SceneReader::read_sphere(const json& j, const JsonPath& path) {
  check_keys(j, path, {"center", "radius", "material"});
  vec3 c = position(required(j, path, "center"), path / "center");
  float r = positive(required(j, path, "radius"), path / "radius");
  if (r > kMaxCoordinate) {
    fail_at(path / "radius", "must be at most 1e15, the largest length a scene may hold (got " + j["radius"].dump() + ")");
  }
  const int32_t m = material_named(required(j, path, "material"), path / "material");
  scene_.spheres.push_back(SphereGeom{c.x, c.y, c.z, r});
  scene_.sphere_materials.push_back(static_cast<uint32_t>(m));
}

}  // namespace wt

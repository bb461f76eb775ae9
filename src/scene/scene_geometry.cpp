// Scene files: spheres.
#include "scene/scene_reader.hpp"

namespace wt {

void SceneReader::read_sphere(const json& j, const JsonPath& path) {
  check_keys(j, path, {"center", "radius", "material"});
  vec3 c = triple(required(j, path, "center"), path / "center");
  float r = positive(required(j, path, "radius"), path / "radius");
  const int32_t m = material_named(required(j, path, "material"), path / "material");
  scene_.spheres.push_back(SphereGeom{c.x, c.y, c.z, r});
  scene_.sphere_material.push_back(static_cast<uint32_t>(m));
}

}  // namespace wt

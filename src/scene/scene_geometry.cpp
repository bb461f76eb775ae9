// Scene files: geometry (spheres).
#include "scene/scene_reader.hpp"

namespace wt {

void SceneReader::read_sphere(const json& j, const JsonPath& path) {
  check_keys(j, path, {"center", "radius", "material"});
  vec3 c = triple(required(j, path, "center"), path / "center");
  float r = positive(required(j, path, "radius"), path / "radius");
  const std::string& m = string(required(j, path, "material"), path / "material");
  auto found = material_names_.find(m);
  if (found == material_names_.end()) fail_at(path / "material", "unknown material '" + m + "'");
  scene_.spheres.push_back(SphereGeom{c.x, c.y, c.z, r});
  scene_.sphere_material.push_back(static_cast<uint32_t>(found->second.first));
}

}  // namespace wt

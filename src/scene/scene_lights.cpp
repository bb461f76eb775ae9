// Scene files: `lights`, the punctual lights the scene file places itself (a mesh
// file's own are placed by its instances).
#include <algorithm>
#include <cmath>

#include "scene/scene_reader.hpp"

namespace wt {

void SceneReader::read_light(const json& j, const JsonPath& path) {
  const size_t type = type_of(j, path, "light", {"point", "spot", "directional"});
  PunctualLight l{};
  if (type == 0) {
    check_keys(j, path, {"type", "position", "intensity"}, "point");
    l.kind = PunctualKind::Point;
  } else if (type == 1) {
    check_keys(j, path, {"type", "position", "direction", "intensity", "inner_angle", "outer_angle"}, "spot");
    l.kind = PunctualKind::Spot;
  } else {
    check_keys(j, path, {"type", "direction", "irradiance"}, "directional");
    l.kind = PunctualKind::Directional;
  }
  if (l.kind != PunctualKind::Directional) {
    l.position = position(required(j, path, "position"), path / "position");
    l.intensity = radiance(required(j, path, "intensity"), path / "intensity");
  } else {
    l.intensity = radiance(required(j, path, "irradiance"), path / "irradiance");
  }
  if (l.kind != PunctualKind::Point) {
    const vec3 d = triple(required(j, path, "direction"), path / "direction");
    if (!(glm::length(d) > 0.0f)) fail_at(path / "direction", "must not be zero");
    l.direction = glm::normalize(d);
  }
  if (l.kind == PunctualKind::Spot) {
    const double inner = j.contains("inner_angle") ? number(j["inner_angle"], path / "inner_angle") : 0.0;
    const double outer = j.contains("outer_angle") ? number(j["outer_angle"], path / "outer_angle") : 45.0;
    if (!(inner >= 0.0 && inner < outer && outer <= 90.0)) {
      fail_at(path, "the cone's angles must satisfy 0 <= inner_angle < outer_angle <= 90 (degrees)");
    }
    set_spot_cones(l, inner * kPi / 180.0, outer * kPi / 180.0);
  }
  scene_.file_lights.push_back(l);
}

}  // namespace wt

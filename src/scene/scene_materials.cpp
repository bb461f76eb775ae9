// Scene files: materials.
#include "scene/scene_reader.hpp"

namespace wt {

void SceneReader::read_material(const json& j, const JsonPath& path) {
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

}  // namespace wt

// Scene files: materials.
#include <sstream>

#include "scene/bsdf_tables.hpp"
#include "scene/conductor_presets.hpp"
#include "scene/scene_reader.hpp"

namespace wt {
namespace {

std::string preset_names() {
  std::ostringstream os;
  bool first = true;
  for (const ConductorPreset& p : kConductorPresets) {
    os << (first ? "" : ", ") << p.name;
    first = false;
  }
  return os.str();
}

}  // namespace

void SceneReader::read_material(const json& j, const JsonPath& path) {
  // In MaterialKind's order.
  static const std::vector<std::string> kTypes = {"lambertian", "metal", "dielectric", "coated",
                                                  "emissive",   "conductor", "glass", "plastic"};
  static const std::vector<std::vector<std::string>> kKeys = {
      {"name", "type", "albedo", "texture"},
      {"name", "type", "albedo", "fuzz", "texture"},
      {"name", "type", "ior", "albedo"},
      {"name", "type", "albedo", "ior", "texture"},
      {"name", "type", "emission"},
      {"name", "type", "roughness", "anisotropy", "metal", "eta", "k", "f0", "energy_compensation", "masking"},
      {"name", "type", "ior", "roughness", "tint", "thin", "energy_compensation", "masking"},
      {"name", "type", "albedo", "texture", "ior", "roughness", "masking"},
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
  if (m.kind == MaterialKind::Glass || m.kind == MaterialKind::Plastic) {
    m.ior = j.contains("ior") ? positive(j["ior"], path / "ior") : 1.5f;
  }
  if (m.kind == MaterialKind::Emissive) {
    m.albedo = vec3(0.0f);
    m.emission = radiance(required(j, path, "emission"), path / "emission");
  }
  if (m.kind == MaterialKind::Conductor || m.kind == MaterialKind::Glass || m.kind == MaterialKind::Plastic) {
    read_microfacet(j, path, m);
  }
  int texture_kind = -1;
  if (j.contains("texture")) {
    std::string t = string(j["texture"], path / "texture");
    auto found = texture_names_.find(t);
    if (found == texture_names_.end()) fail_at(path / "texture", "unknown texture '" + t + "'");
    m.texture = static_cast<int32_t>(found->second.first);
    texture_kind = static_cast<int>(scene_.textures[m.texture].kind);
  }
  m.sort_key = static_cast<uint8_t>(material_sort_key(m.kind, texture_kind));
  scene_.materials.push_back(m);
  scene_.material_names.push_back(n);
}

// The microfacet kinds' own fields, into a MaterialParams of their own.
void SceneReader::read_microfacet(const json& j, const JsonPath& path, Material& m) {
  MaterialParams p{};
  const float roughness = j.contains("roughness") ? unit_interval(j["roughness"], path / "roughness") : 0.0f;
  const float anisotropy = j.contains("anisotropy") ? unit_interval(j["anisotropy"], path / "anisotropy") : 0.0f;
  const Ggx g = ggx_from_roughness(roughness, anisotropy);
  p.ax = g.ax;
  p.ay = g.ay;
  const bool compensate =
      j.contains("energy_compensation") ? boolean(j["energy_compensation"], path / "energy_compensation") : true;
  if (compensate && m.kind != MaterialKind::Plastic) m.flags |= kMaterialCompensated;
  if (j.contains("masking") && choice(j["masking"], path / "masking", {"height-correlated", "separable"}) == 1) {
    m.flags |= kMaterialSeparable;
  }
  if (m.kind == MaterialKind::Conductor) {
    const int given = (j.contains("metal") ? 1 : 0) + (j.contains("eta") || j.contains("k") ? 1 : 0) +
                      (j.contains("f0") ? 1 : 0);
    if (given != 1) {
      fail_at(path, "a conductor takes exactly one of 'metal' (a preset), 'eta' with 'k', or 'f0'");
    }
    if (j.contains("metal")) {
      const std::string& name = string(j["metal"], path / "metal");
      const ConductorPreset* found = nullptr;
      for (const ConductorPreset& preset : kConductorPresets) {
        if (name == preset.name) found = &preset;
      }
      if (!found) fail_at(path / "metal", "unknown metal '" + name + "' (known: " + preset_names() + ")");
      p.eta = found->eta;
      p.k = found->k;
    } else if (j.contains("f0")) {
      p.eta = colour(j["f0"], path / "f0");
      m.flags |= kMaterialSchlick;
    } else {
      p.eta = triple(required(j, path, "eta"), path / "eta");
      p.k = triple(required(j, path, "k"), path / "k");
      for (int c = 0; c < 3; ++c) {
        if (!(p.eta[c] > 0.0f)) fail_at(path / "eta", "each component must be > 0");
        if (!(p.k[c] >= 0.0f)) fail_at(path / "k", "each component must be >= 0");
      }
    }
  }
  if (m.kind == MaterialKind::Glass) {
    if (j.contains("tint")) m.albedo = colour(j["tint"], path / "tint");
    if (j.contains("thin") && boolean(j["thin"], path / "thin")) {
      if (roughness > 0.0f) fail_at(path / "thin", "a thin sheet is smooth: give roughness 0 or leave it out");
      m.flags |= kMaterialThin;
    }
  }
  prepare_microfacet(m, p, scene_.bsdf_tables, conductor_tables_);
  m.params = static_cast<int32_t>(scene_.material_params.size());
  scene_.material_params.push_back(p);
}

}  // namespace wt

// Scene files: materials.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "scene/bsdf_tables.hpp"
#include "scene/conductor_presets.hpp"
#include "scene/scene_reader.hpp"
#include "wavetrace/blend.hpp"

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
  static const std::vector<std::string> kTypes = {"lambertian", "metal", "dielectric", "coated",    "emissive",
                                                  "conductor",  "glass", "plastic",    "principled", "blend"};
  static const std::vector<std::vector<std::string>> kKeys = {
      {"name", "type", "albedo", "texture", "normal_texture", "normal_strength", "bump_texture", "bump_scale"},
      {"name", "type", "albedo", "fuzz", "texture", "normal_texture", "normal_strength", "bump_texture", "bump_scale"},
      {"name", "type", "ior", "albedo", "normal_texture", "normal_strength", "bump_texture", "bump_scale"},
      {"name", "type", "albedo", "ior", "texture", "normal_texture", "normal_strength", "bump_texture", "bump_scale"},
      {"name", "type", "emission", "emission_texture"},
      {"name", "type", "roughness", "anisotropy", "metal", "eta", "k", "f0", "energy_compensation", "masking",
       "roughness_texture", "normal_texture", "normal_strength", "bump_texture", "bump_scale"},
      {"name", "type", "ior", "roughness", "tint", "thin", "energy_compensation", "masking", "roughness_texture",
       "normal_texture", "normal_strength", "bump_texture", "bump_scale"},
      {"name", "type", "albedo", "texture", "ior", "roughness", "masking", "roughness_texture", "normal_texture",
       "normal_strength", "bump_texture", "bump_scale", "metallic", "metallic_texture", "energy_compensation"},
      {"name", "type", "albedo", "texture", "ior", "roughness", "anisotropy", "metallic", "roughness_texture",
       "metallic_texture", "normal_texture", "normal_strength", "bump_texture", "bump_scale", "energy_compensation", "masking", "double_sided",
       "specular", "clearcoat", "clearcoat_roughness", "clearcoat_texture", "clearcoat_roughness_texture",
       "clearcoat_normal_texture", "clearcoat_normal_strength", "transmission", "transmission_texture", "thin",
       "attenuation_color", "attenuation_distance", "emission", "emission_texture", "specular_texture",
       "specular_color", "specular_color_texture"},
      {"name", "type", "materials", "weight", "weight_texture"},
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
  if (m.kind == MaterialKind::Blend) {
    read_blend(j, path, m);
    scene_.materials.push_back(m);
    scene_.material_names.push_back(n);
    return;
  }
  m.albedo = j.contains("albedo") ? colour(j["albedo"], path / "albedo") : vec3(1.0f);
  if (j.contains("fuzz")) m.fuzz = unit_interval(j["fuzz"], path / "fuzz");
  if (m.kind == MaterialKind::Dielectric || m.kind == MaterialKind::Coated) {
    m.ior = positive(required(j, path, "ior"), path / "ior");
  }
  if (m.kind == MaterialKind::Glass || m.kind == MaterialKind::Plastic || m.kind == MaterialKind::Principled) {
    m.ior = j.contains("ior") ? positive(j["ior"], path / "ior") : 1.5f;
  }
  if (m.kind == MaterialKind::Emissive) {
    m.albedo = vec3(0.0f);
    m.emission = radiance(required(j, path, "emission"), path / "emission");
  }
  int texture_kind = -1;
  if (j.contains("texture")) {
    m.texture = texture_named(j["texture"], path / "texture");
    texture_kind = static_cast<int>(scene_.textures[m.texture].kind);
  }
  // An emitter's texture slot is its emission's (it has no albedo); a reflecting
  // kind's emission texture is a parameter (read_params).
  if (m.kind == MaterialKind::Emissive && j.contains("emission_texture")) {
    m.texture = texture_named(j["emission_texture"], path / "emission_texture");
  }
  if (m.kind != MaterialKind::Emissive && j.contains("emission")) {
    m.emission = radiance(j["emission"], path / "emission");
    if (m.emission.x > 0.0f || m.emission.y > 0.0f || m.emission.z > 0.0f) m.flags |= kMaterialEmits;
  }
  if (m.kind == MaterialKind::Conductor || m.kind == MaterialKind::Glass || m.kind == MaterialKind::Plastic ||
      m.kind == MaterialKind::Principled || j.contains("normal_texture") || j.contains("bump_texture") ||
      j.contains("bump_scale")) {
    read_params(j, path, m);
  }
  m.sort_key = static_cast<uint8_t>(material_sort_key(m.kind, texture_kind));
  scene_.materials.push_back(m);
  scene_.material_names.push_back(n);
}

// A blend of two materials named before it (so that blends cannot form a cycle),
// neither of which emits (an emitter's light sampling needs every hit on it to
// emit), at most kMaxBlendDepth blends deep.
void SceneReader::read_blend(const json& j, const JsonPath& path, Material& m) {
  const JsonPath at = path / "materials";
  const json& list = required(j, path, "materials");
  if (!list.is_array() || list.size() != 2) fail_at(at, "must be a list of two material names");
  MaterialParams p{};
  int depth = 1;
  for (size_t i = 0; i < 2; ++i) {
    const JsonPath item = at / i;
    const std::string& name = string(list[i], item);
    if (!material_names_.count(name)) {
      fail_at(item, "unknown material '" + name + "' (a blend names materials defined before it)");
    }
    const int32_t index = material_named(list[i], item);
    const Material& inner = scene_.materials[static_cast<size_t>(index)];
    if (inner.kind == MaterialKind::Emissive || (inner.flags & kMaterialEmits)) {
      fail_at(item, "material '" + name + "' emits: a blend's materials must not (give the blended surface its own emitter)");
    }
    if (inner.kind == MaterialKind::Blend) depth = std::max(depth, 1 + blend_depth(inner));
    p.blend_materials[i] = index;
  }
  if (depth > kMaxBlendDepth) {
    fail_at(at, "blends nest " + std::to_string(depth) + " deep; at most " + std::to_string(kMaxBlendDepth) + " are supported");
  }
  p.blend_weight = j.contains("weight") ? unit_interval(j["weight"], path / "weight") : 0.5f;
  if (j.contains("weight_texture")) p.blend_texture = texture_named(j["weight_texture"], path / "weight_texture");
  m.albedo = vec3(0.0f);
  m.sort_key = static_cast<uint8_t>(material_sort_key(m.kind, -1));
  m.params = static_cast<int32_t>(scene_.material_params.size());
  scene_.material_params.push_back(p);
}

int SceneReader::blend_depth(const Material& m) const {
  if (m.kind != MaterialKind::Blend) return 0;
  const MaterialParams& p = scene_.material_params[static_cast<size_t>(m.params)];
  int depth = 0;
  for (int32_t index : p.blend_materials) depth = std::max(depth, blend_depth(scene_.materials[static_cast<size_t>(index)]));
  return 1 + depth;
}

int32_t SceneReader::texture_named(const json& j, const JsonPath& path) const {
  const std::string& t = string(j, path);
  auto found = texture_names_.find(t);
  if (found == texture_names_.end()) fail_at(path, "unknown texture '" + t + "'");
  return static_cast<int32_t>(found->second.first);
}

// The fields beyond the study's (the microfacet kinds', a normal map), into a
// MaterialParams of the material's own.
void SceneReader::read_params(const json& j, const JsonPath& path, Material& m) {
  MaterialParams p{};
  p.table_rows = 1;
  p.roughness_texture = j.contains("roughness_texture") ? texture_named(j["roughness_texture"], path / "roughness_texture") : -1;
  p.normal_texture = -1;
  p.normal_strength = 1.0f;
  if (j.contains("normal_texture")) {
    p.normal_texture = texture_named(j["normal_texture"], path / "normal_texture");
    if (scene_.textures[p.normal_texture].kind == TextureKind::Image &&
        scene_.images[scene_.textures[p.normal_texture].image].srgb_decoded) {
      fail_at(path / "normal_texture", "a normal map holds vectors, not colours: give its image texture \"colorspace\": \"linear\"");
    }
  }
  if (j.contains("normal_strength")) p.normal_strength = non_negative(j["normal_strength"], path / "normal_strength");
  // A bump map: an image's heights (its luminance), times bump_scale in the scene's units.
  if (j.contains("bump_texture")) {
    const JsonPath at = path / "bump_texture";
    if (p.normal_texture >= 0) fail_at(at, "a material takes a normal map or a bump map, not both");
    const Texture& heights = scene_.textures[static_cast<size_t>(texture_named(j["bump_texture"], at))];
    if (heights.kind != TextureKind::Image) fail_at(at, "a bump map is an image of heights: name an image texture");
    if (scene_.images[static_cast<size_t>(heights.image)].srgb_decoded) {
      fail_at(at, "a bump map holds heights, not colours: give its image texture \"colorspace\": \"linear\"");
    }
    p.bump_texture = bump_texture(heights, HeightChannel::Luminance);
  }
  if (j.contains("bump_scale")) {
    if (!j.contains("bump_texture")) fail_at(path / "bump_scale", "scales a bump map: give \"bump_texture\" too");
    p.bump_scale = number(j["bump_scale"], path / "bump_scale");
    if (!(std::fabs(p.bump_scale) <= 1e3f)) fail_at(path / "bump_scale", "must be in [-1000, 1000]");
  }
  // Textured roughness scales the roughness, which then defaults to 1.
  const float roughness = j.contains("roughness")           ? unit_interval(j["roughness"], path / "roughness")
                          : p.roughness_texture >= 0 ? 1.0f
                                                     : 0.0f;
  const float anisotropy = j.contains("anisotropy") ? unit_interval(j["anisotropy"], path / "anisotropy") : 0.0f;
  const Ggx g = ggx_from_roughness(roughness, anisotropy);
  p.ax = g.ax;
  p.ay = g.ay;
  const bool compensate =
      j.contains("energy_compensation") ? boolean(j["energy_compensation"], path / "energy_compensation") : true;
  // A plastic's coat is not compensated (Mitsuba's model); its metal is, where it has one.
  if (m.kind == MaterialKind::Plastic || m.kind == MaterialKind::Principled) {
    p.metallic = j.contains("metallic") ? unit_interval(j["metallic"], path / "metallic") : 0.0f;
    if (j.contains("metallic_texture")) {
      p.metallic_texture = texture_named(j["metallic_texture"], path / "metallic_texture");
      if (!j.contains("metallic")) p.metallic = 1.0f;  // the texture's blue channel alone
    }
  }
  if (compensate && (m.kind != MaterialKind::Plastic || p.metallic > 0.0f)) m.flags |= kMaterialCompensated;
  if (j.contains("specular")) p.specular = unit_interval(j["specular"], path / "specular");
  if (m.kind == MaterialKind::Principled && j.contains("double_sided") &&
      !boolean(j["double_sided"], path / "double_sided")) {
    m.flags |= kMaterialOneSided;
  }
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
  if (m.kind == MaterialKind::Principled) {
    auto texture = [&](const char* key) { return j.contains(key) ? texture_named(j[key], path / key) : -1; };
    PrincipledLayers l;
    if (j.contains("clearcoat")) l.clearcoat = unit_interval(j["clearcoat"], path / "clearcoat");
    if (j.contains("clearcoat_roughness")) {
      l.clearcoat_roughness = unit_interval(j["clearcoat_roughness"], path / "clearcoat_roughness");
    }
    if (j.contains("clearcoat_normal_strength")) {
      l.clearcoat_normal_strength = non_negative(j["clearcoat_normal_strength"], path / "clearcoat_normal_strength");
    }
    if (j.contains("transmission")) l.transmission = unit_interval(j["transmission"], path / "transmission");
    if (j.contains("thin")) l.thin = boolean(j["thin"], path / "thin");
    if (j.contains("attenuation_color")) l.attenuation_color = colour(j["attenuation_color"], path / "attenuation_color");
    if (j.contains("attenuation_distance")) {
      l.attenuation_distance = positive(j["attenuation_distance"], path / "attenuation_distance");
    }
    for (const char* key : {"attenuation_color", "attenuation_distance"}) {
      if (j.contains(key) && l.thin) fail_at(path / key, "a thin wall holds no volume: give \"thin\": false");
    }
    // A texture given alone sets its parameter outright (the factor defaults to 1).
    p.clearcoat_texture = texture("clearcoat_texture");
    if (p.clearcoat_texture >= 0 && !j.contains("clearcoat")) l.clearcoat = 1.0f;
    p.coat_roughness_texture = texture("clearcoat_roughness_texture");
    if (p.coat_roughness_texture >= 0 && !j.contains("clearcoat_roughness")) l.clearcoat_roughness = 1.0f;
    p.coat_normal_texture = texture("clearcoat_normal_texture");
    p.transmission_texture = texture("transmission_texture");
    if (p.transmission_texture >= 0 && !j.contains("transmission")) l.transmission = 1.0f;
    p.emission_texture = texture("emission_texture");
    p.specular_texture = texture("specular_texture");
    p.specular_color_texture = texture("specular_color_texture");
    if (j.contains("specular_color")) p.specular_color = triple(j["specular_color"], path / "specular_color");
    for (int c = 0; c < 3; ++c) {
      if (!(p.specular_color[c] >= 0.0f && p.specular_color[c] <= 1e3f)) {
        fail_at(path / "specular_color", "each component must be in [0, 1000]");
      }
    }
    if (p.emission_texture >= 0 && !(m.flags & kMaterialEmits)) {
      fail_at(path / "emission_texture", "scales the emission: give \"emission\" too");
    }
    set_principled_layers(p, m, l);
  }
  if (m.kind == MaterialKind::Glass) {
    if (j.contains("tint")) m.albedo = colour(j["tint"], path / "tint");
    if (j.contains("thin") && boolean(j["thin"], path / "thin")) {
      if (roughness > 0.0f) fail_at(path / "thin", "a thin sheet is smooth: give roughness 0 or leave it out");
      m.flags |= kMaterialThin;
    }
  }
  prepare_microfacet(m, p, scene_.bsdf_tables, shared_tables_);
  m.params = static_cast<int32_t>(scene_.material_params.size());
  scene_.material_params.push_back(p);
}

}  // namespace wt

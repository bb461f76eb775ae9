// The materials as the scene holds them: each kind's parameters. How a kind
// scatters light is its BSDF (bsdf.hpp and bsdfs/).
#pragma once

#include "wavetrace/geometry/surface.hpp"
#include "wavetrace/texture.hpp"

namespace wt {

// The study's kinds keep their numbers (0-4); the microfacet kinds follow.
enum class MaterialKind : uint8_t {
  Lambertian = 0,
  Metal = 1,
  Dielectric = 2,
  Coated = 3,
  Emissive = 4,
  Conductor = 5,
  Glass = 6,
  Plastic = 7,
  Principled = 8,
  // Two materials mixed by a weight: not shaded itself. Each hit on it shades with
  // one of the two, picked with the weight's probability (blend.hpp), so the image
  // converges to the weighted sum of the two BSDFs.
  Blend = 9,
};
constexpr uint32_t kMaterialKindCount = 10;

// Material::flags.
enum MaterialFlag : uint16_t {
  kMaterialThin = 1,         // Glass: a thin sheet; Principled: its transmission is through a thin wall
  kMaterialSchlick = 2,      // Conductor: Fresnel from f0 (MaterialParams::eta) by Schlick's formula
  kMaterialCompensated = 4,  // Conductor, Glass: the energy lost to multiple scattering is put back
  kMaterialSeparable = 8,    // Conductor, Glass, Plastic, Principled: separable Smith masking (Ggx::separable)
  kMaterialOneSided = 16,    // Principled: a back face reflects nothing (glTF's doubleSided false)
  kMaterialEmits = 32,       // a kind other than Emissive that also emits (Material::emission)
};

// The parameters beyond the study's: the microfacet kinds' (conductor, glass,
// plastic) and any kind's normal map; one per such material, in the scene's
// material_params (Material::params indexes it).
struct MaterialParams {
  float ax = 0.0f, ay = 0.0f;  // GGX alphas along the tangent and across it (below kSmoothAlpha: smooth)
  float internal = 0.0f;   // Plastic: the coat's diffuse reflectance seen from inside
  int32_t table = -1;      // the offset of the material's tables in the scene's bsdf_tables (-1: none)
  vec3 eta{0.0f};          // Conductor: the real part of the index (or f0 with kMaterialSchlick)
  vec3 k{0.0f};            // Conductor: the imaginary part
  vec3 fresnel_average{0.0f};  // Conductor: 2 int F(mu) mu dmu per channel (Kulla-Conty's F_avg)
  int32_t table_rows = 1;          // 1, or kEnergySize rows by roughness where the roughness is textured
  int32_t roughness_texture = -1;  // -1, or the texture whose green channel scales the roughness
  int32_t normal_texture = -1;     // -1, or a tangent-space normal map (linear colour)
  float normal_strength = 1.0f;    // scales the normal map's x and y (glTF's normalTexture.scale)
  // A bump (height) map: -1, or a texture of the height's derivatives (dh/du, dh/dv,
  // per unit of its coordinates: the scene's height_gradient of the height image),
  // the surface displaced along its normal by bump_scale times the height, in the
  // scene's units (bumped_normal).
  int32_t bump_texture = -1;
  float bump_scale = 1.0f;
  // Plastic: the share of a metal of f0 = albedo at the coat's roughness (glTF's
  // metallic), scaled by metallic_texture's blue channel where it has one; and the
  // metal's energy tables (the conductors', -1: uncompensated).
  float metallic = 0.0f;
  int32_t metallic_texture = -1;
  int32_t metal_table = -1;
  // Principled: the strength of the dielectric's specular layer (glTF's
  // KHR_materials_specular specularFactor, times specular_texture's alpha; 0: the
  // base alone, a Lambertian) and the tint of its f0 (specularColorFactor, times
  // specular_color_texture's colour).
  float specular = 1.0f;
  int32_t specular_texture = -1;
  vec3 specular_color{1.0f};
  int32_t specular_color_texture = -1;
  // Principled: a clear coat (KHR_materials_clearcoat) of weight `clearcoat` (times
  // clearcoat_texture's red channel) and GGX alpha coat_alpha (its roughness
  // squared; the roughness times coat_roughness_texture's green channel), with a
  // normal map of its own (none: the surface's shading normal); coat_table: its
  // layer table (principled_table at index 1.5).
  float clearcoat = 0.0f;
  int32_t clearcoat_texture = -1;
  float coat_alpha = 0.0f;
  int32_t coat_roughness_texture = -1;
  int32_t coat_normal_texture = -1;
  float coat_normal_strength = 1.0f;
  int32_t coat_table = -1;
  // Principled: the share of the dielectric base that transmits
  // (KHR_materials_transmission, times transmission_texture's red channel), tinted
  // by the base colour: through a thin wall (kMaterialThin), or refracting into a
  // volume as `glass` does (glass_table: its energy tables, rows by roughness) that
  // absorbs `attenuation` per unit length (KHR_materials_volume, Beer-Lambert).
  float transmission = 0.0f;
  int32_t transmission_texture = -1;
  int32_t glass_table = -1;
  vec3 attenuation{0.0f};
  // A reflecting material's emission texture (Material::emission times its colour).
  int32_t emission_texture = -1;
  // Blend: its two materials (indices into the scene's materials), the second taken
  // with probability blend_weight, times blend_texture's luminance where it has one.
  int32_t blend_materials[2] = {-1, -1};
  float blend_weight = 0.5f;
  int32_t blend_texture = -1;
};

// Kept at 44 bytes: the constant-memory megakernel holds every material of a
// scene (rtiow-cover has 464) in 63 KiB with the scene's tree.
struct Material {
  MaterialKind kind;
  // Shading work differs by material kind and by texture kind; this key groups hits
  // that run the same code, so that sorting by it gives warps one code path.
  uint8_t sort_key;
  uint16_t flags;   // MaterialFlag
  int32_t texture;  // < 0: the constant albedo
  float fuzz;       // Metal
  float ior;        // Dielectric, Coated (the coat), Glass, Plastic (the coat), Principled (the base)
  vec3 albedo;      // Lambertian, Metal, Coated, Plastic (the base), Principled (the base colour);
                    // Dielectric, Glass: transmission tint
  vec3 emission;    // Emissive; any other kind with kMaterialEmits
  int32_t params = -1;  // Conductor, Glass, Plastic, Principled, Blend: index into material_params (-1: none)
};
static_assert(sizeof(Material) == 44, "a material grows every constant-memory scene");

// Sort keys. The kinds whose albedo a texture may set (lambertian, metal, coated,
// plastic, principled) take four keys each (the texture slot: 0 untextured, 1 +
// TextureKind), the others one (the dielectric keeps the study's four, of which it
// uses the first, so that the study's kinds keep their keys), then one key for
// emitters, whose hits only add their emission; the miss key follows.
//   lambertian 0-3, metal 4-7, dielectric 8, coated 12-15, conductor 16, glass 17,
//   plastic 18-21, principled 22-25, emitters 26, misses 27.
// A blend has no key of its own: a hit shades with the material it picks, under
// that material's key (its slot here is never read).
constexpr uint8_t kKindFirstKey[kMaterialKindCount] = {0, 4, 8, 12, 26, 16, 17, 18, 22, 26};
constexpr uint32_t kEmitterSortKey = 26;
WT_HD WT_INLINE uint32_t material_sort_key(MaterialKind kind, int texture_kind /* -1: none */) {
  const bool textured = kind == MaterialKind::Lambertian || kind == MaterialKind::Metal ||
                        kind == MaterialKind::Coated || kind == MaterialKind::Plastic ||
                        kind == MaterialKind::Principled;
  return kKindFirstKey[static_cast<uint32_t>(kind)] + (textured ? static_cast<uint32_t>(texture_kind + 1) : 0u);
}
constexpr uint32_t kSortKeyCount = kEmitterSortKey + 1;
// The kind a sort key belongs to (material_sort_key's inverse in the kind).
WT_HD WT_INLINE MaterialKind sort_key_kind(uint32_t key) {
  if (key >= kEmitterSortKey) return MaterialKind::Emissive;
  if (key >= 22) return MaterialKind::Principled;
  if (key >= 18) return MaterialKind::Plastic;
  if (key == 17) return MaterialKind::Glass;
  if (key == 16) return MaterialKind::Conductor;
  return static_cast<MaterialKind>(key / 4 < 3 ? key / 4 : 3);
}

// The microfacet kinds' keys (conductor, glass, plastic, principled), whose shading
// costs several times a Lambertian's.
constexpr uint32_t kMicrofacetKeyMask = ((1u << 10) - 1) << 16;
constexpr uint32_t kSortKeyMiss = kSortKeyCount;  // paths that left the scene sort last
// The miss key must fit the bits above the slot (path_queue.hpp's 27 leave 5), and a
// bounce's keys below it are gathered as the bits of one word.
static_assert(kSortKeyMiss < 32, "the sort keys and the miss key must fit in 5 bits");

// Filtered: with the mip-mapped lookups (texture.hpp's eval_texture).
template <bool Filtered = true>
WT_HD WT_INLINE vec3 material_albedo(const Material& m, const Texture* textures, const ImageView* images,
                                     const SurfacePoint& sp) {
  return m.texture < 0 ? m.albedo : m.albedo * eval_texture<Filtered>(textures[m.texture], images, sp);
}

}  // namespace wt

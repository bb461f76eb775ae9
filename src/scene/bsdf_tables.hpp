// The microfacet kinds' tables (bsdfs/energy.hpp), built on the host from the same
// BSDF code the renderer runs, with the same deterministic points every time, so
// that every backend reads the same numbers.
#pragma once

#include <map>
#include <tuple>
#include <vector>

#include "wavetrace/bsdf.hpp"

namespace wt {

// The conductors' table (energy.hpp) for height-correlated or separable masking:
// each built once a process.
const std::vector<float>& conductor_energy_table(bool separable);

// 2 int_0^1 F(mu) mu dmu of a conductor's Fresnel, per channel.
vec3 conductor_average_fresnel(const vec3& eta, const vec3& k, bool schlick);

// E(mu) of a rough glass from outside, then from inside, each `rows` rows: 1 (the
// material's roughness) or kEnergySize (by roughness).
std::vector<float> glass_energy_table(float ior, const Ggx& g, int rows);

// The transmittance t(mu) from outside of a rough plastic's coat in `rows` rows as
// above, then (rows by roughness only) the coat's internal reflectance by roughness;
// and the internal reflectance of one coat.
std::vector<float> plastic_table(float ior, const Ggx& g, int rows);
float plastic_internal_reflectance(float ior, const Ggx& g);

// The principled kind's layer table (principled.hpp): E_s(r, mu), the directional
// albedo of its dielectric specular lobe (Schlick's Fresnel of f0 from `ior`, with
// the multiple-scattering lobe where `compensated`), rows by roughness, then its
// cosine-weighted average by row.
std::vector<float> principled_table(float ior, bool separable, bool compensated);

// Where tables shared between materials already are in the scene's bsdf_tables.
struct SharedTables {
  int32_t conductor[2] = {-1, -1};  // height-correlated, separable
  std::map<std::tuple<float, bool, bool>, int32_t> principled;  // by (ior, separable, compensated)
  std::map<std::tuple<float, bool>, int32_t> glass;  // principled volumes': rows by roughness, by (ior, separable)
};

// The principled kind's coat, transmission and volume as a file gives them: the
// coat's weight, roughness and normal map strength; the transmitted share, thin
// walled or a volume that absorbs to attenuation_color over attenuation_distance
// (0: infinitely far, a clear volume).
struct PrincipledLayers {
  float clearcoat = 0.0f, clearcoat_roughness = 0.0f, clearcoat_normal_strength = 1.0f;
  float transmission = 0.0f;
  bool thin = true;
  vec3 attenuation_color{1.0f};
  float attenuation_distance = 0.0f;
};

// Sets them in the material's params and flags (before prepare_microfacet): the
// coat's alpha (roughness squared), kMaterialThin, and the volume's absorption
// coefficient -ln(colour) / distance per channel.
void set_principled_layers(MaterialParams& p, Material& m, const PrincipledLayers& l);

// Fills the material's params for its kind (alphas already set, eta/k or f0 for
// conductors): the compensation factors, the internal reflectance, and the tables,
// appended to `tables` (the shared ones once).
void prepare_microfacet(const Material& m, MaterialParams& p, std::vector<float>& tables, SharedTables& shared);

}  // namespace wt

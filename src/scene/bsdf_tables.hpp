// The microfacet kinds' tables (bsdfs/energy.hpp), built on the host from the same
// BSDF code the renderer runs, with the same deterministic points every time, so
// that every backend reads the same numbers.
#pragma once

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

// Fills the material's params for its kind (alphas already set, eta/k or f0 for
// conductors): the compensation factors, the internal reflectance, and the tables,
// appended to `tables` (the conductors' shared ones once: conductor_offsets[0]
// and [1] hold where the height-correlated and the separable one are, -1 until then).
void prepare_microfacet(const Material& m, MaterialParams& p, std::vector<float>& tables, int32_t* conductor_offsets);

}  // namespace wt

// Tables of microfacet energy, built once on the host (src/scene/bsdf_tables.cpp)
// and read here by linear interpolation. Each is sampled at kEnergySize cosines
// mu_j = j / (kEnergySize - 1); the conductors' table has a row per roughness
// r_i = i / (kEnergySize - 1).
#pragma once

#include "wavetrace/config.hpp"

namespace wt {

constexpr int kEnergySize = 32;
// The conductors' table: E(r, mu), the directional albedo of GGX with F = 1 (rows
// by roughness, columns by cosine), then E_avg(r) = 2 int E(r, mu) mu dmu by row,
// then by row the cumulative distribution over kEnergySize equal cells of mu of
// (1 - E(r, mu)) mu, the shape of the multiple-scattering lobe, which samples it.
constexpr int kConductorAverage = kEnergySize * kEnergySize;
constexpr int kConductorCdf = kConductorAverage + kEnergySize;
constexpr int kConductorTableFloats = kConductorCdf + kEnergySize * (kEnergySize + 1);
// A rough glass's: E(mu) from outside, then from inside (reflection plus
// transmission, before the radiance scaling and the tint), each one row, or a row
// per roughness where the roughness is textured (MaterialParams::table_rows).
// A rough plastic's: the coat's transmittance t(mu) from outside, by the same rows,
// then (rows by roughness only) its internal reflectance by roughness.

// Where x in [0, 1] falls in a grid of kEnergySize points: the cell and the weight.
WT_HD WT_INLINE int energy_cell(float x, float& w) {
  const float s = fminf(fmaxf(x, 0.0f), 1.0f) * (kEnergySize - 1);
  const int i = static_cast<int>(fminf(s, static_cast<float>(kEnergySize - 2)));
  w = s - static_cast<float>(i);
  return i;
}

WT_HD WT_INLINE float cosine_table(const float* t, float mu) {
  float w;
  const int j = energy_cell(mu, w);
  return (1.0f - w) * t[j] + w * t[j + 1];
}

// A table of `rows` rows of kEnergySize cosines each: one row, or kEnergySize rows
// by roughness r_i = i / (kEnergySize - 1), read bilinearly.
WT_HD WT_INLINE float rows_table(const float* t, int rows, float roughness, float mu) {
  if (rows <= 1) return cosine_table(t, mu);
  float w;
  const int i = energy_cell(roughness, w);
  return (1.0f - w) * cosine_table(t + i * kEnergySize, mu) + w * cosine_table(t + (i + 1) * kEnergySize, mu);
}

WT_HD WT_INLINE float conductor_energy(const float* t, float roughness, float mu) {
  return rows_table(t, kEnergySize, roughness, mu);
}

WT_HD WT_INLINE float conductor_average_energy(const float* t, float roughness) {
  return cosine_table(t + kConductorAverage, roughness);
}

// The multiple-scattering lobe's sampling distribution of mu (the row nearest the
// roughness; piecewise constant over the cells): a cosine drawn from u, with its
// density in mu.
WT_HD WT_INLINE const float* conductor_cdf_row(const float* t, float roughness) {
  const int i = static_cast<int>(fminf(fmaxf(roughness, 0.0f), 1.0f) * (kEnergySize - 1) + 0.5f);
  return t + kConductorCdf + i * (kEnergySize + 1);
}

WT_HD WT_INLINE float conductor_multiple_cosine(const float* t, float roughness, float u, float& density) {
  const float* c = conductor_cdf_row(t, roughness);
  int lo = 0, hi = kEnergySize;  // c[lo] <= u < c[hi]
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    if (c[mid] <= u) lo = mid; else hi = mid;
  }
  const float width = c[lo + 1] - c[lo];
  density = width * kEnergySize;
  const float within = width > 0.0f ? (u - c[lo]) / width : 0.5f;
  return fminf((static_cast<float>(lo) + within) * (1.0f / kEnergySize), 1.0f);
}

WT_HD WT_INLINE float conductor_multiple_density(const float* t, float roughness, float mu) {
  const float* c = conductor_cdf_row(t, roughness);
  const int j = static_cast<int>(fminf(fmaxf(mu, 0.0f) * kEnergySize, static_cast<float>(kEnergySize - 1)));
  return (c[j + 1] - c[j]) * kEnergySize;
}

}  // namespace wt

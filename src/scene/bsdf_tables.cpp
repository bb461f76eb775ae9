// The microfacet tables: quasi-Monte Carlo integrals over visible normals
// (Hammersley points), which make every table the same on every run.
#include "scene/bsdf_tables.hpp"

#include <cmath>

namespace wt {
namespace {

constexpr int kNormals = 1024;  // visible normals per table entry

float radical_inverse(uint32_t bits) {
  bits = (bits << 16) | (bits >> 16);
  bits = ((bits & 0x55555555u) << 1) | ((bits & 0xaaaaaaaau) >> 1);
  bits = ((bits & 0x33333333u) << 2) | ((bits & 0xccccccccu) >> 2);
  bits = ((bits & 0x0f0f0f0fu) << 4) | ((bits & 0xf0f0f0f0u) >> 4);
  bits = ((bits & 0x00ff00ffu) << 8) | ((bits & 0xff00ff00u) >> 8);
  return static_cast<float>(bits) * 2.3283064e-10f;
}

// The grid's cosine j, kept off the horizon.
float grid_cosine(int j) { return std::fmax(static_cast<float>(j) / (kEnergySize - 1), 1e-3f); }

vec3 view_at(float mu) { return vec3(std::sqrt(std::fmax(0.0f, 1.0f - mu * mu)), 0.0f, mu); }

// The mean over visible normals seen from wo (wo.z > 0) of `weight`(wo, h).
template <class Weight>
double mean_over_normals(const Ggx& g, const vec3& wo, Weight weight) {
  double sum = 0.0;
  for (int i = 0; i < kNormals; ++i) {
    const float u1 = (static_cast<float>(i) + 0.5f) / kNormals, u2 = radical_inverse(static_cast<uint32_t>(i));
    sum += weight(wo, g.sample_visible(wo, u1, u2));
  }
  return sum / kNormals;
}

// G2 / G1 of the reflection about h, which f cos / pdf is when F = 1.
float reflected_weight(const Ggx& g, const vec3& wo, const vec3& h) {
  const vec3 wi = reflect_about(wo, h);
  return wi.z > 0.0f ? g.g2(wo, wi) / g.g1(wo) : 0.0f;
}

float refracted_weight(const Ggx& g, const vec3& wo, const vec3& h, float eta) {
  const float c = glm::dot(wo, h);
  const float cos_t = refracted_cos(c, eta);
  const vec3 wi = -wo * (1.0f / eta) + (c / eta - cos_t) * h;
  return wi.z < 0.0f ? g.g2(wo, wi) / g.g1(wo) : 0.0f;
}

template <class F>
double cosine_weighted_mean(F f) {
  constexpr int kSteps = 1024;
  double sum = 0.0;
  for (int i = 0; i < kSteps; ++i) {
    const float mu = (i + 0.5f) / kSteps;
    sum += f(mu) * mu;
  }
  return 2.0 * sum / kSteps;
}

// 2 int_0^1 table(mu) mu dmu, the table read as the renderer reads it.
float cosine_average(const float* t) {
  return static_cast<float>(cosine_weighted_mean([t](float mu) { return cosine_table(t, mu); }));
}


std::vector<float> make_conductor_table(bool separable) {
  std::vector<float> t(kConductorTableFloats);
  for (int i = 0; i < kEnergySize; ++i) {
    const float r = static_cast<float>(i) / (kEnergySize - 1);
    const Ggx g{r * r, r * r, separable};
    float* row = t.data() + i * kEnergySize;
    for (int j = 0; j < kEnergySize; ++j) {
      row[j] = g.smooth() ? 1.0f
                          : static_cast<float>(mean_over_normals(g, view_at(grid_cosine(j)), [&](const vec3& wo, const vec3& h) {
                              return reflected_weight(g, wo, h);
                            }));
    }
    t[kConductorAverage + i] = cosine_average(row);
    // The multiple-scattering lobe's shape (1 - E) mu over equal cells of mu, by
    // the midpoint of each, accumulated.
    float* cdf = t.data() + kConductorCdf + i * (kEnergySize + 1);
    double total = 0.0;
    std::vector<double> w(kEnergySize);
    for (int j = 0; j < kEnergySize; ++j) {
      const float mu = (j + 0.5f) / kEnergySize;
      w[j] = std::fmax(0.0f, 1.0f - cosine_table(row, mu)) * mu;
      total += w[j];
    }
    double run = 0.0;
    cdf[0] = 0.0f;
    for (int j = 0; j < kEnergySize; ++j) {
      run += total > 0.0 ? w[j] / total : 1.0 / kEnergySize;
      cdf[j + 1] = static_cast<float>(run);
    }
    cdf[kEnergySize] = 1.0f;
  }
  return t;
}

// The rough coat's directional albedo with Fresnel, at index eta (transmitted over
// incident), from the side wo is on.
float coat_albedo(const Ggx& g, float eta, float mu) {
  return static_cast<float>(mean_over_normals(g, view_at(mu), [&](const vec3& wo, const vec3& h) {
    return fresnel_dielectric(glm::dot(wo, h), eta) * reflected_weight(g, wo, h);
  }));
}

// The rough coat's transmittance at index eta from the side wo is on: what its
// microfacet BTDF carries through, (1 - F) G2 / G1 of the refraction about h (the
// single-scattering transmittance of the uncompensated rough glass, and of Mitsuba
// 3's roughplastic). What masking takes from the coat is lost, not passed to the base.
float coat_transmittance(const Ggx& g, float eta, float mu) {
  return static_cast<float>(mean_over_normals(g, view_at(mu), [&](const vec3& wo, const vec3& h) {
    const float f = fresnel_dielectric(glm::dot(wo, h), eta);
    return f < 1.0f ? (1.0f - f) * refracted_weight(g, wo, h, eta) : 0.0f;
  }));
}

}  // namespace

const std::vector<float>& conductor_energy_table(bool separable) {
  static const std::vector<float> correlated = make_conductor_table(false);
  static const std::vector<float> uncorrelated = make_conductor_table(true);
  return separable ? uncorrelated : correlated;
}

vec3 conductor_average_fresnel(const vec3& eta, const vec3& k, bool schlick) {
  vec3 out;
  for (int c = 0; c < 3; ++c) {
    out[c] = static_cast<float>(cosine_weighted_mean([&](float mu) {
      return schlick ? schlick_f0(mu, eta)[c] : fresnel_conductor(mu, eta[c], k[c]);
    }));
  }
  return out;
}

namespace {

// The lobe of table row i: the material's own, or roughness i / (kEnergySize - 1)
// where the table has a row per roughness.
Ggx row_ggx(const Ggx& g, int i, int rows) {
  if (rows <= 1) return g;
  const float r = static_cast<float>(i) / (kEnergySize - 1);
  return Ggx{r * r, r * r, g.separable};
}

}  // namespace

std::vector<float> glass_energy_table(float ior, const Ggx& g, int rows) {
  std::vector<float> t(2 * rows * kEnergySize);
  for (int side = 0; side < 2; ++side) {
    const float eta = side == 0 ? ior : 1.0f / ior;
    for (int i = 0; i < rows; ++i) {
      const Ggx row = row_ggx(g, i, rows);
      for (int j = 0; j < kEnergySize; ++j) {
        t[(side * rows + i) * kEnergySize + j] =
            row.smooth() ? 1.0f
                         : static_cast<float>(mean_over_normals(row, view_at(grid_cosine(j)), [&](const vec3& wo, const vec3& h) {
                             const float f = fresnel_dielectric(glm::dot(wo, h), eta);
                             return f * reflected_weight(row, wo, h) +
                                    (f < 1.0f ? (1.0f - f) * refracted_weight(row, wo, h, eta) : 0.0f);
                           }));
      }
    }
  }
  return t;
}

std::vector<float> plastic_table(float ior, const Ggx& g, int rows) {
  std::vector<float> t(rows * kEnergySize + (rows > 1 ? kEnergySize : 0));
  for (int i = 0; i < rows; ++i) {
    const Ggx row = row_ggx(g, i, rows);
    for (int j = 0; j < kEnergySize; ++j) {
      const float mu = grid_cosine(j);
      t[i * kEnergySize + j] = row.smooth() ? 1.0f - fresnel_dielectric(mu, ior) : coat_transmittance(row, ior, mu);
    }
    if (rows > 1) t[rows * kEnergySize + i] = plastic_internal_reflectance(ior, row);
  }
  return t;
}

float plastic_internal_reflectance(float ior, const Ggx& g) {
  if (g.smooth()) {
    return static_cast<float>(cosine_weighted_mean([&](float mu) { return fresnel_dielectric(mu, 1.0f / ior); }));
  }
  // 2 int R_in(mu) mu dmu, R_in the coat's reflectance from inside (total internal
  // reflection beyond the critical angle), by 128 midpoints: integrated directly,
  // not through a table, whose interpolation across the critical angle's kink
  // would read it 0.6% high.
  constexpr int kCosines = 128;
  double sum = 0.0;
  for (int j = 0; j < kCosines; ++j) {
    const float mu = (j + 0.5f) / kCosines;
    sum += mu * coat_albedo(g, 1.0f / ior, mu);
  }
  return static_cast<float>(2.0 * sum / kCosines);
}

std::vector<float> principled_table(float ior, bool separable, bool compensated) {
  std::vector<float> t(kEnergySize * kEnergySize + kEnergySize);
  const float* ct = conductor_energy_table(separable).data();
  const float f0 = ((ior - 1.0f) / (ior + 1.0f)) * ((ior - 1.0f) / (ior + 1.0f));
  const float f_avg = f0 + (1.0f - f0) / 21.0f;
  for (int i = 0; i < kEnergySize; ++i) {
    const float r = static_cast<float>(i) / (kEnergySize - 1);
    const Ggx g{r * r, r * r, separable};
    float* row = t.data() + i * kEnergySize;
    const float e_avg = conductor_average_energy(ct, r);
    for (int j = 0; j < kEnergySize; ++j) {
      const float mu = grid_cosine(j);
      if (g.smooth()) {
        row[j] = schlick_f0(mu, vec3(f0)).x;
        continue;
      }
      double e = mean_over_normals(g, view_at(mu), [&](const vec3& wo, const vec3& h) {
        return schlick_f0(glm::dot(wo, h), vec3(f0)).x * reflected_weight(g, wo, h);
      });
      // The multiple-scattering lobe returns scale (1 - E(mu_o)) (1 - E_avg).
      if (compensated) e += conductor_multiple_scale(vec3(f_avg), e_avg).x * (1.0f - conductor_energy(ct, r, mu)) * (1.0f - e_avg);
      row[j] = static_cast<float>(e);
    }
    t[kEnergySize * kEnergySize + i] = cosine_average(row);
  }
  return t;
}

void set_principled_layers(MaterialParams& p, Material& m, const PrincipledLayers& l) {
  p.clearcoat = l.clearcoat;
  p.coat_alpha = l.clearcoat_roughness * l.clearcoat_roughness;
  p.coat_normal_strength = l.clearcoat_normal_strength;
  p.transmission = l.transmission;
  p.attenuation = vec3(0.0f);
  if (l.transmission > 0.0f && l.thin) m.flags |= kMaterialThin;
  if (l.transmission > 0.0f && !l.thin && l.attenuation_distance > 0.0f) {
    // A channel of colour 0 absorbs all of it: as colour 1e-30 does over the distance.
    for (int c = 0; c < 3; ++c) {
      p.attenuation[c] = -std::log(std::fmax(l.attenuation_color[c], 1e-30f)) / l.attenuation_distance;
    }
  }
}

void prepare_microfacet(const Material& m, MaterialParams& p, std::vector<float>& tables, SharedTables& shared) {
  int32_t* conductor_offsets = shared.conductor;
  const bool separable = (m.flags & kMaterialSeparable) != 0;
  const Ggx g{p.ax, p.ay, separable};
  // A textured roughness can be any below the material's: its tables get a row per roughness.
  const int rows = p.roughness_texture >= 0 && m.kind != MaterialKind::Conductor && m.kind != MaterialKind::Principled
                       ? kEnergySize
                       : 1;
  p.table_rows = rows;
  const bool rough = !g.smooth();
  const bool compensated = (m.flags & kMaterialCompensated) != 0 && rough;
  auto append = [&tables](const std::vector<float>& t) {
    const int32_t at = static_cast<int32_t>(tables.size());
    tables.insert(tables.end(), t.begin(), t.end());
    return at;
  };
  p.table = -1;
  p.fresnel_average = vec3(0.0f);
  switch (m.kind) {
    case MaterialKind::Conductor:
      if (compensated) {
        if (conductor_offsets[separable] < 0) conductor_offsets[separable] = append(conductor_energy_table(separable));
        p.table = conductor_offsets[separable];
        p.fresnel_average = conductor_average_fresnel(p.eta, p.k, (m.flags & kMaterialSchlick) != 0);
      }
      break;
    case MaterialKind::Glass:
      if (compensated && !(m.flags & kMaterialThin)) p.table = append(glass_energy_table(m.ior, g, rows));
      break;
    case MaterialKind::Principled: {
      // Its glossy lobes are Schlick conductors' (principled.hpp), compensated by
      // the conductors' tables (metal_table); the base is weighed by the layer's.
      // (Read uncompensated too: a tinted specular layer's albedo is moved towards
      // the conductors' single scattering at f0 = 1.)
      const bool compensate = (m.flags & kMaterialCompensated) != 0;
      if (conductor_offsets[separable] < 0) conductor_offsets[separable] = append(conductor_energy_table(separable));
      p.metal_table = conductor_offsets[separable];
      auto layer = [&](float ior) {
        const auto key = std::make_tuple(ior, separable, compensate);
        auto found = shared.principled.find(key);
        if (found == shared.principled.end()) {
          found = shared.principled.emplace(key, append(principled_table(ior, separable, compensate))).first;
        }
        return found->second;
      };
      p.table = layer(m.ior);
      // The clear coat: a layer of index 1.5.
      p.coat_table = p.clearcoat > 0.0f ? layer(1.5f) : -1;
      // A volume's share is glass, compensated by its tables with a row per
      // roughness (a texture may set it), shared by index.
      p.glass_table = -1;
      if (p.transmission > 0.0f && !(m.flags & kMaterialThin) && compensate) {
        const auto key = std::make_tuple(m.ior, separable);
        auto found = shared.glass.find(key);
        if (found == shared.glass.end()) {
          found = shared.glass.emplace(key, append(glass_energy_table(m.ior, Ggx{1.0f, 1.0f, separable}, kEnergySize))).first;
        }
        p.glass_table = found->second;
      }
      break;
    }
    case MaterialKind::Plastic:
      if (rough) p.table = append(plastic_table(m.ior, g, rows));
      p.internal = plastic_internal_reflectance(m.ior, g);
      // A metallic plastic's metal uses the conductors' tables (its F_avg is formed
      // at the hit, from the albedo there).
      p.metal_table = -1;
      if (compensated && p.metallic > 0.0f) {
        if (conductor_offsets[separable] < 0) conductor_offsets[separable] = append(conductor_energy_table(separable));
        p.metal_table = conductor_offsets[separable];
      }
      break;
    default:
      break;
  }
}

}  // namespace wt

// Importance sampling from tabulated densities: a piecewise-constant distribution
// over [0, 1) (1D), one over [0, 1)^2 (2D: rows, then a column within the row), and
// on top of them the directions of a latitude-longitude environment image, drawn
// with a density per solid angle that follows the image's luminance.
//
// The tables are plain arrays reached through pointers, as SceneView reaches the
// scene's, so the same code reads host memory on the CPU and global memory on the
// GPU. They are built on the host (src/scene/environment_distribution.hpp).
//
// Every CDF here is a strictly increasing float array: cdf[0] = 0, cdf[n] = 1, and
// cdf[i] < cdf[i + 1] for every cell. The densities are read from the widths of
// those float cells (not from the weights they were built from), so pdf() is the
// density the sampler draws from, and no cell has density 0.
#pragma once

#include "wavetrace/mutant.hpp"
#include "wavetrace/sampling.hpp"
#include "wavetrace/sky.hpp"

namespace wt {

// The largest float below 1: where a continuous sample in [0, 1) is clamped.
constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

struct Sample1D {
  float x;        // in [0, 1), inside cell `index` (up to float rounding at its edges)
  float pdf;      // the density at x with respect to x: count * (cdf[index + 1] - cdf[index])
  int32_t index;  // the cell, in [0, count)
};

// A piecewise-constant density over [0, 1) in `count` equal cells; cell i holds the
// probability cdf[i + 1] - cdf[i] (cdf has count + 1 entries).
struct PiecewiseConstant1D {
  const float* cdf;
  int32_t count;

  // The cell i with cdf[i] <= u < cdf[i + 1], by binary search (u in [0, 1)).
  WT_HD int32_t find_cell(float u) const {
    int32_t lo = 0, hi = count;  // cdf[lo] <= u < cdf[hi]
    while (hi - lo > 1) {
      const int32_t mid = lo + (hi - lo) / 2;
      if (cdf[mid] <= u)
        lo = mid;
      else
        hi = mid;
    }
    return lo;
  }

  WT_HD float cell_pdf(int32_t i) const { return static_cast<float>(count) * (cdf[i + 1] - cdf[i]); }

  // The cell that holds x (x outside [0, 1) is clamped to the first or last cell).
  WT_HD int32_t cell_of(float x) const {
    const int32_t i = static_cast<int32_t>(x * static_cast<float>(count));
    return i < 0 ? 0 : (i >= count ? count - 1 : i);
  }

  WT_HD float pdf(float x) const { return cell_pdf(cell_of(x)); }

  // u in [0, 1) -> x distributed with density pdf(x): the cell by the CDF, then the
  // place within the cell linearly from where u falls between its two CDF values.
  WT_HD Sample1D sample(float u) const {
    const int32_t i = find_cell(u);
    const float width = cdf[i + 1] - cdf[i];
    const float offset = fminf(fmaxf((u - cdf[i]) / width, 0.0f), kOneMinusEpsilon);
    const float x = fminf((static_cast<float>(i) + offset) / static_cast<float>(count), kOneMinusEpsilon);
    return Sample1D{x, static_cast<float>(count) * width, i};
  }
};

struct Sample2D {
  float u, v;      // in [0, 1)^2: u across the columns, v down the rows
  float pdf;       // the density at (u, v) with respect to (u, v)
  int32_t column;  // the cell: column in [0, columns), row in [0, rows)
  int32_t row;
};

// A piecewise-constant density over [0, 1)^2 on a grid of columns x rows cells: the
// marginal over rows (v), then per row the conditional over its columns (u).
struct PiecewiseConstant2D {
  const float* marginal_cdf;     // rows + 1 entries
  const float* conditional_cdf;  // rows x (columns + 1) entries, row after row
  int32_t columns, rows;

  WT_HD PiecewiseConstant1D marginal() const { return PiecewiseConstant1D{marginal_cdf, rows}; }
  WT_HD PiecewiseConstant1D conditional(int32_t row) const {
    return PiecewiseConstant1D{conditional_cdf + static_cast<size_t>(row) * (columns + 1), columns};
  }

  // The density of cell (column, row) with respect to (u, v): marginal x conditional.
  WT_HD float cell_pdf(int32_t column, int32_t row) const {
    return marginal().cell_pdf(row) * conditional(row).cell_pdf(column);
  }

  WT_HD float pdf(float u, float v) const {
    const int32_t row = marginal().cell_of(v);
    return cell_pdf(conditional(row).cell_of(u), row);
  }

  // u_row picks the row (v), u_column the column within it (u).
  WT_HD Sample2D sample(float u_row, float u_column) const {
    const Sample1D r = marginal().sample(u_row);
    const Sample1D c = conditional(r.index).sample(u_column);
    return Sample2D{c.x, r.x, r.pdf * c.pdf, c.index, r.index};
  }
};

// ---------------------------------------------------------------------------------
// The environment sky's directions.
//
// Only EnvironmentMapping::LatLong has a table. The angular map and the mirror ball
// would need the Jacobian of those mappings (and the mirror ball's corners lie
// outside the disc); light sampling draws their directions uniformly over the
// sphere instead (sample_sky_direction below). For them, and for an empty table,
// sample_environment returns pdf 0 (no sample) and environment_pdf returns 0.
//
// A LatLong image of W x H texels covers (u, v) in [0, 1)^2, texel (x, y) the cell
// [x/W, (x+1)/W) x [y/H, (y+1)/H) (texel centres at half-integers, as sample_image
// has them). With phi = 2 pi u and theta = pi v, the direction in the image's frame
// is e = (sin theta sin phi, cos theta, -sin theta cos phi), whose lookup is
// Sky::environment_uv's u and v. The area element is d omega = 2 pi^2 sin theta du dv,
// so a density p_uv over (u, v) is p_uv / (2 pi^2 sin theta) per solid angle. The
// host builds the table with cell weights luminance x sin(theta) (the luminance
// floored: src/scene/environment_distribution.hpp), which makes the density per
// solid angle follow the luminance.

struct EnvironmentSample {
  vec3 direction;  // world space, unit up to rounding
  float pdf;       // per solid angle; 0: no sample (skip it): v = 0 exactly (the pole, where
                   // sin theta is 0: u_row = 0), or a mapping that is not sampled
  vec2 uv;         // in the image: Sky::environment_uv(direction) up to rounding
  int32_t column;  // the texel the direction was drawn in
  int32_t row;
};

// sin(pi v) for v in [0, 1], accurate near both poles (kPi is not pi, so
// sinf(kPi * v) would be slightly negative at v = 1).
WT_HD WT_INLINE float sin_pi(float v) { return sinf(kPi * fminf(v, 1.0f - v)); }

// Turning the image's frame into the world: the inverse of the turn that
// Sky::environment_uv applies before its lookup.
WT_HD WT_INLINE vec3 environment_to_world(const Sky& sky, const vec3& e) {
  return vec3(sky.turn_cos * e.x + sky.turn_sin * e.z, e.y, -sky.turn_sin * e.x + sky.turn_cos * e.z);
}

// A direction toward the environment of `sky` (LatLong), drawn from two uniforms
// with the table's density. The pdf does not include the sky's intensity or radiance.
WT_HD WT_INLINE EnvironmentSample sample_environment(const Sky& sky, const PiecewiseConstant2D& table,
                                                     float u_row, float u_column) {
  if (sky.mapping != EnvironmentMapping::LatLong || table.rows == 0)
    return EnvironmentSample{vec3(0.0f, 1.0f, 0.0f), 0.0f, vec2(0.0f), 0, 0};
  const Sample2D s = table.sample(u_row, u_column);
  const float v = WT_MUTANT(EnvironmentRowShifted) ? fminf(s.v + 1.0f / table.rows, 1.0f) : s.v;
  const float phi = 2.0f * kPi * s.u;
  const float sin_theta = sin_pi(v);
  const float cos_theta = cosf(kPi * v);
  const vec3 e(sin_theta * sinf(phi), cos_theta, -sin_theta * cosf(phi));
  const float pdf = sin_theta > 0.0f ? s.pdf / (2.0f * kPi * kPi * sin_theta) : 0.0f;
  return EnvironmentSample{environment_to_world(sky, e), pdf, vec2(s.u, v), s.column, s.row};
}

// The density per solid angle with which sample_environment draws `unit_dir`
// (world space), for multiple importance sampling: a direction found by another
// sampler (a BSDF's) looked up in the same cell as Sky::environment_uv looks it up.
// 0 at the poles exactly (as sample_environment reports them), positive elsewhere.
WT_HD WT_INLINE float environment_pdf(const Sky& sky, const PiecewiseConstant2D& table, const vec3& unit_dir) {
  if (sky.mapping != EnvironmentMapping::LatLong || table.rows == 0) return 0.0f;
  const vec2 uv = sky.environment_uv(unit_dir);
  // The turn is about +y, so sin theta is the same in both frames; from x and z it
  // keeps its precision near the poles, where acos(y) loses it.
  const float sin_theta = sqrtf(unit_dir.x * unit_dir.x + unit_dir.z * unit_dir.z);
  if (sin_theta == 0.0f) return 0.0f;
  // environment_uv's u is in (-1/2, 1/2]: wrapped as sample_image wraps it.
  return table.pdf(uv.x - floorf(uv.x), uv.y) / (2.0f * kPi * kPi * sin_theta);
}

// ---------------------------------------------------------------------------------
// The sky as a light. Where the scene samples its sky (SceneView::sky_light_pick() >
// 0: src/scene/scene_bvh.cpp says which skies), light sampling draws directions from
// the environment's table where it has one (a LatLong environment), and uniformly
// over the sphere otherwise (a uniform sky, and the angular and mirror-ball maps,
// which have no table). sky_direction_pdf is the density of both for MIS.

struct SkyDirection {
  vec3 dir;   // world space, unit up to rounding
  float pdf;  // per solid angle; 0: no sample
};

WT_HD WT_INLINE SkyDirection sample_sky_direction(const Sky& sky, const PiecewiseConstant2D& table, float u1,
                                                  float u2) {
  if (table.rows > 0) {
    const EnvironmentSample s = sample_environment(sky, table, u1, u2);
    return SkyDirection{s.direction, s.pdf};
  }
  return SkyDirection{unit_sphere_point(u1, u2), 1.0f / (4.0f * kPi)};
}

WT_HD WT_INLINE float sky_direction_pdf(const Sky& sky, const PiecewiseConstant2D& table, const vec3& unit_dir) {
  return table.rows > 0 ? environment_pdf(sky, table, unit_dir) : 1.0f / (4.0f * kPi);
}

}  // namespace wt

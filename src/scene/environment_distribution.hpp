// The tables for importance-sampling the environment sky
// (include/wavetrace/distribution.hpp), built once per scene on the host with the
// BVH (the scene holds them: Scene::environment) and read through SceneView on
// every backend.
#pragma once

#include <cstdint>
#include <vector>

#include "wavetrace/distribution.hpp"

namespace wt {

struct Image;
struct Scene;

// A texel's luminance: Rec. 709 / sRGB Y of its linear RGB.
constexpr double kLumaR = 0.2126, kLumaG = 0.7152, kLumaB = 0.0722;

// The floor on a texel's luminance, as a fraction of the image's mean luminance (per
// solid angle). The lookup is bilinear, so a black texel's cell still shows part of
// its bright neighbours' radiance; with density 0 there, a light estimate that drew
// only from this table would miss that light, and MIS needs the density of every
// direction the lookup can return to be positive. Relative to the mean, the floor
// adds at most 1/1000 of the total weight, so at most 0.1% of the samples go where
// the luminance alone would not send them. An image with no positive luminance at
// all is sampled uniformly over the sphere.
constexpr double kEnvironmentLuminanceFloor = 1e-3;

// The CDF of a piecewise-constant distribution with these cell weights (>= 0, with a
// positive finite sum), summed in double and stored in float: weights.size() + 1
// entries from 0 to 1. Where float rounding would leave a cell no width (a tiny
// weight beside a huge one), its bounds are moved apart by one float step, so every
// cell keeps a positive probability; the densities read from the float CDF
// (PiecewiseConstant1D::cell_pdf) are then what the sampler draws from. Each moved
// bound takes at most 2^-24 of probability from its neighbours: at most 1e-3 over a
// row of kMaxImageSide cells.
std::vector<float> piecewise_constant_cdf(const std::vector<double>& weights);

// The 2D table of a latitude-longitude environment image: one cell per texel, with
// weight max(luminance, floor) x sin(theta at the texel's centre row). The solid angle
// of a texel is 2 pi^2 / (W H) times the mean of sin theta over its row, which is
// sin(theta at the centre) times a factor that is the same for every row, so these
// weights make each texel's probability proportional to its (floored) luminance times
// its solid angle. Luminance that is negative or not finite counts as 0.
struct EnvironmentDistribution {
  int32_t columns = 0, rows = 0;     // the image's width and height; 0: no table
  std::vector<float> marginal_cdf;     // rows + 1
  std::vector<float> conditional_cdf;  // rows x (columns + 1)
  double luminance_floor = 0;          // the floor used, in the image's units

  bool empty() const { return rows == 0; }
  // Pointers into this struct (host memory).
  PiecewiseConstant2D view() const {
    return PiecewiseConstant2D{marginal_cdf.data(), conditional_cdf.data(), columns, rows};
  }
};

// Throws std::invalid_argument where the image has no texels or they do not match its size.
EnvironmentDistribution build_environment_distribution(const Image& image);

// The scene's: built from its environment image where its sky is an environment with
// the LatLong mapping; empty otherwise (other skies are not importance-sampled).
EnvironmentDistribution build_environment_distribution(const Scene& scene);

}  // namespace wt

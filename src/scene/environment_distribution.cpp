#include "scene/environment_distribution.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "scene/scene.hpp"

namespace wt {

std::vector<float> piecewise_constant_cdf(const std::vector<double>& weights) {
  const size_t n = weights.size();
  double total = 0.0;
  for (double w : weights) {
    if (!(w >= 0.0)) throw std::invalid_argument("piecewise_constant_cdf: a weight is negative or NaN");
    total += w;
  }
  if (n == 0 || !(total > 0.0) || !std::isfinite(total))
    throw std::invalid_argument("piecewise_constant_cdf: the weights need a positive finite sum");
  std::vector<float> cdf(n + 1);
  cdf[0] = 0.0f;
  double running = 0.0;
  // Up: each bound at least one float step above the one before ...
  for (size_t i = 1; i < n; ++i) {
    running += weights[i - 1];
    cdf[i] = std::max(static_cast<float>(running / total), std::nextafter(cdf[i - 1], 2.0f));
  }
  cdf[n] = 1.0f;
  // ... and down: each at least one step below the one after, where the way up
  // pushed bounds to 1 or past it. There are enough floats below 1 for any n an
  // image can have (kMaxImageSide), so cdf[1] stays above 0.
  for (size_t i = n - 1; i >= 1; --i) cdf[i] = std::min(cdf[i], std::nextafter(cdf[i + 1], 0.0f));
  return cdf;
}

EnvironmentDistribution build_environment_distribution(const Image& image) {
  const int w = image.width, h = image.height;
  if (w <= 0 || h <= 0 || image.texels.size() != static_cast<size_t>(w) * h * 4)
    throw std::invalid_argument("build_environment_distribution: the image has no texels or a wrong size");
  const double pi = 3.14159265358979323846;

  std::vector<double> luminance(static_cast<size_t>(w) * h), sin_theta(static_cast<size_t>(h));
  double weighted = 0.0, solid_angle = 0.0;  // sums of luminance x sin theta and of sin theta
  for (int y = 0; y < h; ++y) {
    sin_theta[y] = std::sin(pi * (y + 0.5) / h);
    for (int x = 0; x < w; ++x) {
      const float* t = &image.texels[4 * (static_cast<size_t>(y) * w + x)];
      const double l = kLumaR * t[0] + kLumaG * t[1] + kLumaB * t[2];
      luminance[static_cast<size_t>(y) * w + x] = std::isfinite(l) && l > 0.0 ? l : 0.0;
      weighted += luminance[static_cast<size_t>(y) * w + x] * sin_theta[y];
      solid_angle += sin_theta[y];
    }
  }
  const double mean = weighted / solid_angle;
  // A black image: any positive floor makes every texel equal, uniform per solid angle.
  const double floor = mean > 0.0 && std::isfinite(mean) ? kEnvironmentLuminanceFloor * mean : 1.0;

  EnvironmentDistribution d;
  d.columns = w;
  d.rows = h;
  d.luminance_floor = floor;
  d.conditional_cdf.reserve(static_cast<size_t>(h) * (w + 1));
  std::vector<double> row_weights(static_cast<size_t>(h)), cells(static_cast<size_t>(w));
  for (int y = 0; y < h; ++y) {
    double sum = 0.0;
    // sin theta is the same along a row: it weighs the row, not its columns.
    for (int x = 0; x < w; ++x) sum += cells[x] = std::max(luminance[static_cast<size_t>(y) * w + x], floor);
    row_weights[y] = sum * sin_theta[y];
    const std::vector<float> row = piecewise_constant_cdf(cells);
    d.conditional_cdf.insert(d.conditional_cdf.end(), row.begin(), row.end());
  }
  d.marginal_cdf = piecewise_constant_cdf(row_weights);
  return d;
}

EnvironmentDistribution build_environment_distribution(const Scene& scene) {
  const Sky& sky = scene.sky;
  if (sky.kind != SkyKind::Environment || sky.mapping != EnvironmentMapping::LatLong || sky.image < 0 ||
      static_cast<size_t>(sky.image) >= scene.images.size())
    return EnvironmentDistribution{};
  return build_environment_distribution(scene.images[static_cast<size_t>(sky.image)]);
}

}  // namespace wt

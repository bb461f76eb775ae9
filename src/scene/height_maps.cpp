#include "scene/height_maps.hpp"

#include <cmath>

#include "wavetrace/texture.hpp"

namespace wt {

float channel_of(const float* texel, HeightChannel channel) {
  switch (channel) {
    case HeightChannel::Luminance: return luminance(vec3(texel[0], texel[1], texel[2]));
    case HeightChannel::Red: return texel[0];
    case HeightChannel::Green: return texel[1];
    case HeightChannel::Blue: return texel[2];
    case HeightChannel::Alpha: return texel[3];
  }
  return 0.0f;
}

namespace {

// h's derivative at index i of n along one axis, per unit of the coordinate (n
// texels), from the texels either side (get(j)) as the wrap finds them: a
// neighbour the wrap puts back on i (an edge of Clamp or Mirror) is no step.
template <class Get>
float derivative(int i, int n, Wrap wrap, const Get& get) {
  const int lo = wrap_index(i - 1, n, wrap), hi = wrap_index(i + 1, n, wrap);
  const int steps = (lo != i ? 1 : 0) + (hi != i ? 1 : 0);
  return steps == 0 ? 0.0f : (get(hi) - get(lo)) * static_cast<float>(n) / static_cast<float>(steps);
}

}  // namespace

Image height_gradient(const Image& height, HeightChannel channel, Wrap wrap_u, Wrap wrap_v) {
  Image out;
  out.path = height.path;
  out.width = height.width;
  out.height = height.height;
  const int w = height.width, h = height.height;
  std::vector<float> heights(static_cast<size_t>(w) * h);
  for (size_t i = 0; i < heights.size(); ++i) heights[i] = channel_of(&height.texels[4 * i], channel);
  out.texels.assign(heights.size() * 4, 0.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t row = static_cast<size_t>(y) * w;
      float* t = &out.texels[4 * (row + x)];
      t[0] = derivative(x, w, wrap_u, [&](int j) { return heights[row + j]; });
      t[1] = derivative(y, h, wrap_v, [&](int j) { return heights[static_cast<size_t>(j) * w + x]; });
      t[3] = 1.0f;
    }
  }
  return out;
}

bool reads_as_normal_map(const Image& image) {
  const size_t n = static_cast<size_t>(image.width) * image.height;
  if (n == 0) return false;
  bool grey = true;
  size_t vectors = 0;
  for (size_t i = 0; i < n; ++i) {
    const float* c = &image.texels[4 * i];
    grey = grey && std::fabs(c[0] - c[1]) <= 2.0f / 255.0f && std::fabs(c[1] - c[2]) <= 2.0f / 255.0f;
    const float x = 2.0f * c[0] - 1.0f, y = 2.0f * c[1] - 1.0f, z = 2.0f * c[2] - 1.0f;
    const float length = std::sqrt(x * x + y * y + z * z);
    if (length >= 0.7f && length <= 1.3f && z >= -0.02f) ++vectors;
  }
  return !grey && static_cast<double>(vectors) >= 0.99 * static_cast<double>(n);
}

}  // namespace wt

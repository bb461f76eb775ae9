#include "scene/image_mips.hpp"

#include <algorithm>

namespace wt {

namespace {

// The columns (or rows) of level n (of `above` texels) that texel i of the next
// level, of `below` texels, averages: [first, last).
void span(int i, int above, int below, int& first, int& last) {
  first = std::min(2 * i, above - 1);
  last = i == below - 1 ? above : std::min(2 * i + 2, above);
}

}  // namespace

void build_mip_levels(Image& im) {
  if (im.levels > 1 || im.width < 1 || im.height < 1 || (im.width == 1 && im.height == 1)) return;
  // The levels' sizes and rows are texture.hpp's layout (mip_level_shape), which the
  // lookups read.
  ImageView view{0, im.texels.data(), im.width, im.height, 0, nullptr, 1};
  int w = im.width, h = im.height, row = 0;
  while (w > 1 || h > 1) mip_level_shape(view, view.levels++, w, h, row);
  const int pitch = std::max(im.width / 2, 1);
  im.mip_texels.assign(static_cast<size_t>(pitch) * (row + h) * 4, 0.0f);
  const float* above = im.texels.data();
  int above_pitch = im.width, aw = im.width, ah = im.height;
  for (int l = 1; l < view.levels; ++l) {
    mip_level_shape(view, l, w, h, row);
    float* level = im.mip_texels.data() + static_cast<size_t>(row) * pitch * 4;
    for (int y = 0; y < h; ++y) {
      int y0, y1;
      span(y, ah, h, y0, y1);
      for (int x = 0; x < w; ++x) {
        int x0, x1;
        span(x, aw, w, x0, x1);
        double sum[4] = {0, 0, 0, 0};
        for (int yy = y0; yy < y1; ++yy) {
          for (int xx = x0; xx < x1; ++xx) {
            const float* t = above + (static_cast<size_t>(yy) * above_pitch + xx) * 4;
            for (int c = 0; c < 4; ++c) sum[c] += t[c];
          }
        }
        const double count = static_cast<double>(y1 - y0) * (x1 - x0);
        float* out = level + (static_cast<size_t>(y) * pitch + x) * 4;
        for (int c = 0; c < 4; ++c) out[c] = static_cast<float>(sum[c] / count);
      }
    }
    above = level;
    above_pitch = pitch;
    aw = w;
    ah = h;
  }
  im.levels = view.levels;
}

void build_texture_mips(Scene& scene) {
  for (const Texture& t : scene.textures) {
    if (t.kind == TextureKind::Image && t.filter == Filter::Trilinear && t.image >= 0 &&
        static_cast<size_t>(t.image) < scene.images.size()) {
      build_mip_levels(scene.images[static_cast<size_t>(t.image)]);
    }
  }
}

}  // namespace wt

// Bump (height) maps: the texture of a height image's derivatives that bsdf.hpp's
// bumped_normal reads, and the test that tells a tangent-space normal map written
// where a height map is expected (MTL's bump, which exporters also fill with normal
// maps) from a height map.
#pragma once

#include "scene/scene.hpp"

namespace wt {

// The height's channel of a height image: luminance (Rec. 709's weights of the
// linear values), or one of its channels.
enum class HeightChannel { Luminance, Red, Green, Blue, Alpha };

// That channel of an RGBA texel (four floats).
float channel_of(const float* texel, HeightChannel channel);

// The image of `height`'s derivatives, texel (x, y) holding (dh/du, dh/dv, 0, 1) in
// height units per unit of the texture's coordinates (u across the image's width, v
// down its rows): central differences of the texels either side, times the image's
// width (height), one-sided at an edge that the wrap does not join to the other
// (Clamp, Mirror), 0 along an axis of one texel. Linearly interpolated, as a texture
// is, it is the height's gradient smoothed over a texel; its mip levels average it,
// which differentiation commutes with.
Image height_gradient(const Image& height, HeightChannel channel, Wrap wrap_u, Wrap wrap_v);

// Whether an image reads as a tangent-space normal map rather than heights: it is
// not grey (a texel whose channels differ by more than 2/255), and at least 99% of
// its texels hold a vector 2c - 1 of length 0.7 to 1.3 (8 bits, filtering and
// compression shorten them) whose z (blue: out of the surface) is at least -0.02.
// A grey image is heights; so is a colour image of other texels.
bool reads_as_normal_map(const Image& image);

}  // namespace wt

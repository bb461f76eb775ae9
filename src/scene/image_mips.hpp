// Mip levels of an image, for the trilinear lookups of texture.hpp: each level
// half the one before, rounded down and at least one texel, down to 1 x 1.
#pragma once

#include "scene/scene.hpp"

namespace wt {

// Fills im's mip levels (Image::levels, mip_texels), once: texel (x, y) of a level
// is the mean of the texels 2x..2x+1 by 2y..2y+1 of the level above, and along an
// odd side the last texel also takes the one left over, so that every texel of a
// level counts in exactly one of the next. A level of a power-of-two image keeps
// its mean exactly (to rounding); a constant image stays constant at every level.
void build_mip_levels(Image& im);

// Builds the mip levels of every image that a trilinear image texture reads.
void build_texture_mips(Scene& scene);

}  // namespace wt

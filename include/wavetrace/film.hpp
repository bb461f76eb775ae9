// From linear radiance to display values.
#pragma once

#include "wavetrace/config.hpp"

namespace wt {

// Gamma 2 (square root), clamped to [0, 1]: the reference renderer's output curve.
WT_HD WT_INLINE float encode_gamma2(float linear) { return sqrtf(fminf(fmaxf(linear, 0.0f), 1.0f)); }

// The sRGB transfer curve, clamped to [0, 1].
WT_HD WT_INLINE float encode_srgb(float linear) {
  float x = fminf(fmaxf(linear, 0.0f), 1.0f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * powf(x, 1.0f / 2.4f) - 0.055f;
}

WT_HD WT_INLINE float decode_srgb(float encoded) {
  return encoded <= 0.04045f ? encoded / 12.92f : powf((encoded + 0.055f) / 1.055f, 2.4f);
}

}  // namespace wt

// The radiance of every ray that leaves the scene.
#pragma once

#include "wavetrace/config.hpp"

namespace wt {

enum class SkyKind : uint32_t { Gradient = 0, Uniform = 1 };

struct Sky {
  SkyKind kind;
  vec3 horizon;  // Gradient: colour at dir.y = -1; Uniform: the radiance
  vec3 zenith;   // Gradient: colour at dir.y = +1

  WT_HD vec3 radiance(const vec3& unit_dir) const {
    if (kind == SkyKind::Uniform) return horizon;
    float t = 0.5f * (unit_dir.y + 1.0f);
    return (1.0f - t) * horizon + t * zenith;
  }
};

}  // namespace wt

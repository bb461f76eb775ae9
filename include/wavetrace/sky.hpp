// The radiance of every ray that leaves the scene: a gradient, a uniform radiance,
// or an environment image around the scene (docs/scene-format.md).
#pragma once

#include "wavetrace/texture.hpp"

namespace wt {

enum class SkyKind : uint32_t { Gradient = 0, Uniform = 1, Environment = 2 };

// How an environment image covers the sphere of directions (e: the direction in the
// image's own frame, +y up).
//  LatLong:    u = atan2(e.x, -e.z) / 2 pi (wrapped), v = acos(e.y) / pi: the
//              equirectangular panorama, -z at its left and right edges, +y at the top.
//  Angular:    the light-probe "angular map": a disc whose centre looks along -z,
//              radius proportional to the angle from -z, +z on the rim.
//  MirrorBall: a mirror ball photographed along -z: the pixel at disc position (x, y)
//              shows the direction reflected off the normal (x, y, sqrt(1 - x^2 - y^2)),
//              +z at the centre (the format of scenes/textures/probe_*.png).
enum class EnvironmentMapping : uint32_t { LatLong = 0, Angular = 1, MirrorBall = 2 };

struct Sky {
  SkyKind kind;
  vec3 horizon;  // Gradient: colour at dir.y = -1; Uniform: the radiance
  vec3 zenith;   // Gradient: colour at dir.y = +1
  // Environment: the image (an index into the scene's images), its mapping, a
  // factor on its values, and its turn about +y (as cos and sin of the angle).
  int32_t image = -1;
  EnvironmentMapping mapping = EnvironmentMapping::LatLong;
  float intensity = 1.0f;
  float turn_cos = 1.0f, turn_sin = 0.0f;

  // Where `unit_dir` looks in the environment image.
  WT_HD vec2 environment_uv(const vec3& unit_dir) const {
    // The environment turned by the angle about +y shows at d what the image holds
    // at d turned back.
    const vec3 e(turn_cos * unit_dir.x - turn_sin * unit_dir.z, unit_dir.y,
                 turn_sin * unit_dir.x + turn_cos * unit_dir.z);
    switch (mapping) {
      case EnvironmentMapping::LatLong:
        return vec2(atan2f(e.x, -e.z) * (0.5f / kPi), acosf(fminf(fmaxf(e.y, -1.0f), 1.0f)) * (1.0f / kPi));
      case EnvironmentMapping::Angular: {
        const float sideways = sqrtf(e.x * e.x + e.y * e.y);
        if (sideways == 0.0f) return e.z <= 0.0f ? vec2(0.5f, 0.5f) : vec2(1.0f, 0.5f);
        const float r = acosf(fminf(fmaxf(-e.z, -1.0f), 1.0f)) * (1.0f / kPi) / sideways;
        return vec2(0.5f + 0.5f * e.x * r, 0.5f - 0.5f * e.y * r);
      }
      case EnvironmentMapping::MirrorBall: {
        const vec3 h(e.x, e.y, e.z + 1.0f);  // the ball's normal, before normalising
        const float len = sqrtf(h.x * h.x + h.y * h.y + h.z * h.z);
        if (len == 0.0f) return vec2(1.0f, 0.5f);  // straight away from the camera: the rim
        return vec2(0.5f + 0.5f * h.x / len, 0.5f - 0.5f * h.y / len);
      }
    }
    return vec2(0.0f);
  }

  // images: the scene's images (read by Environment only).
  WT_HD vec3 radiance(const vec3& unit_dir, const ImageView* images) const {
    if (kind == SkyKind::Uniform) return horizon;
    if (kind == SkyKind::Environment) {
      const vec2 uv = environment_uv(unit_dir);
      return intensity * sample_image(images[image], uv.x, uv.y);
    }
    float t = 0.5f * (unit_dir.y + 1.0f);
    return (1.0f - t) * horizon + t * zenith;
  }
};

}  // namespace wt

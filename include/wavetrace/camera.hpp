// Thin-lens camera. Row 0 of the image is the top; x grows to the right in a
// right-handed frame (so the scene is not mirrored).
#pragma once

#include "wavetrace/ray.hpp"
#include "wavetrace/rng.hpp"
#include "wavetrace/sampling.hpp"

namespace wt {

struct CameraSpec {
  vec3 look_from{0, 0, 1};
  vec3 look_at{0, 0, 0};
  vec3 up{0, 1, 0};
  float vfov_degrees = 40.0f;
  float aperture = 0.0f;
  float focus_distance = -1.0f;  // <= 0: distance from look_from to look_at
};

struct Camera {
  vec3 origin;
  vec3 upper_left;  // the focus-plane point seen through the top-left image corner
  vec3 horizontal;  // focus-plane extent of the image, left to right
  vec3 vertical;    // focus-plane extent of the image, top to bottom
  vec3 u, v;        // lens basis
  float lens_radius;
  float pixel_spread;  // the angle one pixel subtends at the centre of the view (radians)

  static Camera make(const CameraSpec& s, int width, int height) {
    vec3 w = glm::normalize(s.look_from - s.look_at);
    vec3 u = glm::normalize(glm::cross(s.up, w));
    vec3 v = glm::cross(w, u);
    float focus = s.focus_distance > 0 ? s.focus_distance : glm::length(s.look_from - s.look_at);
    float half_h = tanf(s.vfov_degrees * kPi / 360.0f);
    float half_w = half_h * static_cast<float>(width) / static_cast<float>(height);
    Camera c;
    c.origin = s.look_from;
    c.horizontal = 2.0f * half_w * focus * u;
    c.vertical = -2.0f * half_h * focus * v;
    c.upper_left = s.look_from - focus * w - 0.5f * c.horizontal - 0.5f * c.vertical;
    c.u = u;
    c.v = v;
    c.lens_radius = 0.5f * s.aperture;
    c.pixel_spread = 2.0f * half_h / static_cast<float>(height);
    return c;
  }

  // The primary ray through pixel (x, y), jittered inside the pixel and across the lens.
  // The width of a pixel's footprint at p on a surface of unit normal ng reached
  // along `dir` (unit): the pixel's spread at p's distance from the camera, stretched
  // by the surface's slant (cos kept above 0.01). pbrt-v4 approximates every hit's
  // footprint from the camera so, camera rays' and the bounces' alike.
  WT_HD float footprint(const vec3& p, const vec3& ng, const vec3& dir) const {
    const vec3 d = p - origin;
    return pixel_spread * sqrtf(glm::dot(d, d)) / fmaxf(fabsf(glm::dot(ng, dir)), 0.01f);
  }

  WT_HD Ray generate(int x, int y, int width, int height, const Rng& rng) const {
    float s = (static_cast<float>(x) + rng.uniform(kDimPixelX)) / static_cast<float>(width);
    float t = (static_cast<float>(y) + rng.uniform(kDimPixelY)) / static_cast<float>(height);
    vec2 lens = lens_radius * unit_disk_point(rng.uniform(kDimLensX), rng.uniform(kDimLensY));
    vec3 o = origin + lens.x * u + lens.y * v;
    vec3 target = upper_left + s * horizontal + t * vertical;
    return Ray{o, glm::normalize(target - o)};
  }
};

}  // namespace wt

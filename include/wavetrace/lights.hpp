// Sampling emitters from a shading point, and weighing two sampling strategies
// against each other: the parts of next-event estimation that know nothing of the
// scene's arrays (path.hpp puts them to work). Densities are per unit solid angle
// at the shading point.
#pragma once

#include "wavetrace/config.hpp"
#include "wavetrace/mutant.hpp"

namespace wt {

// An emitter: a primitive of an instance whose material emits (an emissive sphere,
// or one triangle of a placed mesh).
struct LightRef {
  int32_t instance;  // kSkyLight: the sky
  int32_t prim;
};

// The instance of the LightRef that stands for the sky, when the sky is sampled.
constexpr int32_t kSkyLight = -1;
// The instance of a LightRef that stands for a punctual light (its prim: the
// light's index in the scene's punctual_lights).
constexpr int32_t kPunctualLight = -2;

enum class PunctualKind : uint32_t { Point = 0, Spot = 1, Directional = 2 };

// A light of no extent, as glTF's KHR_lights_punctual defines them: a point, a spot
// (a point whose intensity fades from the inner cone to the outer by the
// extension's smooth step) or a directional light (parallel rays from infinitely
// far). No path meets one: they are reached by light sampling alone, whether or
// not the other lights are (path.hpp, sample_light).
struct PunctualLight {
  vec3 position;  // point, spot
  PunctualKind kind;
  vec3 direction;  // spot, directional: unit, the way the light travels
  float range;     // point, spot: the distance at which it has faded out (> 0), 0: none
  // Point, spot: radiant intensity, W / sr in the renderer's units (the extension's
  // candela); directional: irradiance on a surface facing it (the extension's lux).
  vec3 intensity;
  // Spot: the attenuation clamp(cos * scale + offset, 0, 1)^2 of the cosine between
  // `direction` and the direction to the lit point.
  float spot_scale, spot_offset;

  // Its power in light_power_of's units (power / pi), which picks it among the
  // scene's lights: a point's 4 pi I, a spot's outer cone's 2 pi (1 - cos) I (the
  // smooth edge within it left out), a directional light's E over the scene's
  // bounding disc of `scene_radius`.
  WT_HD float power(float scene_radius) const {
    const float mean = (intensity.x + intensity.y + intensity.z) * (1.0f / 3.0f);
    switch (kind) {
      case PunctualKind::Point: return 4.0f * mean;
      case PunctualKind::Spot: {
        const float cos_outer = -spot_offset / spot_scale;
        return 2.0f * (1.0f - cos_outer) * mean;
      }
      case PunctualKind::Directional: return mean * scene_radius * scene_radius;
    }
    return 0.0f;
  }

  // The direction (unit) from p toward the light and the distance to it (0 for a
  // directional light: infinitely far).
  WT_HD void toward(const vec3& p, vec3& dir, float& dist) const {
    if (kind == PunctualKind::Directional) {
      dir = -direction;
      dist = 0.0f;
      return;
    }
    const vec3 to = position - p;
    dist = sqrtf(glm::dot(to, to));
    dir = dist > 0.0f ? to * (1.0f / dist) : vec3(0.0f);
  }

  // The irradiance it gives, arriving along `dir` (unit, toward the light) from
  // `dist` away, on a surface facing it: I / d^2 within the cones and the range's
  // fade (the extension's max(min(1 - (d / range)^4, 1), 0)); E for a directional light.
  WT_HD vec3 irradiance(const vec3& dir, float dist) const {
    if (kind == PunctualKind::Directional) return intensity;
    if (!(dist > 0.0f)) return vec3(0.0f);
    float falloff = 1.0f / (dist * dist);
    if (range > 0.0f) {
      const float r = dist / range, r2 = r * r;
      falloff *= fmaxf(fminf(1.0f - r2 * r2, 1.0f), 0.0f);
    }
    if (kind == PunctualKind::Spot) {
      const float a = fminf(fmaxf(-glm::dot(direction, dir) * spot_scale + spot_offset, 0.0f), 1.0f);
      falloff *= a * a;
    }
    return intensity * falloff;
  }
};

// The power that picks an emitter among the scene's: its emission's mean over the
// three channels times its area (the factor pi of a diffuse emitter's power is the
// same for all and left out). The host builds the picking table from this, and the
// shading code weighs emitters it hits by it, so both see the same probabilities.
WT_HD WT_INLINE float light_power_of(const vec3& emission, float area) {
  return (emission.x + emission.y + emission.z) * (1.0f / 3.0f) * area;
}

struct LightSample {
  vec3 dir;    // unit, from the shading point toward the light
  float dist;  // along dir to the light's surface
  float pdf;   // per solid angle; 0: no sample (the point is inside the light, or sees it edge-on)
  float b1 = 0.0f, b2 = 0.0f;  // a triangle's point: the barycentric weights of corners 1 and 2
};

// Two unit vectors completing the unit vector n to a right-handed orthonormal basis
// (t, b, n), without a branch on n's direction but for its sign (Duff et al. 2017).
WT_HD WT_INLINE void orthonormal_basis(const vec3& n, vec3& t, vec3& b) {
  const float sign = copysignf(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = vec3(c, sign + n.y * n.y * a, -n.y);
}

// 1 - cos(theta_max) of the cone a sphere of radius r subtends at distance d > r,
// written so that it keeps its precision for small spheres far away (where the
// cosine is within rounding of 1): sin^2 / (1 + cos).
WT_HD WT_INLINE float cone_one_minus_cos(float r, float d) {
  const float sin2 = (r / d) * (r / d);
  return sin2 / (1.0f + sqrtf(fmaxf(0.0f, 1.0f - sin2)));
}

// The density of sample_sphere_light for any direction that meets the sphere.
WT_HD WT_INLINE float sphere_light_pdf(const vec3& center, float radius, const vec3& p) {
  const vec3 to = center - p;
  const float d = sqrtf(glm::dot(to, to));
  if (!(d > radius)) return 0.0f;
  return 1.0f / (2.0f * kPi * cone_one_minus_cos(radius, d));
}

// A direction uniform in the cone of directions from p that meet the sphere, and
// the distance to its near side. Nothing from inside the sphere or on it.
WT_HD WT_INLINE LightSample sample_sphere_light(const vec3& center, float radius, const vec3& p, float u1, float u2) {
  LightSample s{vec3(0.0f), 0.0f, 0.0f};
  const vec3 to = center - p;
  const float d = sqrtf(glm::dot(to, to));
  if (!(d > radius)) return s;
  const vec3 w = to * (1.0f / d);
  const float omc = cone_one_minus_cos(radius, d);
  const float one_minus_cos = u1 * omc;  // 1 - cos(theta), uniform in [0, 1 - cos(theta_max))
  const float cos_theta = 1.0f - one_minus_cos;
  const float sin_theta = sqrtf(fmaxf(0.0f, one_minus_cos * (2.0f - one_minus_cos)));
  const float phi = 2.0f * kPi * u2;
  vec3 t, b;
  orthonormal_basis(w, t, b);
  s.dir = glm::normalize(sin_theta * cosf(phi) * t + sin_theta * sinf(phi) * b + cos_theta * w);
  // Along dir, the sphere's near side: d cos - sqrt(r^2 - d^2 sin^2), with
  // r^2 - d^2 sin^2 = (r - d sin)(r + d sin) against cancellation.
  const float ds = d * sin_theta;
  s.dist = d * cos_theta - sqrtf(fmaxf(0.0f, (radius - ds) * (radius + ds)));
  s.pdf = 1.0f / (2.0f * kPi * omc);
  return s;
}

// The density of sample_triangle_light at the direction `dir` (unit) that meets the
// triangle (a, b, c) at distance `dist` from p: uniform by area, per solid angle.
// Both faces emit.
WT_HD WT_INLINE float triangle_light_pdf(const vec3& a, const vec3& b, const vec3& c, const vec3& dir, float dist) {
  const vec3 n = glm::cross(b - a, c - a);
  const float twice_area = sqrtf(glm::dot(n, n));
  const float cos_light = fabsf(glm::dot(n, dir)) / twice_area;
  const float projected = 0.5f * twice_area * cos_light;  // the area seen along dir
  if (!(projected > 0.0f)) return 0.0f;
  return dist * dist / projected;
}

// A point uniform by area on the triangle (a, b, c), as a direction from p, its
// distance and the density per solid angle.
WT_HD WT_INLINE LightSample sample_triangle_light(const vec3& a, const vec3& b, const vec3& c, const vec3& p,
                                                 float u1, float u2) {
  LightSample s{vec3(0.0f), 0.0f, 0.0f};
  const float su = sqrtf(u1);
  const float b0 = 1.0f - su, b1 = u2 * su;
  const vec3 q = b0 * a + b1 * b + (1.0f - b0 - b1) * c;
  s.b1 = b1;
  s.b2 = 1.0f - b0 - b1;
  const vec3 v = q - p;
  const float dist = sqrtf(glm::dot(v, v));
  if (!(dist > 0.0f)) return s;
  s.dir = v * (1.0f / dist);
  s.dist = dist;
  s.pdf = triangle_light_pdf(a, b, c, s.dir, dist);
  return s;
}

// An emitter's shape in world space, read from the scene once per use (path.hpp's
// emitter_shape): a sphere (centre `a`, `radius`) or a triangle (corners a, b, c).
// Its area weighs it in the picking table (light_power_of), its sampler draws
// points on it and its density says how likely a direction is, so the host's table
// and the shading code compute them with the same float arithmetic.
struct EmitterShape {
  vec3 a, b, c;
  float radius;  // > 0: a sphere; 0: a triangle
  bool sphere;

  WT_HD static EmitterShape of_sphere(const vec3& centre, float r) {
    return EmitterShape{centre, vec3(0.0f), vec3(0.0f), r, true};
  }
  WT_HD static EmitterShape of_triangle(const vec3& a, const vec3& b, const vec3& c) {
    return EmitterShape{a, b, c, 0.0f, false};
  }

  WT_HD float area() const {
    return sphere ? 4.0f * kPi * radius * radius : 0.5f * glm::length(glm::cross(b - a, c - a));
  }
  // The density per solid angle at p of sample(p, ...) drawing `dir` (unit), which
  // meets the shape at distance `dist`.
  WT_HD float pdf(const vec3& p, const vec3& dir, float dist) const {
    const float density = sphere ? sphere_light_pdf(a, radius, p) : triangle_light_pdf(a, b, c, dir, dist);
    return WT_MUTANT(LightPdfScaled) ? 1.05f * density : density;
  }
  WT_HD LightSample sample(const vec3& p, float u1, float u2) const {
    LightSample s = sphere ? sample_sphere_light(a, radius, p, u1, u2) : sample_triangle_light(a, b, c, p, u1, u2);
    if (WT_MUTANT(LightPdfScaled)) s.pdf *= 1.05f;
    return s;
  }
};

// The power heuristic (exponent 2): the weight of a sample drawn by the strategy of
// density f where another strategy would have drawn it with density g. The two
// weights of a direction sum to 1.
WT_HD WT_INLINE float power_heuristic(float f, float g) {
  const float f2 = f * f, g2 = g * g;
  return f2 + g2 > 0.0f ? (WT_MUTANT(MisWeightsSwapped) ? g2 : f2) / (f2 + g2) : 0.0f;
}

}  // namespace wt

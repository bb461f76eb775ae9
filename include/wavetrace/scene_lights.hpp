// A scene's lights as the path code samples them, through any scene accessor
// (geometry/geometry.hpp lists its functions): an emitter's shape in world space,
// the density with which light sampling draws a direction toward it or toward the
// sky, and the pick of one emitter by power. The host's light table
// (src/scene/scene_bvh.cpp) is built from the same shapes.
#pragma once

#include "wavetrace/distribution.hpp"
#include "wavetrace/geometry/geometry.hpp"
#include "wavetrace/lights.hpp"

namespace wt {

// Emitter (instance, prim)'s shape in world space (spheres are placed untransformed).
template <uint32_t Kinds, class Scene>
WT_HD WT_INLINE EmitterShape emitter_shape(const Scene& scene, int instance, int prim) {
  if (spheres_only(Kinds) || scene.instance(instance).kind == PrimitiveKind::Sphere) {
    const SphereGeom sg = scene.sphere(prim);
    return EmitterShape::of_sphere(vec3(sg.x, sg.y, sg.z), sg.w);
  }
  vec3 a, b, c;
  world_triangle(scene.triangle(prim), scene.instance(instance), a, b, c);
  return EmitterShape::of_triangle(a, b, c);
}

// The density per solid angle with which light sampling from `from` draws the
// direction `dir` (unit) that meets the emitter of this emission and shape at
// distance `dist`: the probability of picking it by power (the host's table holds
// the same light_power_of) times the shape's own density. Evaluated the same way for
// a light sample and for a path that hits the emitter, so that the two MIS weights
// of a direction sum to one.
template <class Scene>
WT_HD WT_INLINE float light_density(const Scene& scene, const vec3& emission, const EmitterShape& shape,
                                    const vec3& from, const vec3& dir, float dist) {
  const float pdf = shape.pdf(from, dir, dist);
  return pdf > 0.0f ? light_power_of(emission, shape.area()) / scene.total_light_power() * pdf : 0.0f;
}

// The same for the sky (when it is sampled) and the direction `dir`.
template <class Scene>
WT_HD WT_INLINE float sky_light_density(const Scene& scene, const vec3& dir) {
  return scene.sky_light_pick() * sky_direction_pdf(scene.sky, scene.environment_table(), dir);
}

// The emitter that u (in [0, 1)) picks from the scene's table, and the probability
// of picking it.
template <class Scene>
WT_HD WT_INLINE int pick_light(const Scene& scene, float u, float& probability) {
  int lo = 0, hi = scene.light_count() - 1;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (u < scene.light_cdf_at(mid)) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  probability = scene.light_cdf_at(lo) - (lo > 0 ? scene.light_cdf_at(lo - 1) : 0.0f);
  return lo;
}

}  // namespace wt

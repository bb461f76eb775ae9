// One bounce of a path, and a whole path: the single definition of the light
// transport that every backend and kernel runs.
#pragma once

#include "wavetrace/scene_view.hpp"

namespace wt {

constexpr float kRayTMax = 3.0e38f;

// Kinds: the primitive kinds the scene holds (geometry.hpp), or a superset.
template <uint32_t Kinds = kAllKinds, class Scene>
WT_HD WT_INLINE Hit intersect_scene(const Scene& scene, const Ray& ray) {
  return intersect_closest<Kinds>(scene, ray, kRayTMax);
}

// Camera ray of path (pixel, sample).
template <class Scene>
WT_HD WT_INLINE Ray primary_ray(const Scene& scene, const RenderParams& rp, uint32_t pixel, uint32_t sample) {
  Rng rng = Rng::at(rp.seed, pixel, sample, 0);
  int x = static_cast<int>(pixel % static_cast<uint32_t>(rp.width));
  int y = static_cast<int>(pixel / static_cast<uint32_t>(rp.width));
  return scene.camera.generate(x, y, rp.width, rp.height, rng);
}

// Shades a hit at `bounce`: adds what the surface emits, scatters, and plays
// Russian roulette. On true the path goes on along `ray`, with `throughput` updated.
template <uint32_t Kinds = kAllKinds, class Scene>
WT_HD WT_INLINE bool shade_hit(const Scene& scene, const RenderParams& rp, const Hit& hit, uint32_t pixel,
                               uint32_t sample, uint32_t bounce, Ray& ray, vec3& throughput, vec3& radiance) {
  const Material& m = scene.material(material_index<Kinds>(scene, hit));
  if (m.kind == MaterialKind::Emissive) {
    radiance += throughput * m.emission;
    return false;
  }
  const SurfacePoint sp = surface_at<Kinds>(scene, ray, hit);
  Rng rng = Rng::at(rp.seed, pixel, sample, bounce);
  vec3 attenuation;
  Ray next;
  if (!scatter(m, scene.texture_array(), scene.image_array(), ray, sp, rng, attenuation, next)) return false;
  throughput *= attenuation;
  if (static_cast<int>(bounce) + 1 >= rp.roulette_depth) {
    // Survive with probability p and divide by it: the expectation is unchanged.
    float p = fminf(fmaxf(throughput.x, fmaxf(throughput.y, throughput.z)), 0.95f);
    if (!(rng.uniform(kDimRoulette) < p)) return false;
    throughput *= 1.0f / p;
  }
  ray = next;
  return true;
}

// The radiance of path (pixel, sample); `rays` grows by every ray intersected.
template <uint32_t Kinds = kAllKinds, class Scene>
WT_HD WT_INLINE vec3 trace_path(const Scene& scene, const RenderParams& rp, uint32_t pixel, uint32_t sample,
                                uint32_t& rays) {
  Ray ray = primary_ray(scene, rp, pixel, sample);
  vec3 throughput(1.0f), radiance(0.0f);
  for (int bounce = 0; bounce < rp.depth; ++bounce) {
    Hit hit = intersect_scene<Kinds>(scene, ray);
    ++rays;
    if (hit.missed()) {
      radiance += throughput * scene.sky.radiance(ray.dir, scene.image_array());
      break;
    }
    if (!shade_hit<Kinds>(scene, rp, hit, pixel, sample, static_cast<uint32_t>(bounce), ray, throughput, radiance)) break;
  }
  return radiance;
}

}  // namespace wt

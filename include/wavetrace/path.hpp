// One bounce of a path, and a whole path: the single definition of the light
// transport that every backend and kernel runs.
#pragma once

#include "wavetrace/scene_view.hpp"

namespace wt {

constexpr float kRayTMax = 3.0e38f;

// What the path functions are compiled for unless a kernel says otherwise: every
// primitive kind, and light sampling.
constexpr uint32_t kEverything = kAllKinds | kLightSampling;

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

// Whether anything blocks `ray` before tmax (a shadow ray: the first hit ends it).
template <uint32_t Kinds = kAllKinds, class Scene>
WT_HD WT_INLINE bool occluded(const Scene& scene, const Ray& ray, float tmax) {
  return !intersect_closest<Kinds, true>(scene, ray, tmax).missed();
}

// A triangle of an instance, in world space.
template <class Scene>
WT_HD WT_INLINE void world_triangle(const Scene& scene, const Instance& in, int prim, vec3& a, vec3& b, vec3& c) {
  const TriangleGeom t = scene.triangle(prim);
  a = t.corner(0);
  b = t.corner(1);
  c = t.corner(2);
  if (!in.identity) {
    a = in.world_from_object.point(a);
    b = in.world_from_object.point(b);
    c = in.world_from_object.point(c);
  }
}

// The probability of picking emitter (instance, prim) among the scene's, by power
// (light_power_of), from its emission and its world-space shape.
template <uint32_t Kinds, class Scene>
WT_HD WT_INLINE float light_pick_probability(const Scene& scene, const vec3& emission, int instance, int prim) {
  float area;
  if (spheres_only(Kinds) || scene.instance(instance).kind == PrimitiveKind::Sphere) {
    const SphereGeom sg = scene.sphere(prim);
    area = 4.0f * kPi * sg.w * sg.w;
  } else {
    vec3 a, b, c;
    world_triangle(scene, scene.instance(instance), prim, a, b, c);
    area = 0.5f * glm::length(glm::cross(b - a, c - a));
  }
  return light_power_of(emission, area) / scene.total_light_power();
}

// The density per solid angle with which light sampling from `from` draws the
// direction `dir` (unit) that meets emitter (instance, prim) at distance `dist`:
// the picking probability times the emitter's own density. Evaluated the same way
// for a light sample and for a path that hits the emitter, so that the two MIS
// weights of a direction sum to one.
template <uint32_t Kinds, class Scene>
WT_HD WT_INLINE float light_density(const Scene& scene, const vec3& emission, int instance, int prim,
                                    const vec3& from, const vec3& dir, float dist) {
  float pdf;
  if (spheres_only(Kinds) || scene.instance(instance).kind == PrimitiveKind::Sphere) {
    const SphereGeom sg = scene.sphere(prim);
    pdf = sphere_light_pdf(vec3(sg.x, sg.y, sg.z), sg.w, from);
  } else {
    vec3 a, b, c;
    world_triangle(scene, scene.instance(instance), prim, a, b, c);
    pdf = triangle_light_pdf(a, b, c, dir, dist);
  }
  return pdf > 0.0f ? light_pick_probability<Kinds>(scene, emission, instance, prim) * pdf : 0.0f;
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

// A light sample's contribution, waiting for its shadow ray: added to the film
// where nothing blocks `ray` before tmax.
struct ShadowRay {
  Ray ray;
  float tmax;
  vec3 contribution;
  bool valid;
};

// Shadow rays stop this far short of the emitter (relatively), so that they never
// count the emitter's own surface as what blocks them.
constexpr float kShadowShorten = 1e-4f;

// Next-event estimation at a diffuse hit: one emitter picked by power, one point on
// it, and its contribution weighted against the BSDF's sampling of the same
// direction (the power heuristic). Lambertian surfaces and the diffuse base of
// coated ones are light-sampled; specular and glossy ones (dielectric, metal, a
// coat's mirror reflection) are not, and the paths they scatter count what they
// hit in full.
//
// `lobe`: the share of the surface's reflection that is diffuse (1 for Lambertian;
// 1 - Fresnel for a coat over a diffuse base), which scales both the BSDF and the
// density with which the BSDF samples the direction.
template <uint32_t Kinds, class Scene>
WT_HD WT_INLINE ShadowRay sample_light(const Scene& scene, const vec3& albedo, const SurfacePoint& sp,
                                       const vec3& facing_n, float lobe, const vec3& throughput, const Rng& rng) {
  ShadowRay out{};
  out.valid = false;
  float pick;
  const LightRef light = scene.light(pick_light(scene, rng.uniform(kDimLightPick), pick));
  if (!(pick > 0.0f)) return out;
  LightSample s;
  if (spheres_only(Kinds) || scene.instance(light.instance).kind == PrimitiveKind::Sphere) {
    const SphereGeom sg = scene.sphere(light.prim);
    s = sample_sphere_light(vec3(sg.x, sg.y, sg.z), sg.w, sp.p, rng.uniform(kDimLightA), rng.uniform(kDimLightB));
  } else {
    vec3 a, b, c;
    world_triangle(scene, scene.instance(light.instance), light.prim, a, b, c);
    s = sample_triangle_light(a, b, c, sp.p, rng.uniform(kDimLightA), rng.uniform(kDimLightB));
  }
  const float cos_s = glm::dot(s.dir, facing_n);
  if (!(s.pdf > 0.0f) || cos_s <= 0.0f || glm::dot(s.dir, sp.front ? sp.ng : -sp.ng) <= 0.0f) return out;
  const Material& lm = scene.material(material_index<Kinds>(scene, Hit{s.dist, light.instance, light.prim, 0.0f, 0.0f}));
  // The shadow ray leaves from the offset a ray leaving the surface starts at, and
  // is aimed at the sampled point itself, so that it ends on the light's surface
  // (shortened by kShadowShorten) however large the offset is.
  out.ray = spawn_ray(sp, s.dir);
  const vec3 to = sp.p + s.dist * s.dir - out.ray.origin;
  const float length = sqrtf(glm::dot(to, to));
  if (!(length > 0.0f)) return out;
  out.ray.dir = to * (1.0f / length);
  out.tmax = length * (1.0f - kShadowShorten);
  // The MIS weight from there, for that direction: the density light_density gives
  // when a path that leaves here in the same direction hits the light.
  const float light_pdf = light_density<Kinds>(scene, lm.emission, light.instance, light.prim, out.ray.origin,
                                               out.ray.dir, length);
  const float w = power_heuristic(light_pdf, lobe * cos_s * (1.0f / kPi));
  const vec3 f = albedo * (lobe / kPi);
  out.contribution = throughput * f * lm.emission * (cos_s * w / (pick * s.pdf));
  out.valid = out.contribution.x > 0.0f || out.contribution.y > 0.0f || out.contribution.z > 0.0f;
  return out;
}

// Shades a hit at `bounce`: adds what the surface emits (weighted against light
// sampling where the path's last bounce could have sampled it: `pdf` is that
// bounce's BSDF density, 0 after a specular bounce or the camera), samples a light
// (`shadow`), scatters, and plays Russian roulette. On true the path goes on along
// `ray`, with `throughput` and `pdf` updated.
template <uint32_t Kinds = kEverything, class Scene>
WT_HD WT_INLINE bool shade_hit(const Scene& scene, const RenderParams& rp, const Hit& hit, uint32_t pixel,
                               uint32_t sample, uint32_t bounce, Ray& ray, vec3& throughput, vec3& radiance,
                               float& pdf, ShadowRay& shadow) {
  shadow.valid = false;
  const Material& m = scene.material(material_index<Kinds>(scene, hit));
  constexpr bool kSampleLights = (Kinds & kLightSampling) != 0;
  const bool nee = kSampleLights && rp.nee != 0 && scene.light_count() > 0;
  if (m.kind == MaterialKind::Emissive) {
    float w = 1.0f;
    if (kSampleLights && nee && pdf > 0.0f) {
      w = power_heuristic(pdf, light_density<Kinds>(scene, m.emission, hit.instance, hit.prim, ray.origin, ray.dir,
                                                    hit.t));
    }
    radiance += throughput * m.emission * w;
    return false;
  }
  const SurfacePoint sp = surface_at<Kinds>(scene, ray, hit);
  Rng rng = Rng::at(rp.seed, pixel, sample, bounce);
  const vec3 facing_n = sp.front ? sp.n : -sp.n;
  // The diffuse share of the surface's reflection (scatter_coated draws the coat's
  // mirror with Schlick's probability from the front, and the base otherwise).
  const float coat = m.kind == MaterialKind::Coated && sp.front
                         ? schlick(fminf(-glm::dot(ray.dir, facing_n), 1.0f), 1.0f / m.ior)
                         : 0.0f;
  const float lobe = m.kind == MaterialKind::Lambertian ? 1.0f : (m.kind == MaterialKind::Coated ? 1.0f - coat : 0.0f);
  // A light sample here stands for the path's next ray hitting the emitter, so it
  // is taken only where that ray could still be traced: with and without light
  // sampling the render estimates the same paths.
  const vec3 albedo = material_albedo(m, scene.texture_array(), scene.image_array(), sp);
  if (kSampleLights && nee && lobe > 0.0f && static_cast<int>(bounce) + 1 < rp.depth) {
    shadow = sample_light<Kinds>(scene, albedo, sp, facing_n, lobe, throughput, rng);
  }
  vec3 attenuation;
  Ray next;
  if (!scatter_with_albedo(m, albedo, ray, sp, rng, attenuation, next)) return false;
  // The density of the direction the path goes on in, where the BSDF has one: the
  // diffuse lobe's; 0 after a mirror-like bounce (the coat's, when it was drawn).
  const bool mirrored = m.kind == MaterialKind::Coated && sp.front && rng.uniform(kDimLayer) < coat;
  pdf = lobe > 0.0f && !mirrored ? lobe * fmaxf(glm::dot(next.dir, facing_n), 0.0f) * (1.0f / kPi) : 0.0f;
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

// The radiance of path (pixel, sample); `rays` grows by every path ray intersected,
// `shadow_rays` by every shadow ray traced.
template <uint32_t Kinds = kEverything, class Scene>
WT_HD WT_INLINE vec3 trace_path(const Scene& scene, const RenderParams& rp, uint32_t pixel, uint32_t sample,
                                uint32_t& rays, uint32_t& shadow_rays) {
  Ray ray = primary_ray(scene, rp, pixel, sample);
  vec3 throughput(1.0f), radiance(0.0f);
  float pdf = 0.0f;
  for (int bounce = 0; bounce < rp.depth; ++bounce) {
    Hit hit = intersect_scene<Kinds>(scene, ray);
    ++rays;
    if (hit.missed()) {
      radiance += throughput * scene.sky.radiance(ray.dir, scene.image_array());
      break;
    }
    ShadowRay shadow;
    const bool alive =
        shade_hit<Kinds>(scene, rp, hit, pixel, sample, static_cast<uint32_t>(bounce), ray, throughput, radiance, pdf,
                         shadow);
    if ((Kinds & kLightSampling) && shadow.valid) {
      ++shadow_rays;
      if (!occluded<Kinds>(scene, shadow.ray, shadow.tmax)) radiance += shadow.contribution;
    }
    if (!alive) break;
  }
  return radiance;
}

}  // namespace wt

// One bounce of a path, and a whole path: the single definition of the light
// transport that every backend and kernel runs.
#pragma once

#include "wavetrace/blend.hpp"
#include "wavetrace/mutant.hpp"
#include "wavetrace/scene_lights.hpp"
#include "wavetrace/scene_view.hpp"

namespace wt {

constexpr float kRayTMax = 3.0e38f;

// What the path functions are compiled for unless a kernel says otherwise: every
// primitive kind, light sampling, the microfacet BSDFs, principled's layers and alpha.
constexpr uint32_t kEverything = kAllKinds | kLightSampling | kMicrofacet | kLayersAndAlpha;

// Kinds: the primitive kinds the scene holds (geometry.hpp), or a superset.
template <uint32_t Kinds = kAllKinds | kAlphaTested, class Scene>
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
template <uint32_t Kinds = kAllKinds | kAlphaTested, class Scene>
WT_HD WT_INLINE bool occluded(const Scene& scene, const Ray& ray, float tmax) {
  if (WT_MUTANT(ShadowIgnoresFirstHit)) {
    const Hit first = intersect_closest<Kinds, false>(scene, ray, tmax);
    if (first.missed()) return false;
    const float past = first.t * (1.0f + 1e-4f) + 1e-4f;
    return past < tmax && !intersect_closest<Kinds, true>(scene, Ray{ray.at(past), ray.dir}, tmax - past).missed();
  }
  return !intersect_closest<Kinds, true>(scene, ray, tmax).missed();
}

// What a path adds that leaves the scene along `dir` (unit): the sky's radiance,
// weighted against light sampling where the sky is a sampled light and the path's
// last bounce (of BSDF density `pdf`; 0 after a specular bounce or the camera)
// sampled the lights.
// Kinds without kLightSampling: compiled for scenes with no lights to sample.
template <uint32_t Kinds = kEverything, class Scene>
WT_HD WT_INLINE vec3 sky_seen(const Scene& scene, const RenderParams& rp, const vec3& dir, float pdf) {
  const vec3 sky = scene.sky.radiance(dir, scene.image_array());
  if ((Kinds & kLightSampling) == 0 || !(pdf > 0.0f) || rp.nee == 0 || !(scene.sky_light_pick() > 0.0f)) return sky;
  return sky * power_heuristic(pdf, sky_light_density(scene, dir));
}

// What emitter material m sends out at `hit`, reached along `ray`: its emission,
// times its emission texture there where it has one. (Light sampling picks emitters
// by the untextured emission, light_power_of's, for both of MIS's densities.)
// Kinds without kMicrofacet: compiled for scenes whose emitters are untextured.
template <uint32_t Kinds, class Scene>
WT_HD WT_INLINE vec3 emitted_radiance(const Scene& scene, const Material& m, const Ray& ray, const Hit& hit) {
  if constexpr ((Kinds & kMicrofacet) == 0) {
    return m.emission;
  } else {
    // An emitter's texture is its emission's; a reflecting material's is a parameter.
    const int32_t texture = m.kind == MaterialKind::Emissive ? m.texture
                            : m.params >= 0                  ? scene.material_param_array()[m.params].emission_texture
                                                             : -1;
    if (texture < 0) return m.emission;
    SurfacePoint sp = surface_at<Kinds>(scene, ray, hit);
    sp.footprint = scene.camera.footprint(sp.p, sp.ng, ray.dir);
    return m.emission * eval_texture(scene.texture_array()[texture], scene.image_array(), sp);
  }
}

// The material that shades `hit`, reached along `ray`: material_index's, or where
// that is a blend, the material it picks there (blend.hpp), level after level.
// Intersect takes the sort key from it and shade the material, so that both pick
// alike. A blend's weight texture is looked up as the BSDF's textures are, filtered
// over the camera's footprint, and its luminance (clamped to [0, 1]) scales the weight.
// Kinds without kMicrofacet: compiled for scenes without blends (a blend has params).
template <uint32_t Kinds, class Scene>
WT_HD WT_INLINE uint32_t shading_material_index(const Scene& scene, const Ray& ray, const Hit& hit) {
  uint32_t index = material_index<Kinds>(scene, hit);
  if constexpr ((Kinds & kMicrofacet) != 0) {
    for (int level = 0; level < kMaxBlendDepth; ++level) {
      const Material& m = scene.material(index);
      if (m.kind != MaterialKind::Blend) break;
      const MaterialParams& p = scene.material_param_array()[m.params];
      float weight = p.blend_weight;
      if (p.blend_texture >= 0) {
        SurfacePoint sp = surface_at<Kinds>(scene, ray, hit);
        sp.footprint = scene.camera.footprint(sp.p, sp.ng, ray.dir);
        const float y = luminance(eval_texture(scene.texture_array()[p.blend_texture], scene.image_array(), sp));
        weight *= fminf(fmaxf(y, 0.0f), 1.0f);
      }
      index = static_cast<uint32_t>(p.blend_materials[blend_takes_second(weight, blend_uniform(ray, hit, level)) ? 1 : 0]);
    }
  }
  return index;
}

// The BSDF of material m at sp, reached along `ray`: its textures filtered over the
// camera's footprint there (texture_lod), which is set in sp.
template <uint32_t Kinds, class Scene>
WT_HD WT_INLINE BsdfAt bsdf_at_hit(const Scene& scene, const Material& m, const Ray& ray, SurfacePoint& sp) {
  constexpr bool kFacets = (Kinds & kMicrofacet) != 0;
  constexpr bool kLayers = kFacets && (Kinds & kLayersAndAlpha) != 0;
  if constexpr (kFacets) {
    if (m.texture >= 0 || m.params >= 0) sp.footprint = scene.camera.footprint(sp.p, sp.ng, ray.dir);
  }
  return bsdf_at<kFacets, kLayers>(
      m, BsdfInputs{scene.material_param_array(), scene.bsdf_table_array(), scene.texture_array(), scene.image_array()},
      sp, material_albedo<kFacets>(m, scene.texture_array(), scene.image_array(), sp), -ray.dir);
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

// Next-event estimation at a hit: one light picked by power (an emitter, or the
// sky), one point or direction on it, and its contribution weighted against the
// BSDF's sampling of the same direction (the power heuristic). Taken where the BSDF
// has a lobe that is not a delta (bsdf_samples_lights); the paths that specular
// lobes scatter count what they hit in full. A BSDF that only reflects looks for
// lights on wo's side of the surface; one that transmits looks on both.
template <uint32_t Kinds, class Scene>
WT_HD WT_INLINE ShadowRay sample_light(const Scene& scene, const RenderParams& rp, const BsdfAt& bsdf,
                                       const SurfacePoint& sp, const vec3& wo, const vec3& throughput, const Rng& rng) {
  ShadowRay out{};
  out.valid = false;
  float pick;
  LightRef light;
  if (rp.nee != 0) {
    light = scene.light(pick_light(scene, rng.uniform(kDimLightPick), pick));
  } else {
    // Without next-event estimation the punctual lights alone, which no path meets,
    // are sampled: one of them, uniformly.
    const int n = scene.punctual_count();
    const int i = static_cast<int>(rng.uniform(kDimLightPick) * static_cast<float>(n));
    light = LightRef{kPunctualLight, i < n ? i : n - 1};
    pick = 1.0f / static_cast<float>(n);
  }
  if (!(pick > 0.0f)) return out;
  const float u1 = rng.uniform(WT_MUTANT(DimensionReused) ? kDimLightPick : kDimLightA), u2 = rng.uniform(kDimLightB);
  const vec3 outward = sp.front ? sp.ng : -sp.ng;
  const bool either_side = (Kinds & kMicrofacet) != 0 && bsdf_transmits(bsdf);
  vec3 emitted;
  float drawn_pdf;  // the density the direction was drawn with, times the picking probability
  float light_pdf;  // light_density's (or sky_light_density's) for it, for the MIS weight
  bool delta = false;  // a punctual light: drawn with probability `pick` alone, met by no path
  if (light.instance == kPunctualLight) {
    const PunctualLight pl = scene.punctual_light(light.prim);
    vec3 dir;
    float dist;
    pl.toward(sp.p, dir, dist);
    if ((pl.kind != PunctualKind::Directional && !(dist > 0.0f)) || (!either_side && glm::dot(dir, outward) <= 0.0f)) {
      return out;
    }
    out.ray = spawn_ray(sp, dir);
    out.tmax = kRayTMax;
    if (pl.kind != PunctualKind::Directional) {
      pl.toward(out.ray.origin, out.ray.dir, dist);
      if (!(dist > 0.0f)) return out;
      out.tmax = dist * (1.0f - kShadowShorten);
    }
    emitted = pl.irradiance(out.ray.dir, dist);
    drawn_pdf = pick;
    light_pdf = 1.0f;
    delta = true;
  } else if (light.instance == kSkyLight) {
    const SkyDirection d = sample_sky_direction(scene.sky, scene.environment_table(), u1, u2);
    if (!(d.pdf > 0.0f) || (!either_side && glm::dot(d.dir, outward) <= 0.0f)) return out;
    out.ray = spawn_ray(sp, d.dir);
    out.tmax = kRayTMax;
    emitted = scene.sky.radiance(d.dir, scene.image_array());
    drawn_pdf = light_pdf = pick * d.pdf;
  } else {
    const EmitterShape shape = emitter_shape<Kinds>(scene, light.instance, light.prim);
    const LightSample s = shape.sample(sp.p, u1, u2);
    if (!(s.pdf > 0.0f) || (!either_side && glm::dot(s.dir, outward) <= 0.0f)) return out;
    const Hit at{s.dist, light.instance, light.prim, s.b1, s.b2};
    const Material& lm = scene.material(material_index<Kinds>(scene, at));
    emitted = emitted_radiance<Kinds>(scene, lm, Ray{sp.p, s.dir}, at);
    // An alpha-tested emitter gives light where it is there (on average, as a path
    // meets it).
    if ((Kinds & kAlphaTested) && !spheres_only(Kinds) && scene.instance(light.instance).kind == PrimitiveKind::Triangle) {
      emitted *= alpha_coverage(scene, scene.triangle(light.prim).alpha, light.instance, light.prim, s.b1, s.b2);
    }
    // The shadow ray leaves from the offset a ray leaving the surface starts at, and
    // is aimed at the sampled point itself, so that it ends on the light's surface
    // (shortened by kShadowShorten) however large the offset is.
    out.ray = spawn_ray(sp, s.dir);
    const vec3 to = sp.p + s.dist * s.dir - out.ray.origin;
    const float length = sqrtf(glm::dot(to, to));
    if (!(length > 0.0f)) return out;
    out.ray.dir = to * (1.0f / length);
    out.tmax = length * (1.0f - kShadowShorten);
    // The density light_density gives when a path that leaves here in the same
    // direction hits the light, for the MIS weight.
    drawn_pdf = pick * s.pdf;
    light_pdf = light_density(scene, lm.emission, shape, out.ray.origin, out.ray.dir, length);
  }
  float bsdf_pdf;
  vec3 f_cos = eval_bsdf<(Kinds & kMicrofacet) != 0, (Kinds & kLayersAndAlpha) != 0>(bsdf, wo, out.ray.dir, bsdf_pdf);
  if (!(bsdf_pdf > 0.0f) || !(light_pdf > 0.0f)) return out;
  if (WT_MUTANT(MissingCosine)) f_cos *= 1.0f / fmaxf(fabsf(glm::dot(out.ray.dir, bsdf.facing_n())), 1e-3f);
  // A delta light's sample has no rival strategy: its weight is 1.
  const float weight = delta ? 1.0f : power_heuristic(light_pdf, bsdf_pdf);
  out.contribution = throughput * f_cos * emitted * (weight / drawn_pdf);
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
  const Material& m = scene.material(shading_material_index<Kinds>(scene, ray, hit));
  const bool nee = (Kinds & kLightSampling) != 0 && rp.nee != 0 && scene.light_count() > 0;
  constexpr bool kFacets = (Kinds & kMicrofacet) != 0;
  constexpr bool kLayers = kFacets && (Kinds & kLayersAndAlpha) != 0;
  // An emitter adds what it sends out (a reflecting one, kMaterialEmits, then
  // scatters too).
  if (m.kind == MaterialKind::Emissive || (kFacets && (m.flags & kMaterialEmits))) {
    float w = 1.0f;
    if (nee && pdf > 0.0f) {
      w = power_heuristic(pdf, light_density(scene, m.emission, emitter_shape<Kinds>(scene, hit.instance, hit.prim),
                                             ray.origin, ray.dir, hit.t));
    }
    radiance += throughput * emitted_radiance<Kinds>(scene, m, ray, hit) * w;
    if (m.kind == MaterialKind::Emissive) return false;
  }
  SurfacePoint sp = surface_at<Kinds>(scene, ray, hit);
  // A path that meets a volume's boundary from inside crossed the volume to it:
  // Beer-Lambert's absorption over the distance (KHR_materials_volume; a closed
  // surface, volumes not nested).
  if constexpr (kLayers) {
    if (m.params >= 0 && !sp.front) {
      const vec3 sigma = scene.material_param_array()[m.params].attenuation;
      if (sigma.x > 0.0f || sigma.y > 0.0f || sigma.z > 0.0f) {
        throughput *= vec3(expf(-sigma.x * hit.t), expf(-sigma.y * hit.t), expf(-sigma.z * hit.t));
      }
    }
  }
  Rng rng = Rng::at(rp.seed, pixel, sample, bounce);
  const vec3 wo = -ray.dir;
  const BsdfAt bsdf = bsdf_at_hit<Kinds>(scene, m, ray, sp);
  // A light sample here stands for the path's next ray hitting the emitter, so it
  // is taken only where that ray could still be traced: with and without light
  // sampling the render estimates the same paths.
  // Punctual lights are sampled with next-event estimation off too: nothing else reaches them.
  const bool punctual = (Kinds & kLightSampling) != 0 && scene.punctual_count() > 0;
  if ((nee || punctual) && bsdf_samples_lights<kFacets>(bsdf) && static_cast<int>(bounce) + 1 < rp.depth) {
    shadow = sample_light<Kinds>(scene, rp, bsdf, sp, wo, throughput, rng);
  }
  const BsdfSample s = sample_bsdf<kFacets, kLayers>(bsdf, wo, rng);
  if (s.lobe == 0u) return false;
  const Ray next = spawn_ray(sp, s.wi);
  // The density of the direction the path goes on in, for the MIS weight of what it
  // hits: 0 after a specular lobe. (Only light sampling reads it.)
  pdf = nee && !(s.lobe & kLobeSpecular) ? s.pdf : 0.0f;
  throughput *= s.weight;
  if (static_cast<int>(bounce) + 1 >= rp.roulette_depth) {
    // Survive with probability p and divide by it: the expectation is unchanged.
    float p = fminf(fmaxf(throughput.x, fmaxf(throughput.y, throughput.z)), 0.95f);
    if (!(rng.uniform(kDimRoulette) < p)) return false;
    if (!WT_MUTANT(RouletteWithoutOneOverQ)) throughput *= 1.0f / p;
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
      radiance += throughput * sky_seen<Kinds>(scene, rp, ray.dir, pdf);
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

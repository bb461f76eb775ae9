// What a path sees first, for the arbitrary output variables (AOVs) a render writes
// beside its image (render/aovs.hpp) and that guide the denoiser: the single
// definition every backend runs, one camera sample at a time.
//
// A sample follows the camera ray (primary_ray: the same ray as the path of that
// pixel and sample) through surfaces whose BSDF is only a delta (a mirror, smooth
// glass), choosing reflection or refraction with the path's own random numbers, to
// the first surface with a lobe that is not a delta. There:
//   - albedo: the BSDF's directional albedo, the expectation of f cos / pdf, estimated
//     by one sample of the BSDF drawn with the path's random numbers (exact for a
//     Lambertian surface: its colour), times the weights of the delta bounces before
//     it. An emitter gives its emission, a ray that leaves the scene the sky's
//     radiance there, each clamped to [0, 1].
//   - normal: the BSDF's shading normal (normal and bump maps applied), world space.
// The first surface the camera ray meets, delta or not, gives
//   - depth: the distance along the camera ray (not the camera's z);
//   - position: the point, in world space.
#pragma once

#include "wavetrace/path.hpp"

namespace wt {

// A pixel's sums over its samples, kAovFloats floats a pixel: the albedo and normal
// summed over every sample (a miss adds a zero normal), the position and depth over
// the samples that hit something, and the count of those.
constexpr int kAovAlbedo = 0;
constexpr int kAovNormal = 3;
constexpr int kAovPosition = 6;
constexpr int kAovDepth = 9;
constexpr int kAovHits = 10;
constexpr int kAovFloats = 11;

struct FirstSurface {
  vec3 albedo{0.0f};
  vec3 normal{0.0f};
  vec3 position{0.0f};
  float depth = 0.0f;
  bool hit = false;
};

WT_HD WT_INLINE vec3 clamp_unit(const vec3& v) {
  return vec3(fminf(fmaxf(v.x, 0.0f), 1.0f), fminf(fmaxf(v.y, 0.0f), 1.0f), fminf(fmaxf(v.z, 0.0f), 1.0f));
}

template <uint32_t Kinds = kEverything, class Scene>
WT_HD WT_INLINE FirstSurface first_surface(const Scene& scene, const RenderParams& rp, uint32_t pixel,
                                           uint32_t sample) {
  constexpr bool kFacets = (Kinds & kMicrofacet) != 0;
  constexpr bool kLayers = kFacets && (Kinds & kLayersAndAlpha) != 0;
  FirstSurface out;
  Ray ray = primary_ray(scene, rp, pixel, sample);
  vec3 weight(1.0f);
  for (int bounce = 0; bounce < rp.depth; ++bounce) {
    const Hit hit = intersect_scene<Kinds>(scene, ray);
    if (hit.missed()) {
      out.albedo = weight * clamp_unit(scene.sky.radiance(ray.dir, scene.image_array()));
      break;
    }
    if (bounce == 0) {
      out.hit = true;
      out.depth = hit.t;
      out.position = ray.at(hit.t);
    }
    const Material& m = scene.material(shading_material_index<Kinds>(scene, ray, hit));
    SurfacePoint sp = surface_at<Kinds>(scene, ray, hit);
    if (m.kind == MaterialKind::Emissive) {
      out.albedo = weight * clamp_unit(emitted_radiance<Kinds>(scene, m, ray, hit));
      out.normal = sp.n;
      break;
    }
    const BsdfAt bsdf = bsdf_at_hit<Kinds>(scene, m, ray, sp);
    const BsdfSample s = sample_bsdf<kFacets, kLayers>(bsdf, -ray.dir, Rng::at(rp.seed, pixel, sample, bounce));
    if (bsdf_samples_lights<kFacets>(bsdf) || s.lobe == 0u || !(s.lobe & kLobeSpecular)) {
      if (s.lobe != 0u) out.albedo = weight * s.weight;
      out.normal = bsdf.n;
      break;
    }
    weight *= s.weight;
    ray = spawn_ray(sp, s.wi);
  }
  return out;
}

// Adds one sample's first surface to a pixel's kAovFloats sums.
WT_HD WT_INLINE void add_first_surface(float* sums, const FirstSurface& f) {
  sums[kAovAlbedo + 0] += f.albedo.x;
  sums[kAovAlbedo + 1] += f.albedo.y;
  sums[kAovAlbedo + 2] += f.albedo.z;
  sums[kAovNormal + 0] += f.normal.x;
  sums[kAovNormal + 1] += f.normal.y;
  sums[kAovNormal + 2] += f.normal.z;
  if (f.hit) {
    sums[kAovPosition + 0] += f.position.x;
    sums[kAovPosition + 1] += f.position.y;
    sums[kAovPosition + 2] += f.position.z;
    sums[kAovDepth] += f.depth;
    sums[kAovHits] += 1.0f;
  }
}

}  // namespace wt

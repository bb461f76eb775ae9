// What every BSDF shares: the lobe flags, a sample's record, the shading frame and
// the local-frame trigonometry the microfacet BSDFs use.
#pragma once

#include "wavetrace/geometry/surface.hpp"
#include "wavetrace/material.hpp"
#include "wavetrace/optics.hpp"
#include "wavetrace/rng.hpp"
#include "wavetrace/sampling.hpp"

namespace wt {

// A sampled direction's lobe: its kind (diffuse, glossy or specular: a delta) and
// its side (reflection or transmission). 0: no direction (the path is absorbed).
enum BsdfLobe : uint32_t {
  kLobeDiffuse = 1u,
  kLobeGlossy = 2u,
  kLobeSpecular = 4u,
  kLobeReflection = 8u,
  kLobeTransmission = 16u,
};

// One sampled direction. `weight` is f cos / pdf, the factor the path's throughput
// takes; `pdf` is the solid-angle density of drawing `wi` (the lobe's share
// included), 0 for a specular lobe, whose density is a delta.
struct BsdfSample {
  vec3 wi;
  vec3 weight;
  float pdf;
  uint32_t lobe;
};

WT_HD WT_INLINE BsdfSample no_sample() { return BsdfSample{vec3(0.0f), vec3(0.0f), 0.0f, 0u}; }

// An orthonormal frame about unit `n`, with `t` along the tangent hint where it has
// a component across n (the surface's dp/du: the direction anisotropy is measured
// from), else any vector across n (Duff et al. 2017's branchless basis).
struct Frame {
  vec3 t, b, n;

  WT_HD static Frame about(const vec3& n, const vec3& hint) {
    Frame f;
    f.n = n;
    const vec3 across = hint - glm::dot(hint, n) * n;
    const float len2 = glm::dot(across, across);
    if (len2 > 1e-12f && len2 < 1e30f) {
      f.t = across * (1.0f / sqrtf(len2));
    } else {
      const float sign = copysignf(1.0f, n.z);
      const float a = -1.0f / (sign + n.z);
      const float b = n.x * n.y * a;
      f.t = vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    }
    f.b = glm::cross(n, f.t);
    return f;
  }
  WT_HD vec3 to_local(const vec3& v) const { return vec3(glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)); }
  WT_HD vec3 to_world(const vec3& v) const { return v.x * t + v.y * b + v.z * n; }
};

// Local-frame trigonometry (z is the normal).
WT_HD WT_INLINE float cos2_theta(const vec3& w) { return w.z * w.z; }
WT_HD WT_INLINE float sin2_theta(const vec3& w) { return fmaxf(0.0f, w.x * w.x + w.y * w.y); }

// The shading normal a tangent-space normal map gives, from the map's linear colour
// c: n_t = 2c - 1, its x and y scaled by `strength`, in the frame of the tangent T
// (dp/du made orthogonal to n), the bitangent B = cross(n, T) times the UV
// handedness (up the image) and n, the unperturbed shading normal (outward).
WT_HD WT_INLINE vec3 mapped_normal(const vec3& n, const vec3& dpdu, float tangent_sign, const vec3& c,
                                   float strength) {
  const Frame f = Frame::about(n, dpdu);
  const vec3 t = 2.0f * c - vec3(1.0f);
  const vec3 m = t.x * strength * f.t + (t.y * strength * tangent_sign) * f.b + t.z * f.n;
  const float len2 = glm::dot(m, m);
  return len2 > 1e-12f ? m * (1.0f / sqrtf(len2)) : n;
}

// A shading normal that faces away from wo on wo's side of the surface (an
// interpolated or mapped normal can) is turned towards wo, in the plane of the
// two, until their cosine is kFacingCosine: the BSDF then sees wo above its
// hemisphere and gives no black pixel, and the reflections it samples that would
// cross the geometric surface are absorbed there (BsdfAt::same_side), so no light
// leaks through. `n` outward; `front`: wo on the outward side.
constexpr float kFacingCosine = 0.01f;
WT_HD WT_INLINE vec3 facing_viewer(const vec3& n, const vec3& wo, bool front) {
  const vec3 nf = front ? n : -n;
  const float c = glm::dot(wo, nf);
  if (c >= kFacingCosine) return n;
  const vec3 turned = glm::normalize(nf + (kFacingCosine - c) * wo);
  return front ? turned : -turned;
}

// The BSDF at one hit, as every BSDF reads it: the material's values there
// (textures looked up), the microfacet kinds' parameters, the hit's normals and
// which side of the surface the path arrives from. Directions are world-space and
// unit, both pointing away from the surface: wo towards where the path came from,
// wi towards where it goes (or where light arrives from).
struct BsdfAt {
  MaterialKind kind;
  uint32_t flags;   // kMaterialThin, ...
  float fuzz;       // Metal
  float ior;        // the dielectric kinds
  vec3 albedo;      // Material::albedo times its texture
  MaterialParams p; // the microfacet kinds'
  vec3 n;           // unit shading normal, outward
  vec3 ng;          // unit geometric normal, outward
  vec3 dpdu;        // the tangent hint (SurfacePoint::dpdu)
  vec3 coat_n;      // Principled with a clear coat: the coat's unit shading normal, outward
  bool front;       // wo is on the outward side of ng
  const float* tables;  // the scene's BSDF tables (bsdf_tables.hpp)

  WT_HD vec3 facing_n() const { return front ? n : -n; }
  WT_HD vec3 facing_ng() const { return front ? ng : -ng; }
  // The shading frame on wo's side (z = facing_n), for the two-sided kinds.
  WT_HD Frame facing_frame() const { return Frame::about(facing_n(), dpdu); }
  // The shading frame about the outward normal, for the kinds light crosses.
  WT_HD Frame outward_frame() const { return Frame::about(n, dpdu); }
  // Whether wi leaves on wo's side of the geometric surface (a reflection that
  // does not would pass through the surface it leaves).
  WT_HD bool same_side(const vec3& wi) const { return glm::dot(wi, facing_ng()) >= 0.0f; }
};

}  // namespace wt

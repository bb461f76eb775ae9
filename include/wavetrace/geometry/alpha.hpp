// Alpha-tested triangles (glTF's alphaMode MASK and BLEND): where a triangle's
// coverage is below its material's cutoff (MASK), or with the probability of its
// transparency (BLEND: stochastic, unbiased on average), a ray passes through as if
// it were not there. The traversal asks at every candidate hit on such a triangle,
// so camera, bounce and shadow rays are let through alike on every kernel; light
// sampling weighs an emitter's point by its coverage.
#pragma once

#include <cstring>

#include "wavetrace/geometry/instance.hpp"
#include "wavetrace/geometry/triangle.hpp"
#include "wavetrace/rng.hpp"
#include "wavetrace/texture.hpp"

namespace wt {

enum class AlphaMode : uint32_t { Mask = 1, Blend = 2 };

// A material's alpha: a factor (glTF's baseColorFactor alpha) times its texture's A
// channel (the base colour texture's), and for MASK the cutoff below which a point is
// not there.
struct AlphaTest {
  AlphaMode mode;
  int32_t texture;  // -1: the factor alone
  float factor;
  float cutoff;  // Mask
};

// The texture's alpha at the surface's uv: its image's A channel at level 0, nearest
// or bilinear as the texture is magnified (after its UV transform and wrap).
WT_HD WT_INLINE float texture_alpha(const Texture& t, const ImageView* images, const vec2& surface_uv) {
  if (t.kind != TextureKind::Image) return 1.0f;
  const ImageView& im = images[t.image];
  const vec2 uv = texture_uv(t, surface_uv);
  auto alpha = [&](int x, int y) {
#if defined(__CUDA_ARCH__)
    return tex2D<float4>(static_cast<cudaTextureObject_t>(im.object), x + 0.5f, y + 0.5f).w;
#else
    return im.texels[4 * (static_cast<size_t>(y) * im.width + x) + 3];
#endif
  };
  if (t.magnify == Filter::Nearest) {
    int x, y;
    nearest_texel(im, uv.x, uv.y, t.wrap_u, t.wrap_v, x, y);
    return alpha(x, y);
  }
  return bilinear(im.width, im.height, uv.x, uv.y, t.wrap_u, t.wrap_v,
                  [&](int x, int y) { return vec3(alpha(x, y), 0.0f, 0.0f); })
      .x;
}

// How much of triangle `prim` of `instance` is there at (b1, b2): 1 where it is
// opaque (no alpha test, or a material the instance puts in its place), else MASK's
// 0 or 1, or BLEND's alpha.
template <class Geometry>
WT_HD WT_INLINE float alpha_coverage(const Geometry& g, uint32_t alpha, int instance, int prim, float b1, float b2) {
  if (alpha == 0u || g.instance(instance).material >= 0) return 1.0f;
  const AlphaTest a = g.alpha_test(static_cast<int>(alpha - 1u));
  float c = a.factor;
  if (a.texture >= 0) {
    const TriangleShading sh = g.triangle_shading(prim);
    vec2 uv(b1, b2);  // as the surface has it without UVs
    if (sh.flags & kTriangleHasUvs) {
      uv = (1.0f - b1 - b2) * g.uv(sh.vertex[0]) + b1 * g.uv(sh.vertex[1]) + b2 * g.uv(sh.vertex[2]);
    }
    c *= texture_alpha(g.texture(static_cast<uint32_t>(a.texture)), g.image_array(), uv);
  }
  if (a.mode == AlphaMode::Mask) return c >= a.cutoff ? 1.0f : 0.0f;
  return fminf(fmaxf(c, 0.0f), 1.0f);
}

WT_HD WT_INLINE uint32_t float_bits(float f) {
#if defined(__CUDA_ARCH__)
  return __float_as_uint(f);
#else
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
#endif
}

// Whether a ray meets alpha-tested triangle `prim` at (b1, b2): by its coverage, and
// for a partial one by a number in [0, 1) hashed from the ray and the triangle (the
// same ray always decides alike; different rays independently).
template <class Geometry>
WT_HD WT_INLINE bool alpha_lets_hit(const Geometry& g, uint32_t alpha, int instance, int prim, float b1, float b2,
                                    const Ray& ray) {
  const float c = alpha_coverage(g, alpha, instance, prim, b1, b2);
  if (c >= 1.0f) return true;
  if (!(c > 0.0f)) return false;
  uint32_t h = hash_u32(float_bits(ray.origin.x) ^ 0x6a09e667u);
  h = hash_u32(h ^ float_bits(ray.origin.y));
  h = hash_u32(h ^ float_bits(ray.origin.z));
  h = hash_u32(h ^ float_bits(ray.dir.x));
  h = hash_u32(h ^ float_bits(ray.dir.y));
  h = hash_u32(h ^ float_bits(ray.dir.z));
  h = hash_u32(h ^ static_cast<uint32_t>(prim));
  return static_cast<float>(h >> 8) * (1.0f / 16777216.0f) < c;
}

}  // namespace wt

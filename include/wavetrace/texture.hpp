// Textures: procedural (checker, gradient noise) and images. An image is sampled
// with the same bilinear (or trilinear, between mip levels) arithmetic on every
// backend; on the GPU its texels come through CUDA texture objects, on the CPU from
// host memory.
#pragma once

#include "wavetrace/geometry/surface.hpp"
#include "wavetrace/mutant.hpp"
#include "wavetrace/rng.hpp"

namespace wt {

enum class TextureKind : uint32_t { Checker = 0, Noise = 1, Image = 2 };

// How an image texture's coordinates outside [0, 1] fall on it, per axis.
enum class Wrap : uint32_t { Repeat = 0, Clamp = 1, Mirror = 2 };

// How an image texture is filtered: bilinearly on the full image (the study's
// lookup), trilinearly between the two mip levels whose texels match the pixel's
// footprint (minified textures do not alias), or by the nearest texel of the full
// image (glTF's NEAREST: pixel art stays sharp).
enum class Filter : uint32_t { Bilinear = 0, Trilinear = 1, Nearest = 2 };

struct Texture {
  TextureKind kind;
  int32_t image;  // index into the scene's images (Image only)
  float scale;    // Checker: square size; Noise: spatial frequency
  int32_t octaves;
  vec3 a;  // Checker: colour of even squares; Noise: the colour at 1
  vec3 b;  // Checker: colour of odd squares;  Noise: the colour at 0
  // Image: the UV transform (scale, then rotation, then offset, as glTF's
  // KHR_texture_transform: uv' = offset + R(rotation) (scale * uv)) and the wrap of u and v.
  vec2 uv_offset;
  vec2 uv_scale;
  float uv_cos, uv_sin;  // of the rotation
  Wrap wrap_u, wrap_v;
  // `filter` where the texture is minified (a texel smaller than the pixel's
  // footprint), `magnify` (Bilinear or Nearest) where it is magnified or the kernel
  // knows no footprint, as glTF's minFilter and magFilter.
  Filter filter;
  Filter magnify;
};

// An image texture of image `image`, untransformed, wrapping u and v as given,
// mip-mapped.
inline Texture image_texture(int32_t image, Wrap wrap_u, Wrap wrap_v) {
  Texture t{};
  t.kind = TextureKind::Image;
  t.image = image;
  t.uv_scale = vec2(1.0f);
  t.uv_cos = 1.0f;
  t.wrap_u = wrap_u;
  t.wrap_v = wrap_v;
  t.filter = Filter::Trilinear;
  return t;
}

// A texel index along an axis of n texels, by the wrap mode.
WT_HD WT_INLINE int wrap_index(int i, int n, Wrap w) {
  switch (w) {
    case Wrap::Repeat: return i < 0 ? i + n : (i >= n ? i - n : i);
    case Wrap::Clamp: return i < 0 ? 0 : (i >= n ? n - 1 : i);
    case Wrap::Mirror: {
      const int m = i < 0 ? -1 - i : i;  // reflected about the edge: -1 -> 0
      const int period = m % (2 * n);
      return period < n ? period : 2 * n - 1 - period;
    }
  }
  return 0;
}

// The two taps i0 and i1 = i0 + 1 of a coordinate wrap_coordinate reduced, scaled
// to n texels (so i0 >= -1, and i1 <= n, or 2n where mirrored): repeat and clamp
// need one test each, as the study's lookup had.
WT_HD WT_INLINE void wrap_taps(int& i0, int& i1, int n, Wrap w) {
  switch (w) {
    case Wrap::Repeat:
      i0 = i0 < 0 ? i0 + n : i0;
      i1 = i1 >= n ? i1 - n : i1;
      return;
    case Wrap::Clamp:
      i0 = i0 < 0 ? 0 : i0;
      i1 = i1 >= n ? n - 1 : i1;
      return;
    case Wrap::Mirror:
      i0 = wrap_index(i0, n, w);
      i1 = wrap_index(i1, n, w);
      return;
  }
}

// The coordinate reduced before it is scaled to texels: repeat keeps its fraction
// (so large coordinates keep their precision), clamp clamps it to [0, 1], mirror
// reduces it modulo 2.
WT_HD WT_INLINE float wrap_coordinate(float u, Wrap w) {
  switch (w) {
    case Wrap::Repeat: return u - floorf(u);
    case Wrap::Clamp: return fminf(fmaxf(u, 0.0f), 1.0f);
    case Wrap::Mirror: return u - 2.0f * floorf(0.5f * u);
  }
  return u;
}

// One image: a float RGBA texel array in linear colour. `object` is the CUDA texture
// object (point sampling, unnormalised coordinates) on the GPU; `texels` the host copy.
// Its mip levels 1, 2, ... (each half the one before, rounded down, at least 1 texel;
// `levels` counts level 0 too, 1: none) lie in a second array, one below the other
// from the top, level 1's width wide: `mip_object` and `mip_texels`.
struct ImageView {
  unsigned long long object;
  const float* texels;  // RGBA, row-major, row 0 = top (v = 0)
  int32_t width, height;
  unsigned long long mip_object = 0;
  const float* mip_texels = nullptr;
  int32_t levels = 1;
};

// Level `level`'s size, and where it starts in the mip array (level >= 1).
WT_HD WT_INLINE void mip_level_shape(const ImageView& im, int level, int& w, int& h, int& row) {
  w = im.width;
  h = im.height;
  row = 0;
  for (int l = 1; l <= level; ++l) {
    if (l > 1) row += h;
    w = w > 1 ? w / 2 : 1;
    h = h > 1 ? h / 2 : 1;
  }
}

WT_HD WT_INLINE vec3 image_texel(const ImageView& im, int x, int y) {
#if defined(__CUDA_ARCH__)
  float4 t = tex2D<float4>(static_cast<cudaTextureObject_t>(im.object), x + 0.5f, y + 0.5f);
  return vec3(t.x, t.y, t.z);
#else
  const float* p = im.texels + 4 * (static_cast<size_t>(y) * im.width + x);
  return vec3(p[0], p[1], p[2]);
#endif
}

// Texel (x, y) of the mip array (`pitch`: its width, level 1's).
WT_HD WT_INLINE vec3 mip_texel(const ImageView& im, int pitch, int x, int y) {
#if defined(__CUDA_ARCH__)
  (void)pitch;
  float4 t = tex2D<float4>(static_cast<cudaTextureObject_t>(im.mip_object), x + 0.5f, y + 0.5f);
  return vec3(t.x, t.y, t.z);
#else
  const float* p = im.mip_texels + 4 * (static_cast<size_t>(y) * pitch + x);
  return vec3(p[0], p[1], p[2]);
#endif
}

// Bilinear lookup (texel centres at half-integers) of an image of w x h texels, u
// and v wrapped by their modes; `texel(x, y)` fetches.
template <class Fetch>
WT_HD WT_INLINE vec3 bilinear(int w, int h, float u, float v, Wrap wrap_u, Wrap wrap_v, const Fetch& texel) {
  float x = wrap_coordinate(u, wrap_u) * w - 0.5f;
  float y = wrap_coordinate(v, wrap_v) * h - 0.5f;
  float fx = floorf(x), fy = floorf(y);
  float ax = x - fx, ay = y - fy;
  int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  int x1 = x0 + 1, y1 = y0 + 1;
  wrap_taps(x0, x1, w, wrap_u);
  wrap_taps(y0, y1, h, wrap_v);
  vec3 top = (1.0f - ax) * texel(x0, y0) + ax * texel(x1, y0);
  vec3 bottom = (1.0f - ax) * texel(x0, y1) + ax * texel(x1, y1);
  return (1.0f - ay) * top + ay * bottom;
}

// The texel of the full image nearest to (u, v), wrapped by the modes.
WT_HD WT_INLINE void nearest_texel(const ImageView& im, float u, float v, Wrap wrap_u, Wrap wrap_v, int& x, int& y) {
  x = wrap_index(static_cast<int>(floorf(wrap_coordinate(u, wrap_u) * im.width)), im.width, wrap_u);
  y = wrap_index(static_cast<int>(floorf(wrap_coordinate(v, wrap_v) * im.height)), im.height, wrap_v);
}

// The nearest texel of the full image.
WT_HD WT_INLINE vec3 sample_image_nearest(const ImageView& im, float u, float v, Wrap wrap_u, Wrap wrap_v) {
  int x, y;
  nearest_texel(im, u, v, wrap_u, wrap_v, x, y);
  return image_texel(im, x, y);
}

// Bilinear lookup of the full image (by default u repeats and v clamps, the
// spheres' mapping).
WT_HD WT_INLINE vec3 sample_image(const ImageView& im, float u, float v, Wrap wrap_u = Wrap::Repeat,
                                  Wrap wrap_v = Wrap::Clamp) {
  return bilinear(im.width, im.height, u, v, wrap_u, wrap_v,
                  [&](int x, int y) { return image_texel(im, x, y); });
}

// Bilinear lookup of mip level `level` (0: the full image).
WT_HD WT_INLINE vec3 sample_image_level(const ImageView& im, int level, float u, float v, Wrap wrap_u, Wrap wrap_v) {
  if (level <= 0) return sample_image(im, u, v, wrap_u, wrap_v);
  int w, h, row;
  mip_level_shape(im, level, w, h, row);
  int pitch = im.width > 1 ? im.width / 2 : 1;
  return bilinear(w, h, u, v, wrap_u, wrap_v, [&](int x, int y) { return mip_texel(im, pitch, x, y + row); });
}

// Trilinear lookup at level of detail `lod` (log2 of the footprint in texels of
// level 0): the two levels about it, blended linearly; the full image alone at
// lod <= 0 (magnified), the coarsest level alone beyond it. Continuous in lod, so
// that a level of detail off by rounding changes the result only by as much.
WT_HD WT_INLINE vec3 sample_image_lod(const ImageView& im, float lod, float u, float v, Wrap wrap_u, Wrap wrap_v) {
  if (!(lod > 0.0f) || im.levels <= 1) return sample_image(im, u, v, wrap_u, wrap_v);
  const float top = static_cast<float>(im.levels - 1);
  if (lod >= top) return sample_image_level(im, im.levels - 1, u, v, wrap_u, wrap_v);
  const float fl = floorf(lod);
  const int l = static_cast<int>(fl);
  const float t = lod - fl;
  const vec3 a = sample_image_level(im, l, u, v, wrap_u, wrap_v);
  if (!(t > 0.0f)) return a;
  return (1.0f - t) * a + t * sample_image_level(im, l + 1, u, v, wrap_u, wrap_v);
}

// The spherical mapping of the reference scene, from the unit normal at the hit.
WT_HD WT_INLINE vec2 sphere_uv(const vec3& n) {
  float u = 0.5f + atan2f(n.z, n.x) * (0.5f / kPi);
  float v = 0.5f - asinf(fminf(fmaxf(n.y, -1.0f), 1.0f)) / kPi;
  return vec2(u, v);
}

// The UV density (SurfacePoint::uv_density) of a sphere's mapping at its point:
// u runs once around a circle of radius r sin(theta), v once from pole to pole, so
// the square root of (du/dl)(dv/dl) is 1 / (pi r sqrt(2 sin theta)); sin theta is
// kept above 1e-4 at the poles, where u's circles shrink to a point.
// The sphere's radius at sp and sin(theta) of its point, kept above 1e-4.
WT_HD WT_INLINE void sphere_radius_and_sin_theta(const SurfacePoint& sp, float& r, float& sin_theta) {
  r = sqrtf(glm::dot(sp.local, sp.local));
  sin_theta = fmaxf(sqrtf(fmaxf(1.0f - sp.n.y * sp.n.y, 0.0f)), 1e-4f);
}

WT_HD WT_INLINE float sphere_uv_density(const SurfacePoint& sp) {
  float r, sin_theta;
  sphere_radius_and_sin_theta(sp, r, sin_theta);
  return r > 0.0f ? 1.0f / (kPi * r * sqrtf(2.0f * sin_theta)) : 0.0f;
}

// The same mapping's UV units per unit length along u and along v apart:
// 1 / (2 pi r sin theta) and 1 / (pi r).
WT_HD WT_INLINE vec2 sphere_uv_rates(const SurfacePoint& sp) {
  float r, sin_theta;
  sphere_radius_and_sin_theta(sp, r, sin_theta);
  return r > 0.0f ? vec2(0.5f / (kPi * r * sin_theta), 1.0f / (kPi * r)) : vec2(0.0f);
}

// An image texture's level of detail at sp: log2 of the pixel's footprint there in
// texels of the full image (the footprint's world width times the UV density, the
// larger of the transform's scales, and the image's larger side), as ray cones give
// it (Akenine-Moller et al. 2019) with pbrt-v4's footprint from the camera.
WT_HD WT_INLINE float texture_lod(const Texture& t, const ImageView& im, const SurfacePoint& sp) {
  const float density = sp.has_uv ? sp.uv_density : sphere_uv_density(sp);
  const float scale = fmaxf(fabsf(t.uv_scale.x), fabsf(t.uv_scale.y));
  const float texels = sp.footprint * density * scale * static_cast<float>(im.width > im.height ? im.width : im.height);
  return texels > 0.0f ? log2f(texels) : 0.0f;
}

// Gradient noise on the integer lattice; gradients come from a hash of the lattice
// point, so no permutation table has to live in memory. Range about [-1, 1].
WT_HD WT_INLINE vec3 lattice_gradient(int x, int y, int z) {
  uint32_t h = hash_u32(static_cast<uint32_t>(x) * 0x8da6b343u ^ static_cast<uint32_t>(y) * 0xd8163841u ^
                        static_cast<uint32_t>(z) * 0xcb1ab31fu);
  float gz = 1.0f - 2.0f * ((h & 0xffffu) * (1.0f / 65536.0f));
  float r = sqrtf(fmaxf(0.0f, 1.0f - gz * gz));
  float phi = 2.0f * kPi * ((h >> 16) * (1.0f / 65536.0f));
  return vec3(r * cosf(phi), r * sinf(phi), gz);
}

WT_HD WT_INLINE float gradient_noise(const vec3& p) {
  float fx = floorf(p.x), fy = floorf(p.y), fz = floorf(p.z);
  int ix = static_cast<int>(fx), iy = static_cast<int>(fy), iz = static_cast<int>(fz);
  vec3 f(p.x - fx, p.y - fy, p.z - fz);
  vec3 w = f * f * f * (f * (f * 6.0f - 15.0f) + 10.0f);  // quintic fade
  float acc = 0.0f;
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        vec3 g = lattice_gradient(ix + dx, iy + dy, iz + dz);
        float d = glm::dot(g, f - vec3(dx, dy, dz));
        float wx = dx ? w.x : 1.0f - w.x, wy = dy ? w.y : 1.0f - w.y, wz = dz ? w.z : 1.0f - w.z;
        acc += wx * wy * wz * d;
      }
  return acc;
}

// Sum of |noise| over octaves of doubling frequency and halving weight.
WT_HD WT_INLINE float turbulence(vec3 p, int octaves) {
  float sum = 0.0f, weight = 1.0f;
  for (int i = 0; i < octaves; ++i) {
    sum += weight * fabsf(gradient_noise(p));
    weight *= 0.5f;
    p *= 2.0f;
  }
  return sum;
}

// An image texture's coordinates from the surface's: scaled, rotated and offset
// (the UV transform), before they are wrapped.
WT_HD WT_INLINE vec2 texture_uv(const Texture& t, vec2 uv) {
  if (WT_MUTANT(TextureVFlipped)) uv.y = 1.0f - uv.y;
  const vec2 s = uv * t.uv_scale;
  return t.uv_offset + vec2(t.uv_cos * s.x + t.uv_sin * s.y, t.uv_cos * s.y - t.uv_sin * s.x);
}

// The luminance Y of a linear Rec. 709 colour (what a texture's value means where
// one number is read from it: a height, an opacity, a blend's weight).
WT_HD WT_INLINE float luminance(const vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

// Procedural textures are functions of the object-space point (a sphere's: relative
// to its centre); images are looked up by the surface's UVs (a sphere's from its normal).
// Filtered = false: compiled for kernels without the mip-mapped lookup (the study's
// scenes: geometry.hpp's kMicrofacet), where every image is looked up bilinearly.
template <bool Filtered = true>
WT_HD WT_INLINE vec3 eval_texture(const Texture& t, const ImageView* images, const SurfacePoint& sp) {
  const vec3& local = sp.local;
  switch (t.kind) {
    case TextureKind::Checker: {
      int parity = static_cast<int>(floorf(local.x / t.scale)) + static_cast<int>(floorf(local.z / t.scale));
      return (parity & 1) ? t.b : t.a;
    }
    case TextureKind::Noise: {
      // Marble veins: a sine along z, bent by turbulence.
      float s = 0.5f * (1.0f + sinf(t.scale * local.z + 10.0f * turbulence(t.scale * local, t.octaves)));
      return t.b + s * (t.a - t.b);
    }
    case TextureKind::Image: {
      const vec2 uv = texture_uv(t, sp.has_uv ? sp.uv : sphere_uv(sp.n));
      const ImageView& im = images[t.image];
      if constexpr (Filtered) {
        // The level of detail only where minifying and magnifying differ.
        if (sp.footprint > 0.0f && (t.filter != t.magnify || (t.filter == Filter::Trilinear && im.levels > 1))) {
          const float lod = texture_lod(t, im, sp);
          if (lod > 0.0f) {
            if (t.filter == Filter::Trilinear && im.levels > 1) {
              return sample_image_lod(im, lod, uv.x, uv.y, t.wrap_u, t.wrap_v);
            }
            if (t.filter == Filter::Nearest) return sample_image_nearest(im, uv.x, uv.y, t.wrap_u, t.wrap_v);
            return sample_image(im, uv.x, uv.y, t.wrap_u, t.wrap_v);
          }
        }
      }
      if (t.magnify == Filter::Nearest) return sample_image_nearest(im, uv.x, uv.y, t.wrap_u, t.wrap_v);
      return sample_image(im, uv.x, uv.y, t.wrap_u, t.wrap_v);
    }
  }
  return vec3(0.0f);
}

}  // namespace wt

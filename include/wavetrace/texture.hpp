// Textures: procedural (checker, gradient noise) and images. An image is sampled
// with the same bilinear arithmetic on every backend; on the GPU its texels come
// through a CUDA texture object, on the CPU from host memory.
#pragma once

#include "wavetrace/geometry/surface.hpp"
#include "wavetrace/mutant.hpp"
#include "wavetrace/rng.hpp"

namespace wt {

enum class TextureKind : uint32_t { Checker = 0, Noise = 1, Image = 2 };

// How an image texture's coordinates outside [0, 1] fall on it, per axis.
enum class Wrap : uint32_t { Repeat = 0, Clamp = 1, Mirror = 2 };

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
};

// An image texture of image `image`, untransformed, wrapping u and v as given.
inline Texture image_texture(int32_t image, Wrap wrap_u, Wrap wrap_v) {
  Texture t{};
  t.kind = TextureKind::Image;
  t.image = image;
  t.uv_scale = vec2(1.0f);
  t.uv_cos = 1.0f;
  t.wrap_u = wrap_u;
  t.wrap_v = wrap_v;
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
struct ImageView {
  unsigned long long object;
  const float* texels;  // RGBA, row-major, row 0 = top (v = 0)
  int32_t width, height;
};

WT_HD WT_INLINE vec3 image_texel(const ImageView& im, int x, int y) {
#if defined(__CUDA_ARCH__)
  float4 t = tex2D<float4>(static_cast<cudaTextureObject_t>(im.object), x + 0.5f, y + 0.5f);
  return vec3(t.x, t.y, t.z);
#else
  const float* p = im.texels + 4 * (static_cast<size_t>(y) * im.width + x);
  return vec3(p[0], p[1], p[2]);
#endif
}

// Bilinear lookup (texel centres at half-integers), u and v wrapped by their modes
// (by default u repeats and v clamps, the spheres' mapping).
WT_HD WT_INLINE vec3 sample_image(const ImageView& im, float u, float v, Wrap wrap_u = Wrap::Repeat,
                                  Wrap wrap_v = Wrap::Clamp) {
  float x = wrap_coordinate(u, wrap_u) * im.width - 0.5f;
  float y = wrap_coordinate(v, wrap_v) * im.height - 0.5f;
  float fx = floorf(x), fy = floorf(y);
  float ax = x - fx, ay = y - fy;
  int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  int x1 = x0 + 1, y1 = y0 + 1;
  wrap_taps(x0, x1, im.width, wrap_u);
  wrap_taps(y0, y1, im.height, wrap_v);
  vec3 top = (1.0f - ax) * image_texel(im, x0, y0) + ax * image_texel(im, x1, y0);
  vec3 bottom = (1.0f - ax) * image_texel(im, x0, y1) + ax * image_texel(im, x1, y1);
  return (1.0f - ay) * top + ay * bottom;
}

// The spherical mapping of the reference scene, from the unit normal at the hit.
WT_HD WT_INLINE vec2 sphere_uv(const vec3& n) {
  float u = 0.5f + atan2f(n.z, n.x) * (0.5f / kPi);
  float v = 0.5f - asinf(fminf(fmaxf(n.y, -1.0f), 1.0f)) / kPi;
  return vec2(u, v);
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

// Procedural textures are functions of the object-space point (a sphere's: relative
// to its centre); images are looked up by the surface's UVs (a sphere's from its normal).
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
      vec2 uv = sp.has_uv ? sp.uv : sphere_uv(sp.n);
      if (WT_MUTANT(TextureVFlipped)) uv.y = 1.0f - uv.y;
      const vec2 s = uv * t.uv_scale;
      uv = t.uv_offset + vec2(t.uv_cos * s.x + t.uv_sin * s.y, t.uv_cos * s.y - t.uv_sin * s.x);
      return sample_image(images[t.image], uv.x, uv.y, t.wrap_u, t.wrap_v);
    }
  }
  return vec3(0.0f);
}

}  // namespace wt

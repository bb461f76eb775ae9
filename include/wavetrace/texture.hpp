// Textures: procedural (checker, gradient noise) and images. An image is sampled
// with the same bilinear arithmetic on every backend; on the GPU its texels come
// through a CUDA texture object, on the CPU from host memory.
#pragma once

#include "wavetrace/geometry/surface.hpp"
#include "wavetrace/mutant.hpp"
#include "wavetrace/rng.hpp"

namespace wt {

enum class TextureKind : uint32_t { Checker = 0, Noise = 1, Image = 2 };

struct Texture {
  TextureKind kind;
  int32_t image;  // index into the scene's images (Image only)
  float scale;    // Checker: square size; Noise: spatial frequency
  int32_t octaves;
  vec3 a;  // Checker: colour of even squares; Noise: the colour at 1
  vec3 b;  // Checker: colour of odd squares;  Noise: the colour at 0
};

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

// Bilinear lookup: u wraps, v clamps (texel centres at half-integers).
WT_HD WT_INLINE vec3 sample_image(const ImageView& im, float u, float v) {
  float x = (u - floorf(u)) * im.width - 0.5f;
  float y = fminf(fmaxf(v, 0.0f), 1.0f) * im.height - 0.5f;
  float fx = floorf(x), fy = floorf(y);
  float ax = x - fx, ay = y - fy;
  int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  int x1 = x0 + 1, y1 = y0 + 1;
  x0 = x0 < 0 ? x0 + im.width : x0;
  x1 = x1 >= im.width ? x1 - im.width : x1;
  y0 = y0 < 0 ? 0 : y0;
  y1 = y1 >= im.height ? im.height - 1 : y1;
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
      return sample_image(images[t.image], uv.x, uv.y);
    }
  }
  return vec3(0.0f);
}

}  // namespace wt

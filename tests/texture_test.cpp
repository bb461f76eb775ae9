// Textures: the checker parity rule of docs/scene-format.md, the spherical (u, v)
// mapping, bilinear image lookup with its wrap modes and UV transform, and the
// gradient noise behind the marble texture.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "wavetrace/texture.hpp"

namespace wt {
namespace {

const vec3 kEven(0.9f, 0.8f, 0.7f);
const vec3 kOdd(0.1f, 0.2f, 0.3f);

Texture checker(float size) {
  Texture t = image_texture(-1, Wrap::Repeat, Wrap::Clamp);
  t.kind = TextureKind::Checker;
  t.scale = size;
  t.a = kEven;
  t.b = kOdd;
  return t;
}

// A sphere's surface point: local position and normal, UVs from the normal.
SurfacePoint sphere_point(const vec3& local, const vec3& n) {
  SurfacePoint sp{};
  sp.local = local;
  sp.n = n;
  sp.ng = n;
  sp.has_uv = false;
  return sp;
}

vec3 eval_at(const Texture& t, const vec3& local) {
  return eval_texture(t, nullptr, sphere_point(local, glm::normalize(local + vec3(0.0f, 1e-3f, 0.0f))));
}

TEST(Texture, CheckerFollowsTheParityOfFloorXPlusFloorZ) {
  // docs/scene-format.md: `odd` where floor(x/size) + floor(z/size) is odd, with x, z
  // relative to the sphere's centre; y plays no part.
  const Texture t = checker(4.0f);
  struct Case {
    vec3 p;
    bool odd;
  };
  const Case cases[] = {
      {vec3(1.0f, 0.0f, 1.0f), false},      // 0 + 0
      {vec3(5.0f, 0.0f, 1.0f), true},       // 1 + 0
      {vec3(5.0f, 0.0f, 5.0f), false},      // 1 + 1
      {vec3(-1.0f, 0.0f, 1.0f), true},      // -1 + 0: floor, not truncation
      {vec3(-1.0f, 0.0f, -1.0f), false},    // -1 + -1
      {vec3(-5.0f, 3.0f, 1.0f), false},     // -2 + 0
      {vec3(-9.0f, -7.0f, 2.0f), true},     // -3 + 0: odd negative parity
      {vec3(-0.01f, 0.0f, 0.01f), true},    // just left of the x = 0 line
      {vec3(0.01f, 0.0f, 0.01f), false},    // just right of it
      {vec3(7.99f, 0.0f, -4.01f), true},    // 1 + -2
      {vec3(7.99f, 0.0f, -8.01f), false},   // 1 + -3
      {vec3(1000.0f, 0.0f, -1000.0f), false},  // 250 + -250 (the ground's scale)
      {vec3(-1002.0f, 0.0f, 3.0f), true},   // -251 + 0
  };
  for (const Case& c : cases) {
    vec3 got = eval_at(t, c.p);
    EXPECT_EQ(got, c.odd ? kOdd : kEven) << c.p.x << "," << c.p.y << "," << c.p.z;
  }
  // y does not matter.
  for (float y : {-100.0f, -1.0f, 0.0f, 2.5f, 50.0f}) EXPECT_EQ(eval_at(t, vec3(5.0f, y, 1.0f)), kOdd) << y;
  // The square size scales the pattern.
  EXPECT_EQ(eval_at(checker(0.5f), vec3(0.75f, 0.0f, 0.25f)), kOdd);  // 1 + 0
  EXPECT_EQ(eval_at(checker(0.5f), vec3(-0.75f, 0.0f, 0.25f)), kEven);  // -2 + 0
}

TEST(Texture, SphereUvMapsAxesAndPoles) {
  // u = 0.5 + atan2(n.z, n.x) / 2pi, v = 0.5 - asin(n.y) / pi.
  auto uv = [](float x, float y, float z) { return sphere_uv(vec3(x, y, z)); };
  EXPECT_NEAR(uv(1, 0, 0).x, 0.5f, 1e-7f);
  EXPECT_NEAR(uv(1, 0, 0).y, 0.5f, 1e-7f);
  EXPECT_NEAR(uv(0, 0, 1).x, 0.75f, 1e-7f);
  EXPECT_NEAR(uv(0, 0, -1).x, 0.25f, 1e-7f);
  // -x is the seam: u is 0 or 1 there.
  float seam = uv(-1, 0, 0).x;
  EXPECT_TRUE(std::fabs(seam - 1.0f) < 1e-7f || std::fabs(seam) < 1e-7f) << seam;
  // Poles: v = 0 at the top (n.y = 1), v = 1 at the bottom.
  EXPECT_NEAR(uv(0, 1, 0).y, 0.0f, 1e-7f);
  EXPECT_NEAR(uv(0, -1, 0).y, 1.0f, 1e-7f);
  // 45 degrees up: v = 0.25.
  EXPECT_NEAR(uv(std::sqrt(0.5f), std::sqrt(0.5f), 0).y, 0.25f, 1e-6f);
  // Slightly non-unit normals at the poles must not produce NaN (asin is clamped).
  vec2 over = sphere_uv(vec3(0.0f, 1.0000001f, 0.0f));
  EXPECT_FALSE(std::isnan(over.y));
  EXPECT_NEAR(over.y, 0.0f, 1e-6f);
  // Either side of the seam: u near 1 above it (z > 0), near 0 below it, so with u
  // wrapping the two sides are neighbours.
  EXPECT_NEAR(uv(-1, 0, 1e-4f).x, 1.0f, 1e-4f);
  EXPECT_NEAR(uv(-1, 0, -1e-4f).x, 0.0f, 1e-4f);
  for (float z : {1e-4f, -1e-4f, 0.5f, -0.5f}) {
    float u = uv(-1, 0, z).x;
    EXPECT_GE(u, 0.0f);
    EXPECT_LE(u, 1.0f);
  }
}

// A 4 x 2 RGBA image whose texel (x, y) has red = x, green = y, blue = 10x + y.
struct TinyImage {
  std::vector<float> texels;
  ImageView view;
  TinyImage() {
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 4; ++x) {
        texels.push_back(float(x));
        texels.push_back(float(y));
        texels.push_back(float(10 * x + y));
        texels.push_back(1.0f);
      }
    view = ImageView{0, texels.data(), 4, 2};
  }
  vec3 texel(int x, int y) const { return vec3(float(x), float(y), float(10 * x + y)); }
};

TEST(Texture, SampleImageIsExactAtTexelCentresAndAveragesBetween) {
  TinyImage im;
  // Texel centres at u = (x + 0.5) / 4, v = (y + 0.5) / 2.
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x)
      EXPECT_EQ(sample_image(im.view, (x + 0.5f) / 4.0f, (y + 0.5f) / 2.0f), im.texel(x, y)) << x << "," << y;
  // Midway between horizontal neighbours (u = (x + 1) / 4): their average.
  EXPECT_EQ(sample_image(im.view, 0.5f, 0.25f), 0.5f * (im.texel(1, 0) + im.texel(2, 0)));
  // Midway between the two rows (v = 0.5).
  EXPECT_EQ(sample_image(im.view, 0.375f, 0.5f), 0.5f * (im.texel(1, 0) + im.texel(1, 1)));
  // The centre of four texels: their mean.
  EXPECT_EQ(sample_image(im.view, 0.25f, 0.5f),
            0.25f * (im.texel(0, 0) + im.texel(1, 0) + im.texel(0, 1) + im.texel(1, 1)));
  // A quarter of the way: bilinear weights 3/4, 1/4.
  vec3 q = sample_image(im.view, 0.125f + 0.0625f, 0.25f);
  EXPECT_NEAR(q.x, 0.25f, 1e-6f);
  EXPECT_NEAR(q.z, 2.5f, 1e-6f);
}

TEST(Texture, SampleImageWrapsUAndClampsV) {
  TinyImage im;
  // u = 0 (and 1) lies between the last column's centre and the first's: their average.
  const vec3 edge = 0.5f * (im.texel(3, 0) + im.texel(0, 0));
  EXPECT_EQ(sample_image(im.view, 0.0f, 0.25f), edge);
  EXPECT_EQ(sample_image(im.view, 1.0f, 0.25f), edge);
  // u outside [0, 1] wraps by whole turns.
  EXPECT_EQ(sample_image(im.view, 1.375f, 0.25f), im.texel(1, 0));
  EXPECT_EQ(sample_image(im.view, -0.625f, 0.25f), im.texel(1, 0));
  // Just left of u = 0: mostly the last column.
  vec3 left = sample_image(im.view, -0.03125f, 0.25f);  // x = 3.375: 3/8 of the way 3 -> 0
  EXPECT_NEAR(left.x, 3.0f * 0.625f + 0.0f * 0.375f, 1e-6f);
  // A value that rounds to u - floor(u) == 1 must still wrap, not read past the row.
  vec3 tiny = sample_image(im.view, -1e-9f, 0.25f);
  EXPECT_EQ(tiny, edge);
  // v clamps: everything above the first row's centre is the first row, everything
  // below the last row's centre is the last row.
  // (The two bilinear weights of one row may sum to 1 within a float ulp.)
  for (float v : {-3.0f, -0.1f, 0.0f, 0.1f, 0.25f}) {
    vec3 got = sample_image(im.view, 0.375f, v);
    EXPECT_NEAR(glm::length(got - im.texel(1, 0)), 0.0f, 1e-5f) << v;
  }
  for (float v : {0.75f, 0.9f, 1.0f, 1.5f, 40.0f}) {
    vec3 got = sample_image(im.view, 0.375f, v);
    EXPECT_NEAR(glm::length(got - im.texel(1, 1)), 0.0f, 1e-5f) << v;
  }
}

// The wrap modes on texel indices: repeat by whole periods, clamp to the edge,
// mirror reflects about each edge (period 2n: ..., 1, 0 | 0, 1, ..., n-1 | n-1, ...).
TEST(Texture, WrapIndicesRepeatClampAndMirror) {
  EXPECT_EQ(wrap_index(-1, 4, Wrap::Repeat), 3);
  EXPECT_EQ(wrap_index(4, 4, Wrap::Repeat), 0);
  EXPECT_EQ(wrap_index(-1, 4, Wrap::Clamp), 0);
  EXPECT_EQ(wrap_index(4, 4, Wrap::Clamp), 3);
  const int mirrored[] = {2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0, 1};  // i = -3 .. 9
  for (int i = -3; i <= 9; ++i) EXPECT_EQ(wrap_index(i, 4, Wrap::Mirror), mirrored[i + 3]) << i;
}

// Coordinates outside [0, 1] by mode, on the 4 x 2 image: u = 1.375 is column 1
// repeated, column 3 clamped (past the last centre), column 2 mirrored (the
// reflection of u = 0.625 about 1).
TEST(Texture, SampleImageWrapsByItsModes) {
  TinyImage im;
  EXPECT_EQ(sample_image(im.view, 1.375f, 0.25f, Wrap::Repeat, Wrap::Clamp), im.texel(1, 0));
  EXPECT_EQ(sample_image(im.view, 1.375f, 0.25f, Wrap::Clamp, Wrap::Clamp), im.texel(3, 0));
  EXPECT_EQ(sample_image(im.view, 1.375f, 0.25f, Wrap::Mirror, Wrap::Clamp), im.texel(2, 0));
  EXPECT_EQ(sample_image(im.view, -0.375f, 0.25f, Wrap::Mirror, Wrap::Clamp), im.texel(1, 0));
  // v repeating: v = 1.25 is row 0 again; mirrored, row 1.
  EXPECT_EQ(sample_image(im.view, 0.375f, 1.25f, Wrap::Repeat, Wrap::Repeat), im.texel(1, 0));
  EXPECT_EQ(sample_image(im.view, 0.375f, 1.25f, Wrap::Repeat, Wrap::Mirror), im.texel(1, 1));
  // At a mirrored edge the two taps are the same texel: no blend with the far side.
  EXPECT_EQ(sample_image(im.view, 0.0f, 0.25f, Wrap::Mirror, Wrap::Clamp), im.texel(0, 0));
}

// The UV transform (KHR_texture_transform's order: scale, rotate, offset) applied
// before the lookup, on a mesh point's UVs.
TEST(Texture, UvTransformScalesRotatesAndOffsets) {
  TinyImage im;
  const ImageView images[] = {im.view};
  SurfacePoint sp{};
  sp.has_uv = true;
  auto at = [&](const Texture& t, float u, float v) {
    sp.uv = vec2(u, v);
    return eval_texture(t, images, sp);
  };
  const Texture plain = image_texture(0, Wrap::Repeat, Wrap::Repeat);
  Texture scaled = plain;
  scaled.uv_scale = vec2(2.0f, 0.5f);
  EXPECT_EQ(at(scaled, 0.1875f, 0.5f), at(plain, 0.375f, 0.25f));
  Texture shifted = plain;
  shifted.uv_offset = vec2(0.25f, 0.5f);
  EXPECT_EQ(at(shifted, 0.125f, 0.25f), at(plain, 0.375f, 0.75f));
  // A quarter turn: (u, v) -> (v, -u).
  Texture turned = plain;
  turned.uv_cos = std::cos(0.5f * 3.14159265f);
  turned.uv_sin = std::sin(0.5f * 3.14159265f);
  const vec3 got = at(turned, 0.25f, 0.375f), want = at(plain, 0.375f, -0.25f);
  EXPECT_NEAR(glm::length(got - want), 0.0f, 1e-4f);
}

TEST(Texture, ImageTextureIsContinuousAcrossTheSeam) {
  // Through eval_texture: normals just either side of the -x seam read nearly the
  // same colour (u wraps there, so both sides blend the first and last columns).
  TinyImage im;
  const Texture t = image_texture(0, Wrap::Repeat, Wrap::Clamp);
  const ImageView images[] = {im.view};
  for (float y : {-0.5f, 0.0f, 0.3f}) {
    vec3 a = eval_texture(t, images, sphere_point(vec3(0.0f), glm::normalize(vec3(-1.0f, y, 1e-4f))));
    vec3 b = eval_texture(t, images, sphere_point(vec3(0.0f), glm::normalize(vec3(-1.0f, y, -1e-4f))));
    // d u = 2e-4 / 2pi turns = 1.3e-4 texels of a 4-wide image, times a texel-to-texel
    // step of at most 30 in blue.
    EXPECT_NEAR(a.x, b.x, 1e-3f) << y;
    EXPECT_NEAR(a.z, b.z, 1e-2f) << y;
  }
}

TEST(Texture, GradientNoiseVanishesOnLatticePoints) {
  for (int x = -3; x <= 3; ++x)
    for (int y = -3; y <= 3; ++y)
      for (int z = -3; z <= 3; ++z) EXPECT_EQ(gradient_noise(vec3(float(x), float(y), float(z))), 0.0f);
  EXPECT_EQ(gradient_noise(vec3(-1000.0f, 17.0f, 123456.0f)), 0.0f);
  // Between lattice points it is not identically zero.
  int nonzero = 0;
  for (int i = 0; i < 100; ++i) nonzero += std::fabs(gradient_noise(vec3(0.37f * i, 0.5f, -0.21f * i))) > 1e-3f;
  EXPECT_GT(nonzero, 50);
}

TEST(Texture, GradientNoiseSlopeAtALatticePointIsItsGradient) {
  // The quintic fade has zero first and second derivatives at 0 and 1, so at a
  // lattice point only that point's own term varies to first order: the noise's
  // gradient there is the lattice gradient. A central difference of step 1e-3 has
  // error O(h^2) from the own term and O(h^3) from the others; 2e-3 is generous.
  for (int x = -2; x <= 2; ++x)
    for (int y = -2; y <= 2; ++y)
      for (int z = -1; z <= 1; ++z) {
        const vec3 lp{float(x), float(y), float(z)};
        const vec3 g = lattice_gradient(x, y, z);
        EXPECT_NEAR(glm::length(g), 1.0f, 1e-5f);
        const float h = 1e-3f;
        for (int k = 0; k < 3; ++k) {
          vec3 e(0.0f);
          e[k] = h;
          float slope = (gradient_noise(lp + e) - gradient_noise(lp - e)) / (2.0f * h);
          EXPECT_NEAR(slope, g[k], 2e-3f) << x << "," << y << "," << z << " axis " << k;
        }
      }
}

TEST(Texture, GradientNoiseIsContinuousAcrossCells) {
  // The noise is Lipschitz: along any axis its derivative is at most
  // 2 * 1.875 * sqrt(3) (the fade's slope times the largest corner term, over the
  // two corners whose weight changes) + 1 (the gradients' own component) < 7.6, so
  // |noise(p + e) - noise(p)| <= 7.6 * sqrt(3) |e| < 13.2 |e|. A jump at a cell face
  // (a wrong corner, a truncating floor at negative coordinates) breaks this.
  std::mt19937 gen(4242);
  std::uniform_real_distribution<float> pos(-20.0f, 20.0f), tiny(-1e-3f, 1e-3f);
  for (int i = 0; i < 20000; ++i) {
    vec3 p(pos(gen), pos(gen), pos(gen));
    // Half of the points are snapped next to a cell face (x near an integer).
    if (i % 2 == 0) p.x = std::round(p.x) + 1e-4f * (i % 4 == 0 ? 1.0f : -1.0f);
    vec3 e(tiny(gen), tiny(gen), tiny(gen));
    if (i % 2 == 0) e.x = p.x > std::round(p.x) ? -2e-4f : 2e-4f;  // step across the face
    float a = gradient_noise(p), b = gradient_noise(p + e);
    // Slack for float rounding of the positions (~2e-6 at |p| = 20) and the sum.
    EXPECT_LE(std::fabs(a - b), 13.2f * glm::length(e) + 1e-4f) << p.x << "," << p.y << "," << p.z;
  }
}

TEST(Texture, NoiseTextureStaysBetweenItsColoursAndVaries) {
  const vec3 high(1.0f, 0.9f, 0.8f), low(0.1f, 0.2f, 0.05f);
  Texture t = checker(4.0f);
  t.kind = TextureKind::Noise;
  t.octaves = 7;
  t.a = high;
  t.b = low;
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> pos(-1.0f, 1.0f);
  float min_s = 1.0f, max_s = 0.0f;
  for (int i = 0; i < 20000; ++i) {
    vec3 local(pos(gen), pos(gen), pos(gen));
    vec3 c = eval_at(t, local);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(c[k], low[k] - 1e-6f);
      EXPECT_LE(c[k], high[k] + 1e-6f);
    }
    // Where between low and high (the same fraction in every channel).
    float s = (c.x - low.x) / (high.x - low.x);
    EXPECT_NEAR((c.y - low.y) / (high.y - low.y), s, 1e-5f);
    min_s = std::fmin(min_s, s);
    max_s = std::fmax(max_s, s);
  }
  // Marble veins sweep the whole range over a unit ball at scale 4.
  EXPECT_LT(min_s, 0.05f);
  EXPECT_GT(max_s, 0.95f);
  // And vary in space: two points 0.5 apart differ (not a constant texture).
  EXPECT_NE(eval_at(t, vec3(0.1f, 0.2f, 0.3f)), eval_at(t, vec3(0.1f, 0.2f, 0.8f)));
}

}  // namespace
}  // namespace wt

// Bump (height) maps: the image of a height map's derivatives (height_gradient),
// the test that tells a normal map from heights (reads_as_normal_map), the bumped
// normal's analytic cases (bumped_normal: a triangle's and a sphere's UV rates, the
// UV transform), and the scene reader's bump maps: a scene file's bump_texture and
// its errors, and MTL's bump, read as heights or, where its texels are a normal
// map's, as that. Renders: material_render_test.cpp (a ramp lights as the tilted
// quad; every kernel and backend renders bump maps alike).
#include <gtest/gtest.h>

#include <stb/stb_image_write.h>

#include <cmath>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "render_support.hpp"
#include "scene/height_maps.hpp"
#include "test_support.hpp"
#include "wavetrace/bsdf.hpp"

namespace wt {
namespace {

// A grey image of w x h texels, heights(x, y).
template <class F>
Image grey(int w, int h, const F& heights) {
  Image im;
  im.width = w;
  im.height = h;
  im.texels.assign(static_cast<size_t>(w) * h * 4, 1.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float* t = &im.texels[4 * (static_cast<size_t>(y) * w + x)];
      t[0] = t[1] = t[2] = heights(x, y);
    }
  }
  return im;
}

vec2 gradient_at(const Image& g, int x, int y) {
  const float* t = &g.texels[4 * (static_cast<size_t>(y) * g.width + x)];
  return vec2(t[0], t[1]);
}

// Inside the image, central differences times the side's texels; at the edges,
// joined by Repeat, one-sided where Clamp or Mirror ends the image.
TEST(HeightGradient, CentralDifferencesPerUnitOfTheCoordinates) {
  // h = 0.01 x + 0.03 y over 8 x 4 texels: dh/du = 0.01 * 8, dh/dv = 0.03 * 4.
  const Image ramp = grey(8, 4, [](int x, int y) { return 0.01f * x + 0.03f * y; });
  const Image clamped = height_gradient(ramp, HeightChannel::Luminance, Wrap::Clamp, Wrap::Mirror);
  ASSERT_EQ(clamped.width, 8);
  ASSERT_EQ(clamped.height, 4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 8; ++x) {
      EXPECT_NEAR(gradient_at(clamped, x, y).x, 0.08f, 1e-5f) << x << " " << y;
      EXPECT_NEAR(gradient_at(clamped, x, y).y, 0.12f, 1e-5f) << x << " " << y;
    }
  }
  // Repeat joins the last column to the first: a drop of 0.07 over 2 texels there.
  const Image repeated = height_gradient(ramp, HeightChannel::Luminance, Wrap::Repeat, Wrap::Clamp);
  EXPECT_NEAR(gradient_at(repeated, 3, 1).x, 0.08f, 1e-5f);
  EXPECT_NEAR(gradient_at(repeated, 0, 1).x, (0.01f - 0.07f) / 2.0f * 8.0f, 1e-5f);
  EXPECT_NEAR(gradient_at(repeated, 7, 1).x, (0.0f - 0.06f) / 2.0f * 8.0f, 1e-5f);
  // An axis of one texel has no slope.
  const Image row = grey(4, 1, [](int x, int) { return 0.25f * x; });
  const Image g = height_gradient(row, HeightChannel::Luminance, Wrap::Clamp, Wrap::Repeat);
  EXPECT_NEAR(gradient_at(g, 2, 0).x, 1.0f, 1e-6f);
  EXPECT_EQ(gradient_at(g, 2, 0).y, 0.0f);
}

// The heights are the luminance (Rec. 709), or the channel named.
TEST(HeightGradient, ReadsTheLuminanceOrTheChannelNamed) {
  Image im;
  im.width = 2;
  im.height = 1;
  im.texels = {0, 0, 0, 0, 1.0f, 0.5f, 0.25f, 0.75f};
  auto slope = [&](HeightChannel c) { return gradient_at(height_gradient(im, c, Wrap::Clamp, Wrap::Clamp), 0, 0).x; };
  EXPECT_NEAR(slope(HeightChannel::Luminance), 2.0f * (0.2126f + 0.7152f * 0.5f + 0.0722f * 0.25f), 1e-6f);
  EXPECT_NEAR(slope(HeightChannel::Red), 2.0f, 1e-6f);
  EXPECT_NEAR(slope(HeightChannel::Green), 1.0f, 1e-6f);
  EXPECT_NEAR(slope(HeightChannel::Blue), 0.5f, 1e-6f);
  EXPECT_NEAR(slope(HeightChannel::Alpha), 1.5f, 1e-6f);
}

// A normal map (bluish unit vectors) reads as one; grey heights, a colour photograph
// and a normal map with more than 1% of other texels do not.
TEST(HeightGradient, TellsANormalMapFromHeights) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  auto image = [&](int bad_every) {
    Image im;
    im.width = im.height = 32;
    for (int i = 0; i < 32 * 32; ++i) {
      // A vector within 40 degrees of +z, 8-bit.
      const float phi = 6.2831853f * u(rng), theta = 0.7f * u(rng);
      vec3 c = 0.5f * (vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)) + 1.0f);
      if (bad_every > 0 && i % bad_every == 0) c = vec3(0.9f, 0.1f, 0.1f);
      for (int k = 0; k < 3; ++k) c[k] = std::round(c[k] * 255.0f) / 255.0f;
      im.texels.insert(im.texels.end(), {c.x, c.y, c.z, 1.0f});
    }
    return im;
  };
  EXPECT_TRUE(reads_as_normal_map(image(0)));
  EXPECT_TRUE(reads_as_normal_map(image(200)));  // 0.5% other texels
  EXPECT_FALSE(reads_as_normal_map(image(50)));  // 2%
  EXPECT_FALSE(reads_as_normal_map(grey(16, 16, [&](int, int) { return u(rng); })));
  // A flat normal map is one colour, and still one.
  Image flat;
  flat.width = flat.height = 4;
  for (int i = 0; i < 16; ++i) flat.texels.insert(flat.texels.end(), {0.5f, 0.5f, 1.0f, 1.0f});
  EXPECT_TRUE(reads_as_normal_map(flat));
  Image photo;
  photo.width = photo.height = 16;
  for (int i = 0; i < 256; ++i) photo.texels.insert(photo.texels.end(), {u(rng), u(rng), u(rng), 1.0f});
  EXPECT_FALSE(reads_as_normal_map(photo));
}

// n - grad d on a flat triangle's point: UV density 1/2, a height slope of 1 per
// unit of u times the scale 2 tilts the normal by 45 degrees away from +u; the
// same slope along v, up the image by the handedness, leans it towards up the
// image; a quarter turn of the UV transform carries u' to v.
TEST(BumpedNormal, ATrianglesSlopesTiltItsNormal) {
  SurfacePoint sp{};
  sp.n = vec3(0, 1, 0);
  sp.dpdu = vec3(3, 0.5f, 0);  // not unit, not in the plane: only its direction across n counts
  sp.tangent_sign = 1.0f;      // cross(n, dpdu) = -z is up the image; v grows to +z
  sp.has_uv = true;
  sp.uv_density = 0.5f;
  Texture t = image_texture(0, Wrap::Repeat, Wrap::Repeat);
  const float r = std::sqrt(0.5f);
  auto expect = [](vec3 got, vec3 want) {
    EXPECT_NEAR(got.x, want.x, 1e-6f);
    EXPECT_NEAR(got.y, want.y, 1e-6f);
    EXPECT_NEAR(got.z, want.z, 1e-6f);
  };
  expect(bumped_normal(sp.n, sp, t, vec3(1, 0, 0), 2.0f), vec3(-r, r, 0));
  expect(bumped_normal(sp.n, sp, t, vec3(0, 1, 0), 2.0f), vec3(0, r, -r));
  expect(bumped_normal(sp.n, sp, t, vec3(0, 1, 0), -2.0f), vec3(0, r, r));
  sp.tangent_sign = -1.0f;  // mirrored UVs: v grows to -z
  expect(bumped_normal(sp.n, sp, t, vec3(0, 1, 0), 2.0f), vec3(0, r, r));
  sp.tangent_sign = 1.0f;
  // Rotated a quarter turn, u' = v and v' = -u (texture_uv): a slope along u' is one along v.
  t.uv_cos = 0.0f;
  t.uv_sin = 1.0f;
  expect(bumped_normal(sp.n, sp, t, vec3(1, 0, 0), 2.0f), vec3(0, r, -r));
  expect(bumped_normal(sp.n, sp, t, vec3(0, 1, 0), 2.0f), vec3(r, r, 0));
  // Scaled, u' = 3u: the slope per unit of u is three times the texel's.
  t.uv_cos = 1.0f;
  t.uv_sin = 0.0f;
  t.uv_scale = vec2(3.0f, 1.0f);
  const vec3 steep = bumped_normal(sp.n, sp, t, vec3(1.0f / 3.0f, 0, 0), 2.0f);
  expect(steep, vec3(-r, r, 0));
  // Without a UV density (a mesh without UVs) nothing moves.
  sp.uv_density = 0.0f;
  expect(bumped_normal(sp.n, sp, t, vec3(5, 5, 0), 2.0f), sp.n);
}

// A sphere's u runs once around the circle of radius r sin(theta), its v from pole
// to pole: on the equator of a sphere of radius 2 at +x, where u grows along +z and
// v down to -y, slopes gu and gv per unit of u and v tilt the normal by
// gu / (2 pi r) away from +z and gv / (pi r) towards +y.
TEST(BumpedNormal, ASpheresRatesFollowItsMapping) {
  SurfacePoint sp{};
  sp.local = vec3(2, 0, 0);
  sp.n = vec3(1, 0, 0);
  sp.dpdu = vec3(-sp.local.z, 0, sp.local.x);
  sp.tangent_sign = -1.0f;
  sp.has_uv = false;
  const Texture t = image_texture(0, Wrap::Repeat, Wrap::Repeat);
  const float gu = 3.0f, gv = 1.5f, scale = 0.8f;
  const vec3 want = glm::normalize(vec3(1.0f, scale * gv / (kPi * 2.0f), -scale * gu / (2.0f * kPi * 2.0f)));
  const vec3 got = bumped_normal(sp.n, sp, t, vec3(gu, gv, 0), scale);
  EXPECT_NEAR(got.x, want.x, 1e-6f);
  EXPECT_NEAR(got.y, want.y, 1e-6f);
  EXPECT_NEAR(got.z, want.z, 1e-6f);
}

class BumpScene : public ::testing::Test {
 protected:
  void SetUp() override {
    std::vector<unsigned char> pixels(16 * 16 * 4, 255);
    for (int i = 0; i < 256; ++i) {
      for (int c = 0; c < 3; ++c) pixels[4 * i + c] = static_cast<unsigned char>((i * 37) % 256);
    }
    ASSERT_NE(stbi_write_png(path("heights.png").c_str(), 16, 16, 4, pixels.data(), 64), 0);
    // A normal map: tilted vectors about +z, 8-bit.
    for (int i = 0; i < 256; ++i) {
      const float a = 0.3f * std::sin(0.7f * i), b = 0.3f * std::cos(1.3f * i);
      const float z = std::sqrt(1.0f - a * a - b * b);
      pixels[4 * i + 0] = static_cast<unsigned char>(std::lround(127.5f * (a + 1.0f)));
      pixels[4 * i + 1] = static_cast<unsigned char>(std::lround(127.5f * (b + 1.0f)));
      pixels[4 * i + 2] = static_cast<unsigned char>(std::lround(127.5f * (z + 1.0f)));
    }
    ASSERT_NE(stbi_write_png(path("normals.png").c_str(), 16, 16, 4, pixels.data(), 64), 0);
    std::ofstream(path("quad.obj")) << "mtllib quad.mtl\nv -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\n"
                                       "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 1 0\nusemtl MAT\n"
                                       "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";
  }
  std::string path(const std::string& name) const { return (folder_.root() / name).string(); }
  // The quad under one material, `mtl`'s lines.
  Scene quad_with(const std::string& mtl) const {
    std::ofstream(path("quad.mtl")) << "newmtl MAT\n" << mtl;
    return parse_scene(R"({"camera": {"look_from": [0, 3, 1], "look_at": [0, 0, 0]},
      "materials": [], "meshes": [{"name": "quad", "file": "quad.obj"}], "instances": [{"mesh": "quad"}]})",
                       path("scene.json"));
  }
  std::string error_of(const std::string& materials) const {
    std::ofstream(path("m.json")) << R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
      "textures": [{"name": "h", "type": "image", "file": "heights.png", "colorspace": "linear"},
                   {"name": "srgb", "type": "image", "file": "heights.png"},
                   {"name": "c", "type": "checker", "size": 1, "even": [1, 1, 1], "odd": [0, 0, 0]}],
      "materials": [)" + materials + R"(],
      "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})";
    try {
      load_scene(path("m.json"));
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  test::TestFolder folder_;
};

// A classic material's grey bump map is heights: the material gets parameters
// (the kernels that read them) with the derivatives' texture, its image the size of
// the heights', whose own texels are not kept; -bm scales it, and may be negative.
TEST_F(BumpScene, MtlGreyBumpMapIsHeights) {
  const Scene s = quad_with("Kd 0.5 0.5 0.5\nbump -bm -0.25 heights.png\n");
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].kind, MaterialKind::Lambertian);
  ASSERT_GE(s.materials[0].params, 0);
  const MaterialParams& p = s.material_params[static_cast<size_t>(s.materials[0].params)];
  EXPECT_EQ(p.normal_texture, -1);
  ASSERT_GE(p.bump_texture, 0);
  EXPECT_FLOAT_EQ(p.bump_scale, -0.25f);
  const Image& g = s.images[static_cast<size_t>(s.textures[static_cast<size_t>(p.bump_texture)].image)];
  EXPECT_EQ(g.width, 16);
  EXPECT_EQ(g.height, 16);
  EXPECT_TRUE(s.kernel_kinds() & kMicrofacet);
  // The heights' image itself (read to derive the texture) is one texel now.
  size_t kept = 0;
  for (const Image& im : s.images) kept += im.texels.size();
  EXPECT_EQ(kept, 16u * 16u * 4u + 4u);
}

// A bump map whose texels are a normal map's is that normal map, of strength -bm,
// whatever the material; an -imfchan makes it heights of that channel.
TEST_F(BumpScene, MtlBumpMapOfANormalMapsTexelsIsThatNormalMap) {
  for (const char* kind : {"Kd 0.5 0.5 0.5\n", "Kd 0.5 0.5 0.5\nPr 0.4\n", "Ks 0.9 0.9 0.9\nKd 0 0 0\n"}) {
    SCOPED_TRACE(kind);
    const Scene s = quad_with(std::string(kind) + "map_Bump -bm 0.6 normals.png\n");
    const MaterialParams& p = s.material_params.at(static_cast<size_t>(s.materials.at(0).params));
    EXPECT_EQ(p.bump_texture, -1);
    ASSERT_GE(p.normal_texture, 0);
    EXPECT_FLOAT_EQ(p.normal_strength, 0.6f);
    EXPECT_FALSE(s.images[static_cast<size_t>(s.textures[static_cast<size_t>(p.normal_texture)].image)].srgb_decoded);
  }
  const Scene s = quad_with("Kd 0.5 0.5 0.5\nmap_Bump -imfchan b normals.png\n");
  const MaterialParams& p = s.material_params.at(static_cast<size_t>(s.materials.at(0).params));
  EXPECT_EQ(p.normal_texture, -1);
  EXPECT_GE(p.bump_texture, 0);
}

// A scene file's bump_texture: a linear image texture's heights, times bump_scale;
// one error naming the field otherwise.
TEST_F(BumpScene, SceneFileBumpTextureAndItsErrors) {
  EXPECT_EQ(error_of(R"({"name": "m", "type": "lambertian", "bump_texture": "h", "bump_scale": 0.5})"), "");
  const std::pair<const char*, const char*> cases[] = {
      {R"({"name": "m", "type": "lambertian", "bump_texture": "c"})",
       "/materials/0/bump_texture: a bump map is an image of heights: name an image texture"},
      {R"({"name": "m", "type": "lambertian", "bump_texture": "srgb"})",
       "/materials/0/bump_texture: a bump map holds heights, not colours"},
      {R"({"name": "m", "type": "lambertian", "bump_texture": "nope"})", "/materials/0/bump_texture: unknown texture 'nope'"},
      {R"({"name": "m", "type": "plastic", "normal_texture": "h", "bump_texture": "h"})",
       "/materials/0/bump_texture: a material takes a normal map or a bump map, not both"},
      {R"({"name": "m", "type": "lambertian", "bump_scale": 2})",
       "/materials/0/bump_scale: scales a bump map: give \"bump_texture\" too"},
      {R"({"name": "m", "type": "lambertian", "bump_texture": "h", "bump_scale": 5000})",
       "/materials/0/bump_scale: must be in [-1000, 1000]"},
      {R"({"name": "m", "type": "emissive", "emission": [1, 1, 1], "bump_texture": "h"})", "bump_texture"},
  };
  for (const auto& [material, message] : cases) {
    const std::string e = error_of(material);
    EXPECT_NE(e.find(message), std::string::npos) << material << "\n" << e;
  }
}

// The shipped comparison scene: the heights' image is the normal map's bumps. At
// each texel the heights' central differences (per texel, times H = 15.6 texels)
// give the normal the normal map stores, to the 8-bit rounding of both images
// (within 0.06 in each of x and y) away from the bumps' rims.
TEST(BumpMapScene, TheShippedHeightsAreTheNormalMapsBumps) {
  const Scene s = load_scene(test::repo_path("scenes/bump-single.json"));
  int32_t bump = -1, normal = -1;
  for (const Material& m : s.materials) {
    if (m.params < 0) continue;
    const MaterialParams& p = s.material_params[static_cast<size_t>(m.params)];
    if (p.bump_texture >= 0) bump = bump < 0 ? p.bump_texture : bump;
    if (p.normal_texture >= 0) normal = p.normal_texture;
  }
  ASSERT_GE(bump, 0);
  ASSERT_GE(normal, 0);
  const Image& g = s.images[static_cast<size_t>(s.textures[static_cast<size_t>(bump)].image)];
  const Image& n = s.images[static_cast<size_t>(s.textures[static_cast<size_t>(normal)].image)];
  ASSERT_EQ(g.width, n.width);
  ASSERT_EQ(g.height, n.height);
  const float h = 0.6f * 26.0f / static_cast<float>(g.width);  // H per unit of u, over the texels per unit
  int compared = 0;
  for (size_t i = 0; i < static_cast<size_t>(g.width) * g.height; ++i) {
    const vec3 want = glm::normalize(vec3(-h * g.texels[4 * i], h * g.texels[4 * i + 1], 1.0f));
    const vec3 got = 2.0f * vec3(n.texels[4 * i], n.texels[4 * i + 1], n.texels[4 * i + 2]) - 1.0f;
    if (got.z < 0.9f && got.z > 0.75f) {  // on the flanks: both images well resolved
      EXPECT_NEAR(got.x, want.x, 0.06f) << i;
      EXPECT_NEAR(got.y, want.y, 0.06f) << i;
      ++compared;
    }
  }
  EXPECT_GT(compared, 5000);
}

}  // namespace
}  // namespace wt

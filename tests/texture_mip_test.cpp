// Mip-mapped image textures: the levels the loader builds, the trilinear lookup
// between them, the level of detail a pixel's footprint picks, and renders in which
// a minified texture does not alias (and the bilinear lookup, shown to alias, does),
// with the CPU and the CUDA texture units agreeing to a stated bound.
#include <gtest/gtest.h>

#include <stb/stb_image_write.h>

#include <cmath>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "dispatch/renderer.hpp"
#include "render_support.hpp"
#include "scene/image_mips.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

Image random_image(int w, int h, uint32_t seed) {
  Image im;
  im.width = w;
  im.height = h;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < w * h; ++i) {
    for (int c = 0; c < 3; ++c) im.texels.push_back(u(rng));
    im.texels.push_back(1.0f);
  }
  return im;
}

ImageView view_of(const Image& im) {
  return ImageView{0, im.texels.data(), im.width, im.height, 0, im.mip_texels.data(), im.levels};
}

// The mean colour of mip level `level` (0: the image).
vec3 level_mean(const ImageView& v, int level) {
  int w = v.width, h = v.height, row = 0;
  if (level > 0) mip_level_shape(v, level, w, h, row);
  const int pitch = v.width > 1 ? v.width / 2 : 1;
  glm::dvec3 sum(0.0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) sum += glm::dvec3(level > 0 ? mip_texel(v, pitch, x, y + row) : image_texel(v, x, y));
  }
  return vec3(sum / double(w * h));
}

TEST(TextureMips, APowerOfTwoImageHalvesToOneTexelKeepingItsMean) {
  Image im = random_image(16, 4, 3);
  build_mip_levels(im);
  ASSERT_EQ(im.levels, 5);  // 16x4, 8x2, 4x1, 2x1, 1x1
  const ImageView v = view_of(im);
  int w, h, row;
  mip_level_shape(v, 4, w, h, row);
  EXPECT_EQ(w, 1);
  EXPECT_EQ(h, 1);
  EXPECT_EQ(row, 2 + 1 + 1);
  const vec3 mean = level_mean(v, 0);
  for (int l = 1; l < im.levels; ++l) {
    const vec3 m = level_mean(v, l);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[c], mean[c], 1e-6) << "level " << l << ", channel " << c;
  }
  // A texel of level 1 is the mean of the 2 x 2 block above it.
  const vec3 block = 0.25f * (image_texel(v, 6, 2) + image_texel(v, 7, 2) + image_texel(v, 6, 3) + image_texel(v, 7, 3));
  const vec3 got = mip_texel(v, 8, 3, 1);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], block[c], 1e-6);
}

TEST(TextureMips, AnOddSidedImageCountsEveryTexelAndAConstantStaysConstant) {
  Image im;
  im.width = 5;
  im.height = 3;
  im.texels.assign(5 * 3 * 4, 0.25f);
  build_mip_levels(im);
  ASSERT_EQ(im.levels, 3);  // 5x3, 2x1, 1x1
  const ImageView v = view_of(im);
  for (int l = 1; l < im.levels; ++l) EXPECT_FLOAT_EQ(level_mean(v, l).x, 0.25f) << "level " << l;
  // Odd sides: the last texel of a row takes three texels; with a ramp in x, level
  // 1's texels are the means of columns {0, 1} and {2, 3, 4}.
  Image ramp;
  ramp.width = 5;
  ramp.height = 1;
  for (int x = 0; x < 5; ++x) ramp.texels.insert(ramp.texels.end(), {float(x), 0.0f, 0.0f, 1.0f});
  build_mip_levels(ramp);
  const ImageView r = view_of(ramp);
  EXPECT_FLOAT_EQ(mip_texel(r, 2, 0, 0).x, 0.5f);
  EXPECT_FLOAT_EQ(mip_texel(r, 2, 1, 0).x, 3.0f);
}

TEST(TextureMips, TrilinearLookupIsBilinearWhenMagnifiedAndContinuousInTheLevel) {
  Image im = random_image(32, 32, 5);
  build_mip_levels(im);
  const ImageView v = view_of(im);
  for (float u : {0.1f, 0.37f, 0.93f}) {
    for (float lod : {-2.0f, 0.0f}) {  // magnified: the image itself, bit for bit
      EXPECT_EQ(sample_image_lod(v, lod, u, 0.6f, Wrap::Repeat, Wrap::Repeat),
                sample_image(v, u, 0.6f, Wrap::Repeat, Wrap::Repeat));
    }
    // At and beyond the coarsest level: the image's mean everywhere.
    const vec3 mean = level_mean(v, 0);
    const vec3 top = sample_image_lod(v, 9.0f, u, 0.6f, Wrap::Repeat, Wrap::Repeat);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(top[c], mean[c], 1e-5);
    // Halfway between levels 1 and 2: their mean; either side of level 2: level 2.
    const vec3 l1 = sample_image_level(v, 1, u, 0.6f, Wrap::Repeat, Wrap::Repeat);
    const vec3 l2 = sample_image_level(v, 2, u, 0.6f, Wrap::Repeat, Wrap::Repeat);
    const vec3 half = sample_image_lod(v, 1.5f, u, 0.6f, Wrap::Repeat, Wrap::Repeat);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(half[c], 0.5f * (l1[c] + l2[c]), 1e-6);
    const vec3 below = sample_image_lod(v, 2.0f - 1e-5f, u, 0.6f, Wrap::Repeat, Wrap::Repeat);
    const vec3 above = sample_image_lod(v, 2.0f + 1e-5f, u, 0.6f, Wrap::Repeat, Wrap::Repeat);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(below[c], l2[c], 1e-4);
      EXPECT_NEAR(above[c], l2[c], 1e-4);
    }
  }
}

TEST(TextureMips, TheLevelOfDetailIsTheFootprintInTexels) {
  Image im = random_image(64, 32, 7);
  build_mip_levels(im);
  const ImageView v = view_of(im);
  Texture t = image_texture(0, Wrap::Repeat, Wrap::Repeat);
  SurfacePoint sp{};
  sp.has_uv = true;
  sp.uv_density = 0.5f;  // UV units per unit length
  sp.footprint = 0.125f;  // 1/16 of the UV square: 4 texels of the larger side (64)
  EXPECT_FLOAT_EQ(texture_lod(t, v, sp), 2.0f);
  t.uv_scale = vec2(0.5f, 4.0f);  // the larger scale counts
  EXPECT_FLOAT_EQ(texture_lod(t, v, sp), 4.0f);
  // A sphere's density at its equator: sqrt((1 / 2 pi r)(1 / pi r)).
  SurfacePoint s{};
  s.has_uv = false;
  s.local = vec3(2.0f, 0.0f, 0.0f);
  s.n = vec3(1.0f, 0.0f, 0.0f);
  EXPECT_NEAR(sphere_uv_density(s), 1.0 / (kPi * 2.0 * std::sqrt(2.0)), 1e-6);
  // The camera's footprint: a pixel's angle times the distance, over the slant.
  CameraSpec spec;
  spec.look_from = vec3(0, 0, 4);
  spec.look_at = vec3(0, 0, 0);
  spec.vfov_degrees = 90.0f;
  const Camera cam = Camera::make(spec, 100, 50);
  EXPECT_NEAR(cam.pixel_spread, 2.0f / 50.0f, 1e-6);
  EXPECT_NEAR(cam.footprint(vec3(0, 0, 0), vec3(0, 0, 1), vec3(0, 0, -1)), 4.0f * 0.04f, 1e-6);
  EXPECT_NEAR(cam.footprint(vec3(0, 0, 0), vec3(0, 0, 1), glm::normalize(vec3(1, 0, -1))),
              4.0f * 0.04f * std::sqrt(2.0f), 1e-5);
}

// The square [-1, 1]^2 in z = 0 facing +z, its UVs (0, 0) to (1, 1) over it.
const char* kSquareObj = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                         "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";

// A square of side 2 facing the camera at distance 3 and filling most of its view,
// textured by a 256 x 256 checker of single black and white texels: a pixel of a
// 16 x 16 render covers about 13 x 13 texels. Lambertian under a uniform sky of 1,
// so a path's value is the texel it lands on.
Scene checker_square(const test::TestFolder& folder, const char* filter) {
  const std::string root = folder.root().string();
  std::vector<unsigned char> px;
  for (int y = 0; y < 256; ++y) {
    for (int x = 0; x < 256; ++x) {
      const unsigned char c = ((x + y) & 1) ? 255 : 0;
      px.insert(px.end(), {c, c, c, 255});
    }
  }
  EXPECT_NE(stbi_write_png((root + "/checker.png").c_str(), 256, 256, 4, px.data(), 256 * 4), 0);
  std::ofstream(root + "/square.obj") << kSquareObj;
  std::ofstream(root + "/scene.json") << R"({
    "camera": {"look_from": [0, 0, 3], "look_at": [0, 0, 0], "vfov": 30},
    "sky": {"type": "uniform", "radiance": [1, 1, 1]},
    "textures": [{"name": "checker", "type": "image", "file": "checker.png", "colorspace": "linear",
                  "filter": ")" + std::string(filter) + R"("}],
    "materials": [{"name": "board", "type": "lambertian", "texture": "checker"}],
    "meshes": [{"name": "square", "file": "square.obj", "material": "board"}],
    "instances": [{"mesh": "square"}]})";
  return load_scene(root + "/scene.json");
}

// The pixels' values at 1 sample each, over the render's middle (all on the square).
std::vector<double> middle_pixels(const Scene& scene, Backend b, Kernel k) {
  const int n = 16;
  RenderOptions o = test::options_for(b, k, n, n, 1, 2, 100, 9);
  o.params.nee = 0;
  const RenderResult r = render(scene, o);
  std::vector<double> out;
  for (int y = 4; y < 12; ++y) {
    for (int x = 4; x < 12; ++x) out.push_back(r.rgb[3 * (static_cast<size_t>(y) * n + x)]);
  }
  return out;
}

double spread(const std::vector<double>& v) {
  double m = 0, s = 0;
  for (double x : v) m += x;
  m /= v.size();
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / v.size());
}

TEST(TextureMipRender, AMinifiedCheckerDoesNotAliasWhereTheBilinearLookupDoes) {
  test::TestFolder folder;
  // Trilinear: every pixel reads levels 3 and 4, where the checker has averaged to
  // grey, so one sample a pixel gives 0.5 everywhere.
  const Scene trilinear = checker_square(folder, "trilinear");
  // Mip-mapped lookups are compiled into the kernels with the features beyond the
  // study's; a scene of bilinear lookups keeps the study's kernels.
  EXPECT_TRUE(trilinear.kernel_kinds() & kMicrofacet);
  EXPECT_FALSE(checker_square(folder, "bilinear").kernel_kinds() & kMicrofacet);
  const std::vector<double> mipped = middle_pixels(trilinear, Backend::Cpu, Kernel::Megakernel);
  for (double v : mipped) EXPECT_NEAR(v, 0.5, 1e-3);
  // Bilinear: each sample lands on black, white or a blend of them, so the same
  // render is noise of spread about 0.3 (aliasing), which the test above would fail.
  const std::vector<double> plain = middle_pixels(checker_square(folder, "bilinear"), Backend::Cpu,
                                                  Kernel::Megakernel);
  EXPECT_GT(spread(plain), 0.1);
  // The CPU wavefront kernels look textures up as its megakernel does.
  EXPECT_EQ(middle_pixels(checker_square(folder, "trilinear"), Backend::Cpu, Kernel::WavefrontSorted), mipped);
}

// A texture that is not flat at any level (a smooth random image), minified across
// level boundaries by a slanted square: the CUDA kernels' lookups, through texture
// objects, agree with the CPU's pixel by pixel to 1e-4 relative (the arithmetic is
// the same code; what differs is rounding and fused multiply-adds).
TEST(TextureMipRender, CudaLookupsAgreeWithTheCpuToRounding) {
  WT_REQUIRE_CUDA();
  test::TestFolder folder;
  const std::string root = folder.root().string();
  std::vector<unsigned char> px;
  std::mt19937 rng(11);
  for (int i = 0; i < 512 * 512; ++i) {
    const unsigned char c = static_cast<unsigned char>(rng() & 255);
    px.insert(px.end(), {c, static_cast<unsigned char>(255 - c), 128, 255});
  }
  ASSERT_NE(stbi_write_png((root + "/noise.png").c_str(), 512, 512, 4, px.data(), 512 * 4), 0);
  std::ofstream(root + "/square.obj") << kSquareObj;
  std::ofstream(root + "/scene.json") << R"({
    "camera": {"look_from": [0, -2.2, 2], "look_at": [0, 0, 0], "vfov": 45},
    "sky": {"type": "uniform", "radiance": [1, 1, 1]},
    "textures": [{"name": "noise", "type": "image", "file": "noise.png", "colorspace": "srgb",
                  "uv_scale": [3, 2], "wrap": "mirror"}],
    "materials": [{"name": "board", "type": "lambertian", "texture": "noise"}],
    "meshes": [{"name": "square", "file": "square.obj", "material": "board"}],
    "instances": [{"mesh": "square"}]})";
  const Scene scene = load_scene(root + "/scene.json");
  auto pixels = [&](Backend b, Kernel k) {
    RenderOptions o = test::options_for(b, k, 48, 32, 2, 2, 100, 5);
    o.params.nee = 0;
    RenderResult r = render(scene, o);
    if (r.radiance == Radiance::SumOfSamples) {
      for (float& v : r.rgb) v /= float(r.samples);
    }
    return r.rgb;
  };
  const std::vector<float> cpu = pixels(Backend::Cpu, Kernel::Megakernel);
  for (Kernel k : {Kernel::Megakernel, Kernel::MegakernelConstant, Kernel::Wavefront, Kernel::WavefrontSorted,
                   Kernel::WavefrontUnsorted}) {
    const std::vector<float> gpu = pixels(Backend::Cuda, k);
    ASSERT_EQ(gpu.size(), cpu.size());
    size_t off = 0;
    double worst = 0;
    for (size_t i = 0; i < cpu.size(); ++i) {
      const double d = std::fabs(double(gpu[i]) - cpu[i]) / std::max(1e-3, double(std::fabs(cpu[i])));
      worst = std::max(worst, d);
      off += d > 1e-4;
    }
    // A path whose camera ray grazes the square's diagonal may hit the other
    // triangle on one backend: allow a handful of such pixels.
    EXPECT_LE(off, 3u) << kernel_name(k) << ": worst relative difference " << worst;
  }
}

}  // namespace
}  // namespace wt

// The microfacet kinds (conductor, glass, plastic) in whole renders and in the
// scene reader:
//   - the scene format's fields, defaults and errors;
//   - glass spheres of any roughness, and a thin sheet, vanish under a uniform sky;
//   - light sampling on and off converge to the same image on a scene of every
//     kind, lit by a lamp and the sky;
//   - the CPU's wavefront kernels equal its megakernel to rounding, and every CUDA
//     kernel agrees with the CPU (the GPU suite).
#include <gtest/gtest.h>

#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <tuple>
#include <vector>

#include "render_support.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

using test::mean;
using test::options_for;

constexpr const char* kSource = "materials-test.json";

std::string scene_with(const std::string& materials, const std::string& rest) {
  return R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]}, "materials": [)" + materials + "], " + rest +
         "}";
}

std::string one_sphere(const std::string& material) {
  return scene_with(material, R"("spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}])");
}

std::string error_of(const std::string& text) {
  try {
    parse_scene(text, kSource);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(MaterialScene, TheMicrofacetKindsReadTheirFields) {
  const Scene s = parse_scene(
      scene_with(R"({"name": "gold", "type": "conductor", "metal": "gold", "roughness": 0.5, "anisotropy": 0.5},
                    {"name": "f0", "type": "conductor", "f0": [0.9, 0.5, 0.2]},
                    {"name": "ek", "type": "conductor", "eta": [0.2, 0.5, 1.3], "k": [3.4, 2.2, 1.9], "energy_compensation": false},
                    {"name": "glass", "type": "glass", "roughness": 0.2, "tint": [0.9, 0.8, 0.7]},
                    {"name": "thin", "type": "glass", "thin": true, "ior": 1.33},
                    {"name": "plastic", "type": "plastic", "albedo": [0.2, 0.3, 0.4], "roughness": 0.3, "masking": "separable"})",
                 R"("spheres": [{"center": [0, 0, 0], "radius": 1, "material": "gold"}])"),
      kSource);
  ASSERT_EQ(s.materials.size(), 6u);
  ASSERT_EQ(s.material_params.size(), 6u);
  const MaterialParams& gold = s.material_params[s.materials[0].params];
  EXPECT_EQ(s.materials[0].kind, MaterialKind::Conductor);
  // alpha = roughness^2 = 0.25, stretched by 1 / sqrt(1 - 0.45) along the tangent.
  EXPECT_NEAR(gold.ax, 0.25f / std::sqrt(0.55f), 1e-6f);
  EXPECT_NEAR(gold.ay, 0.25f * std::sqrt(0.55f), 1e-6f);
  EXPECT_NEAR(gold.eta.x, 0.188f, 1e-6f);
  EXPECT_GE(gold.table, 0) << "compensated by default";
  EXPECT_TRUE(s.materials[0].flags & kMaterialCompensated);
  EXPECT_TRUE(s.materials[1].flags & kMaterialSchlick);
  EXPECT_NEAR(s.material_params[s.materials[1].params].eta.y, 0.5f, 1e-6f);
  EXPECT_FALSE(s.materials[2].flags & kMaterialCompensated);
  EXPECT_EQ(s.material_params[s.materials[2].params].table, -1);
  EXPECT_EQ(s.materials[3].kind, MaterialKind::Glass);
  EXPECT_NEAR(s.materials[3].ior, 1.5f, 0.0f) << "glass defaults to 1.5";
  EXPECT_NEAR(s.materials[3].albedo.z, 0.7f, 1e-6f) << "the tint";
  EXPECT_TRUE(s.materials[4].flags & kMaterialThin);
  EXPECT_EQ(s.materials[5].kind, MaterialKind::Plastic);
  EXPECT_TRUE(s.materials[5].flags & kMaterialSeparable);
  EXPECT_FALSE(s.materials[0].flags & kMaterialSeparable) << "height-correlated by default";
  const MaterialParams& plastic = s.material_params[s.materials[5].params];
  EXPECT_GT(plastic.internal, 0.4f) << "a coat of 1.5 reflects about 60% of diffuse light back from inside";
  EXPECT_LT(plastic.internal, 0.7f);
  // Keys in range; the microfacet kinds' among the mask the wavefront sorts for.
  for (const Material& m : s.materials) {
    EXPECT_LT(m.sort_key, kSortKeyMiss);
    EXPECT_TRUE(kMicrofacetKeyMask & (1u << m.sort_key)) << m.sort_key;
  }
  EXPECT_TRUE(s.kernel_kinds() & kMicrofacet) << "the kernels with the microfacet BSDFs";
  EXPECT_FALSE(parse_scene(one_sphere(R"({"name": "m", "type": "coated", "ior": 1.5})"), kSource).kernel_kinds() &
               kMicrofacet);
}

// The texture slots beyond the albedo: an emitter's emission texture, a plastic's
// metallic (constant or textured) and the metal's tables.
TEST(MaterialScene, EmissionAndMetallicSlotsReadTheirTextures) {
  const Scene s = parse_scene(
      R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
          "textures": [{"name": "c", "type": "checker", "size": 1, "even": [1, 1, 1], "odd": [0, 0, 0]}],
          "materials": [{"name": "lamp", "type": "emissive", "emission": [2, 2, 2], "emission_texture": "c"},
                        {"name": "half", "type": "plastic", "roughness": 0.4, "metallic": 0.5},
                        {"name": "mapped", "type": "plastic", "roughness": 0.4, "metallic_texture": "c"},
                        {"name": "single", "type": "plastic", "roughness": 0.4, "metallic": 1, "energy_compensation": false},
                        {"name": "none", "type": "plastic", "roughness": 0.4}],
          "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "lamp"}]})",
      kSource);
  EXPECT_EQ(s.materials[0].texture, 0) << "the emission's texture";
  const MaterialParams& half = s.material_params[s.materials[1].params];
  EXPECT_FLOAT_EQ(half.metallic, 0.5f);
  EXPECT_EQ(half.metallic_texture, -1);
  EXPECT_GE(half.metal_table, 0) << "the metal is compensated by default";
  const MaterialParams& mapped = s.material_params[s.materials[2].params];
  EXPECT_FLOAT_EQ(mapped.metallic, 1.0f) << "the texture alone sets it";
  EXPECT_EQ(mapped.metallic_texture, 0);
  EXPECT_EQ(s.material_params[s.materials[3].params].metal_table, -1);
  EXPECT_EQ(s.material_params[s.materials[4].params].metallic, 0.0f);
  EXPECT_NE(error_of(one_sphere(R"({"name": "m", "type": "plastic", "metallic": 1.5})")).find("/materials/0/metallic"),
            std::string::npos);
  EXPECT_NE(error_of(one_sphere(R"({"name": "m", "type": "emissive", "emission": [1, 1, 1], "emission_texture": "x"})"))
                .find("/materials/0/emission_texture: unknown texture 'x'"),
            std::string::npos);
  EXPECT_NE(error_of(one_sphere(R"({"name": "m", "type": "conductor", "metal": "gold", "metallic": 1})")).find("metallic"),
            std::string::npos)
      << "metallic belongs to plastic";
}

TEST(MaterialScene, BadFieldsNameTheFieldAndSayWhy) {
  struct Case {
    const char* material;
    const char* where;
    const char* why;
  };
  for (const Case& c : std::vector<Case>{
           {R"({"name": "m", "type": "conductor", "metal": "unobtainium"})", "/materials/0/metal", "unknown metal 'unobtainium' (known: gold, silver"},
           {R"({"name": "m", "type": "conductor", "metal": "gold", "f0": [1, 1, 1]})", "/materials/0", "exactly one of"},
           {R"({"name": "m", "type": "conductor"})", "/materials/0", "exactly one of"},
           {R"({"name": "m", "type": "conductor", "eta": [1, 1, 1]})", "/materials/0/k", "required"},
           {R"({"name": "m", "type": "conductor", "eta": [1, 0, 1], "k": [1, 1, 1]})", "/materials/0/eta", "> 0"},
           {R"({"name": "m", "type": "conductor", "eta": [1, 1, 1], "k": [1, -1, 1]})", "/materials/0/k", ">= 0"},
           {R"({"name": "m", "type": "conductor", "metal": "gold", "roughness": 1.5})", "/materials/0/roughness", ""},
           {R"({"name": "m", "type": "glass", "thin": true, "roughness": 0.1})", "/materials/0/thin", "smooth"},
           {R"({"name": "m", "type": "glass", "ior": 0})", "/materials/0/ior", ""},
           {R"({"name": "m", "type": "plastic", "fuzz": 0.1})", "/materials/0", "fuzz"},
           {R"({"name": "m", "type": "plastic", "masking": "smith"})", "/materials/0/masking", "separable"},
       }) {
    const std::string e = error_of(one_sphere(c.material));
    EXPECT_NE(e.find(std::string(kSource) + ": " + c.where), std::string::npos) << c.material << ": " << e;
    EXPECT_NE(e.find(c.why), std::string::npos) << c.material << ": " << e;
  }
}

// Image textures' transform and wrap, as read; their errors.
TEST(MaterialScene, ImageTexturesReadTheirTransformAndWrap) {
  const std::string source = test::repo_path("scenes/wrap-test.json");
  auto scene = [](const std::string& texture) {
    return R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
      "textures": [)" + texture + R"(],
      "materials": [{"name": "m", "type": "lambertian", "texture": "t"}],
      "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})";
  };
  const Scene s = parse_scene(scene(R"({"name": "t", "type": "image", "file": "textures/planet.png",
      "uv_scale": [2, 3], "uv_offset": [0.5, 0.25], "uv_rotation": 1.5707963, "wrap": ["mirror", "repeat"]})"),
                              source);
  const Texture& t = s.textures.at(0);
  EXPECT_EQ(t.uv_scale, vec2(2.0f, 3.0f));
  EXPECT_EQ(t.uv_offset, vec2(0.5f, 0.25f));
  EXPECT_NEAR(t.uv_cos, 0.0f, 1e-6f);
  EXPECT_NEAR(t.uv_sin, 1.0f, 1e-6f);
  EXPECT_EQ(t.wrap_u, Wrap::Mirror);
  EXPECT_EQ(t.wrap_v, Wrap::Repeat);
  const Scene d = parse_scene(scene(R"({"name": "t", "type": "image", "file": "textures/planet.png"})"), source);
  EXPECT_EQ(d.textures.at(0).wrap_u, Wrap::Repeat) << "the default: u repeats";
  EXPECT_EQ(d.textures.at(0).wrap_v, Wrap::Clamp) << "and v clamps";
  // A normal map must be read as linear values, and textures are named.
  const std::string planet = R"({"name": "t", "type": "image", "file": "textures/planet.png"})";
  auto material_error = [&](const std::string& material) {
    try {
      parse_scene(R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]}, "textures": [)" + planet +
                      R"(], "materials": [)" + material + R"(], "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})",
                  source);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(material_error(R"({"name": "m", "type": "lambertian", "normal_texture": "t"})").find("/materials/0/normal_texture: a normal map holds vectors"),
            std::string::npos);
  EXPECT_NE(material_error(R"({"name": "m", "type": "conductor", "f0": [1, 1, 1], "roughness_texture": "rough"})").find("/materials/0/roughness_texture: unknown texture 'rough'"),
            std::string::npos);
  EXPECT_NE(material_error(R"({"name": "m", "type": "glass", "thin": true, "roughness_texture": "t"})").find("/materials/0/thin"),
            std::string::npos);
  for (const char* bad : {R"("wrap": "tile")", R"("wrap": ["clamp"])", R"("uv_scale": [1])", R"("uv_rotation": "90")"}) {
    try {
      parse_scene(scene(std::string(R"({"name": "t", "type": "image", "file": "textures/planet.png", )") + bad + "}"),
                  source);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("/textures/0/"), std::string::npos) << e.what();
    }
  }
}

// A camera that sees only the sphere, under a uniform sky of radiance 1: a
// dielectric that loses nothing returns the sky in every pixel. Depth 64 and no
// roulette (paths inside the glass bounce many times). Per seed 16 x 16 pixels at
// 256 spp; the mean of 16 seeds within 4 standard errors of 1 (plus 1e-6 for the
// float sums of the smooth spheres, whose every path returns 1), and 4 standard
// errors at most 0.5%.
TEST(MaterialRender, GlassSpheresOfAnyRoughnessVanishUnderAUniformSky) {
  for (const char* glass : {R"({"name": "m", "type": "glass"})", R"({"name": "m", "type": "glass", "roughness": 0.3})",
                            R"({"name": "m", "type": "glass", "roughness": 1})", R"({"name": "m", "type": "glass", "thin": true})"}) {
    const Scene scene = parse_scene(R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0], "vfov": 16},
        "sky": {"type": "uniform", "radiance": [1, 1, 1]}, "materials": [)" + std::string(glass) + R"(],
        "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})",
                                    kSource);
    test::expect_vanishes_under_a_uniform_sky(scene, 16, 16, 256, 64, glass);
  }
}

// Spheres of every microfacet kind (rough gold, anisotropic iron, a smooth silver
// mirror, rough and smooth glass, a thin sheet, rough and smooth plastic, a white
// conductor by f0) on a rough plastic ground, under a spherical lamp and a dim sky.
const Scene& materials_scene() {
  static const Scene scene = parse_scene(R"({
    "camera": {"look_from": [0, 2.2, 6], "look_at": [0, 0.4, 0], "vfov": 40},
    "sky": {"type": "uniform", "radiance": [0.3, 0.3, 0.35]},
    "textures": [{"name": "check", "type": "checker", "size": 0.5, "even": [0.8, 0.8, 0.8], "odd": [0.2, 0.3, 0.5]}],
    "materials": [
      {"name": "ground", "type": "plastic", "albedo": [0.6, 0.6, 0.6], "roughness": 0.4, "texture": "check"},
      {"name": "gold", "type": "conductor", "metal": "gold", "roughness": 0.3},
      {"name": "iron", "type": "conductor", "metal": "iron", "roughness": 0.5, "anisotropy": 0.7},
      {"name": "silver", "type": "conductor", "metal": "silver"},
      {"name": "white", "type": "conductor", "f0": [0.95, 0.95, 0.95], "roughness": 0.8},
      {"name": "rough-glass", "type": "glass", "roughness": 0.3, "tint": [0.9, 0.95, 1.0]},
      {"name": "glass", "type": "glass", "ior": 1.5},
      {"name": "thin", "type": "glass", "thin": true},
      {"name": "plastic", "type": "plastic", "albedo": [0.8, 0.2, 0.1], "roughness": 0.2},
      {"name": "gloss", "type": "plastic", "albedo": [0.1, 0.3, 0.8]},
      {"name": "lamp", "type": "emissive", "emission": [30, 28, 25]}],
    "spheres": [
      {"center": [0, -1000, 0], "radius": 1000, "material": "ground"},
      {"center": [-2.4, 0.5, 0], "radius": 0.5, "material": "gold"},
      {"center": [-1.2, 0.5, 0], "radius": 0.5, "material": "iron"},
      {"center": [0, 0.5, 0], "radius": 0.5, "material": "silver"},
      {"center": [1.2, 0.5, 0], "radius": 0.5, "material": "white"},
      {"center": [2.4, 0.5, 0], "radius": 0.5, "material": "rough-glass"},
      {"center": [-1.8, 0.5, 1.3], "radius": 0.5, "material": "glass"},
      {"center": [-0.6, 0.5, 1.3], "radius": 0.5, "material": "thin"},
      {"center": [0.6, 0.5, 1.3], "radius": 0.5, "material": "plastic"},
      {"center": [1.8, 0.5, 1.3], "radius": 0.5, "material": "gloss"},
      {"center": [1.5, 4, 2], "radius": 0.4, "material": "lamp"}]})",
                                         kSource);
  return scene;
}

// With and without light sampling: the same image mean (16 seeds each, within 4
// standard errors of the difference, at most 3% of the value: 2.4% measured). (The
// noise is not compared: the glass spheres' caustics of the small lamp, which
// light sampling cannot reach, dominate it.)
TEST(MaterialRender, LightSamplingOnAndOffConvergeToTheSameImage) {
  auto renders = [](int nee) {
    std::vector<RenderResult> out;
    for (uint32_t seed = 1; seed <= 16; ++seed) {
      RenderOptions o = options_for(Backend::Cpu, Kernel::Megakernel, 48, 27, 48, 8, 3, seed);
      o.params.nee = nee;
      out.push_back(render(materials_scene(), o));
    }
    return out;
  };
  const std::vector<RenderResult> with = renders(1), without = renders(0);
  std::vector<double> with_means, without_means;
  for (const RenderResult& r : with) with_means.push_back(mean(r.rgb));
  for (const RenderResult& r : without) without_means.push_back(mean(r.rgb));
  test::expect_same_expectation(with_means, without_means, 0.03);
  EXPECT_GT(with[0].shadow_rays, with[0].paths / 4) << "the rough kinds should sample the lights";
}

// The CPU's wavefront kernels trace the same paths and light samples as its
// megakernel; only the order of the film's additions differs.
TEST(MaterialRender, CpuWavefrontKernelsMatchTheMegakernelToRounding) {
  test::expect_cpu_wavefront_kernels_match_the_megakernel(materials_scene());
}

// A flat quad (u along +x, the OBJ's v along -z: v = 0 at z = +1 is the image's
// bottom row) under one far lamp, black sky, direct light only, seen from above;
// the mean over the middle of the image (symmetric about the centre, so that a
// tilt's change of distance to the lamp cancels to first order) of 16 seeds. A
// quad whose map tilts its shading normal lights as the quad tilted by the same
// rotation: each within 4 standard errors (at most 1% of the value), and the
// untilted quad otherwise (the test sees the map).
class TiltedQuad {
 public:
  TiltedQuad() {
    std::ofstream obj(folder.root() / "quad.obj");
    obj << "v -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\n"
           "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 1 0\n"
           "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";
  }
  // `textures`: the scene's texture list; `mapped`: the material's map keys.
  Scene scene(const std::string& textures, const std::string& mapped, const std::string& placement) const {
    const std::string doc = R"({"camera": {"look_from": [0, 6, 0.001], "look_at": [0, 0, 0], "up": [0, 0, -1], "vfov": 24},
      "sky": {"type": "uniform", "radiance": [0, 0, 0]},
      "textures": [)" + textures + R"(],
      "materials": [{"name": "m", "type": "lambertian", "albedo": [0.8, 0.8, 0.8])" + mapped + R"(},
                    {"name": "lamp", "type": "emissive", "emission": [4000, 4000, 4000]}],
      "meshes": [{"name": "quad", "file": "quad.obj"}],
      "instances": [{"mesh": "quad", "material": "m", "matrix": )" + placement + R"(}],
      "spheres": [{"center": [30, 50, 20], "radius": 1, "material": "lamp"}]})";
    return parse_scene(doc, (folder.root() / "scene.json").string());
  }
  void expect_lights_like_tilted(const std::string& textures, const std::string& mapped,
                                 const std::string& matrix) const {
    const Scene flat = scene(textures, mapped, kIdentity), tilted = scene(textures, "", matrix),
                plain = scene(textures, "", kIdentity);
    ASSERT_TRUE(flat.kernel_kinds() & kMicrofacet) << "a map needs the kernels that read it";
    auto middle = [](const Scene& sc, uint32_t seed) {
      const RenderResult r = render(sc, options_for(Backend::Cpu, Kernel::Megakernel, 32, 32, 16, 2, 8, seed));
      double sum = 0;
      int n = 0;
      for (int y = 12; y < 20; ++y)
        for (int x = 12; x < 20; ++x, ++n) sum += r.rgb[3 * (y * 32 + x)];
      return sum / n;
    };
    std::vector<double> a, b, p;
    for (uint32_t seed = 1; seed <= 16; ++seed) {
      a.push_back(middle(flat, seed));
      b.push_back(middle(tilted, seed));
      p.push_back(middle(plain, seed));
    }
    const double lit = test::mean_and_standard_error(b).mean;
    EXPECT_GT(lit, 1e-3) << "the lamp should light the quad";
    test::expect_same_expectation(a, b, 0.01);
    EXPECT_GT(std::fabs(test::mean_and_standard_error(p).mean - lit), 0.1 * lit);
  }
  static constexpr const char* kIdentity = "[1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1]";
  // Rotations by 30 degrees that tilt +y to (s, c, 0), (-s, c, 0) and (0, c, -s).
  static std::string tilt_to_plus_x() { return rotation("[C, S, 0, 0,  -S, C, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1]"); }
  static std::string tilt_to_minus_x() { return rotation("[C, -S, 0, 0,  S, C, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1]"); }
  static std::string tilt_to_minus_z() { return rotation("[1, 0, 0, 0,  0, C, S, 0,  0, -S, C, 0,  0, 0, 0, 1]"); }
  test::TestFolder folder;

 private:
  static std::string rotation(std::string m) {
    const std::string c = std::to_string(std::sqrt(3.0f) / 2.0f), s = std::to_string(0.5f);
    for (size_t at; (at = m.find('C')) != std::string::npos;) m.replace(at, 1, c);
    for (size_t at; (at = m.find('S')) != std::string::npos;) m.replace(at, 1, s);
    return m;
  }
};

// A constant normal map tilting the normal by 30 degrees: once about the v axis
// (the map's red channel: the tangent, dp/du, is +x) and once about the u axis
// (green: up the image, which the OBJ's v runs along -z), so that both axes and the
// bitangent's handedness are held. The map is a checker of one colour: a constant
// texture with no quantisation.
TEST(MaterialRender, AConstantTiltedNormalMapLightsLikeTheTiltedQuad) {
  const TiltedQuad quad;
  const float s = 0.5f, c = std::sqrt(3.0f) / 2.0f;  // sin, cos 30 degrees
  for (const auto& [what, map, matrix] :
       {std::tuple<const char*, vec3, std::string>{"red: along u", vec3(s, 0, c), TiltedQuad::tilt_to_plus_x()},
        std::tuple<const char*, vec3, std::string>{"green: up the image", vec3(0, s, c), TiltedQuad::tilt_to_minus_z()}}) {
    SCOPED_TRACE(what);
    const vec3 colour = 0.5f * (map + vec3(1.0f));
    const std::string rgb = "[" + std::to_string(colour.x) + ", " + std::to_string(colour.y) + ", " +
                            std::to_string(colour.z) + "]";
    quad.expect_lights_like_tilted(R"({"name": "n", "type": "checker", "size": 1, "even": )" + rgb + R"(, "odd": )" +
                                       rgb + "}",
                                   R"(, "normal_texture": "n")", matrix);
  }
}

// A bump map whose heights rise linearly tilts the normal away from the rise: a
// 16-texel grey ramp of 8-bit steps of 16 (exact: its derivative is 16 * 16 / 255
// per unit of u everywhere, the clamped edges' one-sided differences too) over the
// quad's 2 units (UV density 1/2), bump_scale b: the slope b (256 / 255) / 2, which
// b = 2 tan 30 (255 / 256) makes tan 30 degrees. Along u the normal leans to -x;
// down the image's rows, where v and the heights grow towards +z, to -z (so that
// the bitangent's handedness is held too).
TEST(MaterialRender, ARampBumpMapLightsLikeTheTiltedQuad) {
  const TiltedQuad quad;
  std::vector<unsigned char> ramp(16 * 4);
  for (int i = 0; i < 16; ++i) {
    for (int c = 0; c < 3; ++c) ramp[4 * i + c] = static_cast<unsigned char>(16 * i);
    ramp[4 * i + 3] = 255;
  }
  const std::string root = quad.folder.root().string();
  ASSERT_NE(stbi_write_png((root + "/across.png").c_str(), 16, 1, 4, ramp.data(), 16 * 4), 0);
  ASSERT_NE(stbi_write_png((root + "/down.png").c_str(), 1, 16, 4, ramp.data(), 4), 0);
  const std::string scale = std::to_string(2.0 * std::tan(kPi / 6.0) * 255.0 / 256.0);
  for (const auto& [what, file, matrix] :
       {std::tuple<const char*, const char*, std::string>{"along u", "across.png", TiltedQuad::tilt_to_minus_x()},
        std::tuple<const char*, const char*, std::string>{"down the rows", "down.png", TiltedQuad::tilt_to_minus_z()}}) {
    SCOPED_TRACE(what);
    quad.expect_lights_like_tilted(
        std::string(R"({"name": "h", "type": "image", "file": ")") + file +
            R"(", "colorspace": "linear", "wrap": "clamp"})",
        R"(, "bump_texture": "h", "bump_scale": )" + scale, matrix);
  }
}

// Bump maps on a quad and on spheres (a sphere's UV rates), of a lambertian, a
// plastic and a principled, under a lamp and a sky: a 32 x 32 image of random
// heights, repeating.
Scene bump_scene(const test::TestFolder& folder) {
  std::vector<unsigned char> heights(32 * 32 * 4, 255);
  uint32_t state = 12345u;
  for (size_t i = 0; i < 32 * 32; ++i) {
    state = state * 1664525u + 1013904223u;
    for (int c = 0; c < 3; ++c) heights[4 * i + c] = static_cast<unsigned char>(state >> 24);
  }
  const std::string root = folder.root().string();
  EXPECT_NE(stbi_write_png((root + "/heights.png").c_str(), 32, 32, 4, heights.data(), 32 * 4), 0);
  std::ofstream(root + "/quad.obj") << "v -2 0 2\nv 2 0 2\nv 2 0 -2\nv -2 0 -2\n"
                                       "vt 0 0\nvt 2 0\nvt 2 2\nvt 0 2\nvn 0 1 0\n"
                                       "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";
  return parse_scene(R"({"camera": {"look_from": [0, 2.5, 4], "look_at": [0, 0.5, 0], "vfov": 45},
    "sky": {"type": "uniform", "radiance": [0.3, 0.35, 0.4]},
    "textures": [{"name": "h", "type": "image", "file": "heights.png", "colorspace": "linear"}],
    "materials": [{"name": "floor", "type": "lambertian", "albedo": [0.7, 0.7, 0.7], "bump_texture": "h", "bump_scale": 0.01},
                  {"name": "plastic", "type": "plastic", "albedo": [0.2, 0.4, 0.7], "roughness": 0.2, "bump_texture": "h", "bump_scale": 0.02},
                  {"name": "gold", "type": "principled", "albedo": [1.0, 0.8, 0.4], "metallic": 1, "roughness": 0.3, "bump_texture": "h", "bump_scale": -0.03},
                  {"name": "lamp", "type": "emissive", "emission": [30, 30, 30]}],
    "meshes": [{"name": "quad", "file": "quad.obj"}],
    "instances": [{"mesh": "quad", "material": "floor"}],
    "spheres": [{"center": [-0.8, 0.7, 0], "radius": 0.7, "material": "plastic"},
                {"center": [0.8, 0.7, 0], "radius": 0.7, "material": "gold"},
                {"center": [2, 4, 2], "radius": 0.5, "material": "lamp"}]})",
                     (folder.root() / "scene.json").string());
}

// The CPU's wavefront kernels shade bump maps as its megakernel does.
TEST(MaterialRender, CpuWavefrontKernelsMatchTheMegakernelOnBumpMaps) {
  const test::TestFolder folder;
  test::expect_cpu_wavefront_kernels_match_the_megakernel(bump_scene(folder));
}

// Light sampling on and off converge to the same image with bump maps: the bumped
// normal is the one both strategies' BSDF sees (16 seeds each, within 4 standard
// errors, at most 3% of the value).
TEST(MaterialRender, LightSamplingOnAndOffConvergeOnBumpMaps) {
  const test::TestFolder folder;
  const Scene scene = bump_scene(folder);
  test::expect_same_expectation(test::seed_means(scene, 32, 18, 32, 1), test::seed_means(scene, 32, 18, 32, 0), 0.03);
}

TEST(MaterialRender, EveryCudaKernelAgreesWithTheCpuOnBumpMaps) {
  WT_REQUIRE_CUDA();
  const test::TestFolder folder;
  const Scene scene = bump_scene(folder);
  test::expect_cuda_agrees_with_cpu(
      [&](Backend b, Kernel k, uint32_t seed) { return render(scene, options_for(b, k, 64, 36, 8, 8, 3, seed)); }, 3);
}

// --profile's shade by material kind: the same image (to the film's rounding: the
// launches add in another order), the kinds' times making up shade's, one for
// each kind the scene's hits hold.
TEST(MaterialRender, ShadingByKindRendersTheSameImageAndTimesEachKind) {
  RenderOptions o = options_for(Backend::Cpu, Kernel::WavefrontSorted, 32, 18, 4, 8, 3, 1);
  const RenderResult whole = render(materials_scene(), o);
  o.shade_by_kind = true;
  const RenderResult parts = render(materials_scene(), o);
  ASSERT_EQ(parts.rgb.size(), whole.rgb.size());
  for (size_t i = 0; i < whole.rgb.size(); ++i) {
    ASSERT_NEAR(parts.rgb[i], whole.rgb[i], 1e-5f * (1.0f + std::fabs(whole.rgb[i]))) << i;
  }
  double shade = 0, sum = 0;
  std::vector<std::string> timed;
  for (const StageTime& s : parts.stages) {
    if (s.name == "shade") shade = s.ms;
    if (s.part) sum += s.ms;
    if (s.part && s.ms > 0) timed.push_back(s.name);
  }
  // (Shade's own launches over a last bounce of no hits add a few microseconds.)
  EXPECT_LE(sum, shade);
  EXPECT_GT(sum, 0.98 * shade);
  // The scene's kinds (its ground is plastic, its lamp emissive), and no other.
  EXPECT_EQ(timed, (std::vector<std::string>{"  emissive", "  conductor", "  glass", "  plastic"}));
  for (const StageTime& s : whole.stages) EXPECT_FALSE(s.part) << "only with shade_by_kind";
}

TEST(MaterialRender, EveryCudaKernelAgreesWithTheCpu) {
  WT_REQUIRE_CUDA();
  test::expect_cuda_agrees_with_cpu(
      [](Backend b, Kernel k, uint32_t seed) {
        return render(materials_scene(), options_for(b, k, 64, 36, 8, 8, 3, seed));
      },
      3);
}

}  // namespace
}  // namespace wt

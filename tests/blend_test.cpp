// Blends of two materials (material.hpp's Blend, blend.hpp): a hit on a blend
// shades with one of its two materials, the second with the weight's probability.
//   - the pick: its frequency is the weight (times a texture's luminance), nested
//     blends pick independently, and weights 0 and 1 are exact;
//   - the mixture the picks sample, as every BSDF is tested (bsdf_support.hpp): its
//     samples fit (1 - w) pdf_a + w pdf_b by chi-square and a wrong weight fails,
//     the white furnace, reciprocity;
//   - whole renders: a blend of weight 0 or 1 renders exactly its material, a blend
//     of two Lambertians as their mixed albedo, light sampling on and off converge
//     alike, the CPU's kernels match its megakernel to rounding and the CUDA ones
//     agree with the CPU (the GPU suite);
//   - the scene format's errors.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "bsdf_support.hpp"
#include "render_support.hpp"
#include "test_support.hpp"
#include "wavetrace/path.hpp"

namespace wt {
namespace {

using test::mean;
using test::options_for;

constexpr const char* kSource = "blend-test.json";

// One unit sphere at the origin of material "m", after the materials `materials`.
Scene sphere_scene(const std::string& materials, const std::string& textures = "") {
  return parse_scene(R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]}, "textures": [)" + textures +
                         R"(], "materials": [)" + materials +
                         R"(], "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})",
                     kSource);
}

std::string error_of(const std::string& materials) {
  try {
    sphere_scene(materials);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The material each of n rays shades with, the rays going straight down onto the
// sphere's top from points spread over a square of side 1.2 (so that a texture's
// cells are met), each ray its own.
struct Pick {
  uint32_t material;
  vec3 point;
};
std::vector<Pick> picks(const Scene& scene, int n, uint32_t seed) {
  std::vector<ImageView> views;
  const SceneView view = host_view(scene, 8, 8, views);
  std::vector<Pick> out;
  out.reserve(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const Rng rng = Rng::at(seed, static_cast<uint32_t>(i), 0, 0);
    const Ray ray{vec3(1.2f * (rng.uniform(0) - 0.5f), 3.0f, 1.2f * (rng.uniform(1) - 0.5f)), vec3(0.0f, -1.0f, 0.0f)};
    const Hit hit = intersect_scene<kEverything>(view, ray);
    EXPECT_FALSE(hit.missed());
    out.push_back({shading_material_index<kEverything>(view, ray, hit), ray.at(hit.t)});
  }
  return out;
}

uint32_t material_index_named(const Scene& s, const std::string& name) {
  for (size_t i = 0; i < s.material_names.size(); ++i) {
    if (s.material_names[i] == name) return static_cast<uint32_t>(i);
  }
  ADD_FAILURE() << "no material " << name;
  return 0;
}

const std::string kTwoLambertians = R"({"name": "a", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]},
                                       {"name": "b", "type": "lambertian", "albedo": [0.9, 0.9, 0.9]},)";

// The share of n picks that take the second material is within 4.5 binomial
// standard errors of the weight; weights 0 and 1 pick one material every time.
TEST(BlendPick, TakesTheSecondWithTheWeightsProbability) {
  constexpr int n = 40000;
  for (double w : {0.0, 0.25, 0.7, 1.0}) {
    const Scene s =
        sphere_scene(kTwoLambertians + R"({"name": "m", "type": "blend", "materials": ["a", "b"], "weight": )" +
                     std::to_string(w) + "}");
    int second = 0;
    for (const Pick& p : picks(s, n, 1)) {
      ASSERT_TRUE(p.material == 0u || p.material == 1u) << "a blend shades as one of its materials";
      second += p.material == 1u;
    }
    const double share = static_cast<double>(second) / n;
    EXPECT_NEAR(share, w, 4.5 * std::sqrt(w * (1 - w) / n)) << "weight " << w;
  }
}

// A blend within a blend picks with a number of its own: the outer takes the inner
// with 0.4, the inner its second with 0.5, so x, y and z are met 0.6, 0.2 and 0.2
// of the time (one number for both would never meet y). Chi-square on 2 degrees of
// freedom, below 20 (a false alarm of 4.5e-5).
TEST(BlendPick, ABlendWithinABlendPicksIndependently) {
  const Scene s = sphere_scene(R"({"name": "x", "type": "lambertian"}, {"name": "y", "type": "lambertian"},
      {"name": "z", "type": "lambertian"}, {"name": "inner", "type": "blend", "materials": ["y", "z"]},
      {"name": "m", "type": "blend", "materials": ["x", "inner"], "weight": 0.4})");
  constexpr int n = 30000;
  double count[3] = {0, 0, 0};
  for (const Pick& p : picks(s, n, 2)) {
    ASSERT_LT(p.material, 3u) << "a blend shades as one of the materials it holds, however deep";
    count[p.material] += 1;
  }
  const double expected[3] = {0.6 * n, 0.2 * n, 0.2 * n};
  double chi2 = 0;
  for (int k = 0; k < 3; ++k) chi2 += (count[k] - expected[k]) * (count[k] - expected[k]) / expected[k];
  EXPECT_LT(chi2, 20.0) << count[0] << " " << count[1] << " " << count[2];
}

// A weight texture scales the weight by its luminance: on a checker of white and
// grey (luminance 0.5) cells, weight 0.8 picks the second 0.8 of the time on white
// cells and 0.4 on grey ones.
TEST(BlendPick, AWeightTextureScalesTheWeightByItsLuminance) {
  const Scene s = sphere_scene(
      kTwoLambertians +
          R"({"name": "m", "type": "blend", "materials": ["a", "b"], "weight": 0.8, "weight_texture": "cells"})",
      R"({"name": "cells", "type": "checker", "size": 0.25, "even": [1, 1, 1], "odd": [0.5, 0.5, 0.5]})");
  double n[2] = {0, 0}, second[2] = {0, 0};
  for (const Pick& p : picks(s, 40000, 3)) {
    // The checker's parity at the hit (texture.hpp: the object-space x and z).
    const int odd = (static_cast<int>(std::floor(p.point.x / 0.25f)) + static_cast<int>(std::floor(p.point.z / 0.25f))) & 1;
    n[odd] += 1;
    second[odd] += p.material == 1u;
  }
  const double w[2] = {0.8, 0.4};
  for (int k = 0; k < 2; ++k) {
    ASSERT_GT(n[k], 10000) << "both kinds of cell are met";
    EXPECT_NEAR(second[k] / n[k], w[k], 4.5 * std::sqrt(w[k] * (1 - w[k]) / n[k])) << (k ? "grey" : "white") << " cells";
  }
}

// The mixture a blend's picks sample: the chosen material's BSDF at wo, each sample
// of it drawn after its own pick (the real picks of rays on the sphere).
struct Mixture {
  Case a, b;
  float w;
  std::vector<Pick> chosen;

  Mixture(const std::string& a_json, const std::string& b_json, float weight)
      : a(material(a_json)), b(material(b_json)), w(weight) {
    std::string a_named = a_json, b_named = b_json;
    a_named.replace(a_named.find(R"("name": "m")"), 11, R"("name": "a")");
    b_named.replace(b_named.find(R"("name": "m")"), 11, R"("name": "b")");
    const Scene s = sphere_scene(a_named + ", " + b_named + R"(, {"name": "m", "type": "blend", "materials": ["a", "b"], "weight": )" +
                                 std::to_string(weight) + "}");
    chosen = picks(s, kSamples, 4);
  }
  BsdfSample sample(const vec3& wo, int i) const {
    return sample_bsdf(at(chosen[static_cast<size_t>(i)].material == 1u ? b : a, wo),
                       wo, Rng::at(17, static_cast<uint32_t>(i), 0, 0));
  }
  // The density with weights wa for the first and wb for the second.
  std::function<float(const vec3&)> pdf(const vec3& wo, float wa, float wb) const {
    const BsdfAt ba = at(a, wo), bb = at(b, wo);
    return [=](const vec3& wi) { return wa * pdf_bsdf(ba, wo, wi) + wb * pdf_bsdf(bb, wo, wi); };
  }
  Chi2 test(const vec3& wo, float wa, float wb) const {
    return chi2_test([&](int i) { return sample(wo, i); }, pdf(wo, wa, wb), mirror(wo), 0);
  }
};

const char* kGold = R"({"name": "m", "type": "conductor", "metal": "gold", "roughness": 0.3})";
const char* kMatte = R"({"name": "m", "type": "lambertian", "albedo": [0.8, 0.8, 0.8]})";
const char* kPlastic = R"({"name": "m", "type": "plastic", "albedo": [0.5, 0.4, 0.3], "roughness": 0.2})";
const char* kMirror = R"({"name": "m", "type": "conductor", "metal": "silver"})";

TEST(BlendChiSquare, APickSamplesTheMixturesDensity) {
  const Mixture rough(kGold, kMatte, 0.3f), shiny(kPlastic, kMirror, 0.6f);
  for (const Mixture* m : {&rough, &shiny}) {
    for (double deg : kAngles) {
      const Chi2 r = m->test(incident(deg), 1.0f - m->w, m->w);
      EXPECT_LT(r.z, kRejectZ) << m->a.name << " and " << m->b.name << " at " << deg << " deg: chi2 " << r.statistic
                               << " on " << r.dof << " dof";
    }
  }
}

// The wrong densities: the weights swapped, or the first material's alone, fail.
TEST(BlendChiSquare, AWrongWeightFails) {
  const Mixture m(kGold, kMatte, 0.3f);
  for (double deg : {0.0, 60.0}) {
    EXPECT_GT(m.test(incident(deg), m.w, 1.0f - m.w).z, kRejectZ) << "swapped weights at " << deg << " deg";
    EXPECT_GT(m.test(incident(deg), 1.0f, 0.0f).z, kRejectZ) << "the first alone at " << deg << " deg";
  }
}

// What a blend's picks return is the weighted mean of what its materials return:
// a white one returns everything, and a blend of a white and a grey Lambertian
// returns the mixed albedo (each within 4 standard errors plus 0.2%).
TEST(BlendFurnace, ABlendReturnsTheWeightedMeanOfItsMaterials) {
  const std::string white_metal = R"({"name": "m", "type": "conductor", "f0": [1, 1, 1], "roughness": 0.5})";
  const std::string white = R"({"name": "m", "type": "lambertian", "albedo": [1, 1, 1]})";
  const std::string grey = R"({"name": "m", "type": "lambertian", "albedo": [0.2, 0.2, 0.2]})";
  struct Expect {
    const Mixture* m;
    double value;
  };
  const Mixture white_mix(white_metal, white, 0.4f), grey_mix(white, grey, 0.25f);
  for (const Expect& e : {Expect{&white_mix, 1.0}, Expect{&grey_mix, 0.75 * 1.0 + 0.25 * 0.2}}) {
    for (double deg : {0.0, 45.0, 80.0}) {
      const vec3 wo = incident(deg);
      double sum = 0, sum2 = 0;
      for (int i = 0; i < kSamples; ++i) {
        const BsdfSample s = e.m->sample(wo, i);
        const double v = s.lobe == 0u ? 0.0 : (s.weight.x + s.weight.y + s.weight.z) / 3.0;
        sum += v;
        sum2 += v * v;
      }
      const double mean_v = sum / kSamples, error = std::sqrt(std::fmax(sum2 / kSamples - mean_v * mean_v, 0.0) / kSamples);
      EXPECT_NEAR(mean_v, e.value, 4 * error + 0.002 + (e.value == 1.0 ? 0.01 : 0.0))
          << e.m->a.name << " and " << e.m->b.name << " at " << deg << " deg";
    }
  }
}

// The mixture's f is reciprocal where its materials' are: f(wo, wi) = f(wi, wo)
// over pairs of directions drawn over the upper hemisphere.
TEST(BlendContract, TheMixtureIsReciprocal) {
  const Mixture m(kGold, kPlastic, 0.45f);
  int nonzero = 0;
  for (int i = 0; i < 4000; ++i) {
    const Rng rng = Rng::at(9, static_cast<uint32_t>(i), 0, 0);
    vec3 x = unit_sphere_point(rng.uniform(0), rng.uniform(1)), y = unit_sphere_point(rng.uniform(2), rng.uniform(3));
    x.z = std::fabs(x.z);
    y.z = std::fabs(y.z);
    if (x.z < 0.02f || y.z < 0.02f) continue;
    auto f = [&](const vec3& wo, const vec3& wi) {
      return ((1.0f - m.w) * eval_bsdf(at(m.a, wo), wo, wi) + m.w * eval_bsdf(at(m.b, wo), wo, wi)) / wi.z;
    };
    const vec3 fxy = f(x, y), fyx = f(y, x);
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(fxy[k], fyx[k], 2e-3f * std::fmax(fxy[k], fyx[k]) + 1e-6f) << "pair " << i;
    nonzero += fxy.x > 0.0f;
  }
  EXPECT_GT(nonzero, 3000);
}

// ---- whole renders ----

// A floor, three spheres and a lamp under a dim sky: a blend of a metal and a
// plastic, a blend of a textured weight, and a blend within a blend.
const std::string kBlendMaterials = R"(
      {"name": "ground", "type": "plastic", "albedo": [0.6, 0.6, 0.6], "roughness": 0.4},
      {"name": "gold", "type": "conductor", "metal": "gold", "roughness": 0.3},
      {"name": "red", "type": "plastic", "albedo": [0.8, 0.2, 0.1], "roughness": 0.2},
      {"name": "glass", "type": "glass", "roughness": 0.2},
      {"name": "matte", "type": "lambertian", "albedo": [0.3, 0.6, 0.3]},
      {"name": "mix", "type": "blend", "materials": ["gold", "red"], "weight": 0.35},
      {"name": "striped", "type": "blend", "materials": ["red", "glass"], "weight": 0.9, "weight_texture": "cells"},
      {"name": "nested", "type": "blend", "materials": ["mix", "matte"], "weight": 0.5},
      {"name": "lamp", "type": "emissive", "emission": [30, 28, 25]})";

Scene blend_scene(const std::string& materials = kBlendMaterials, const std::string& a = "mix",
                  const std::string& b = "striped", const std::string& c = "nested") {
  return parse_scene(R"({
    "camera": {"look_from": [0, 2.2, 6], "look_at": [0, 0.4, 0], "vfov": 40},
    "sky": {"type": "uniform", "radiance": [0.3, 0.3, 0.35]},
    "textures": [{"name": "cells", "type": "checker", "size": 0.3, "even": [1, 1, 1], "odd": [0.1, 0.1, 0.1]}],
    "materials": [)" + materials + R"(],
    "spheres": [
      {"center": [0, -1000, 0], "radius": 1000, "material": "ground"},
      {"center": [-1.2, 0.5, 0], "radius": 0.5, "material": ")" + a + R"("},
      {"center": [0, 0.5, 0], "radius": 0.5, "material": ")" + b + R"("},
      {"center": [1.2, 0.5, 0], "radius": 0.5, "material": ")" + c + R"("},
      {"center": [1.5, 4, 2], "radius": 0.4, "material": "lamp"}]})",
                     kSource);
}

// Weight 0 picks the first material at every hit and weight 1 the second, drawing
// no random number: the megakernel's image is bit for bit its material's, and the
// wavefront's to the rounding of its film's additions (their order is the threads').
TEST(BlendRender, AWeightOfZeroOrOneRendersExactlyItsMaterial) {
  for (const char* w : {"0", "1"}) {
    const std::string extra = std::string(R"(, {"name": "edge", "type": "blend", "materials": ["gold", "red"], "weight": )") + w + "}";
    const Scene blended = blend_scene(kBlendMaterials + extra, "edge", "striped", "nested");
    const Scene plain = blend_scene(kBlendMaterials + extra, w[0] == '0' ? "gold" : "red", "striped", "nested");
    for (Kernel k : {Kernel::Megakernel, Kernel::WavefrontSorted}) {
      const RenderResult x = render(blended, options_for(Backend::Cpu, k, 32, 18, 4, 8, 3, 1));
      const RenderResult y = render(plain, options_for(Backend::Cpu, k, 32, 18, 4, 8, 3, 1));
      ASSERT_EQ(x.rgb.size(), y.rgb.size());
      for (size_t i = 0; i < x.rgb.size(); ++i) {
        if (k == Kernel::Megakernel) {
          ASSERT_EQ(x.rgb[i], y.rgb[i]) << "weight " << w << ", " << kernel_name(k) << " " << i;
        } else {
          ASSERT_NEAR(x.rgb[i], y.rgb[i], 1e-5f * (1.0f + std::fabs(y.rgb[i]))) << "weight " << w << ", " << kernel_name(k) << " " << i;
        }
      }
    }
  }
}

// A blend of two Lambertians is the Lambertian of their mixed albedo: a lone
// sphere under the sky, whose image is linear in its albedo, renders 0.75 x 0.9 +
// 0.25 x 0.1 = 0.7 (16 seeds each, within 4 standard errors, at most 1% of the value).
TEST(BlendRender, ABlendOfTwoLambertiansRendersAsTheirMixedAlbedo) {
  const std::string lambertians = R"({"name": "light", "type": "lambertian", "albedo": [0.9, 0.9, 0.9]},
      {"name": "dark", "type": "lambertian", "albedo": [0.1, 0.1, 0.1]},)";
  auto means = [&](const std::string& m) {
    const Scene s = sphere_scene(lambertians + m);
    std::vector<double> out;
    for (uint32_t seed = 1; seed <= 16; ++seed) {
      out.push_back(mean(render(s, options_for(Backend::Cpu, Kernel::Megakernel, 32, 32, 16, 8, 3, seed)).rgb));
    }
    return out;
  };
  test::expect_same_expectation(means(R"({"name": "m", "type": "blend", "materials": ["light", "dark"], "weight": 0.25})"),
                                means(R"({"name": "m", "type": "lambertian", "albedo": [0.7, 0.7, 0.7]})"), 0.01);
}

// Each strategy sees the picked material's BSDF: light sampling on and off converge
// to the same image (16 seeds each, within 4 standard errors, at most 3%).
TEST(BlendRender, LightSamplingOnAndOffConvergeToTheSameImage) {
  const Scene scene = blend_scene();
  test::expect_same_expectation(test::seed_means(scene, 32, 18, 48, 1), test::seed_means(scene, 32, 18, 48, 0), 0.03);
}

// The wavefront picks at intersect (for the sort key) what shade picks: the CPU's
// wavefront kernels trace the megakernel's paths, only the film's additions ordered
// otherwise.
TEST(BlendRender, CpuWavefrontKernelsMatchTheMegakernelToRounding) {
  test::expect_cpu_wavefront_kernels_match_the_megakernel(blend_scene());
}

TEST(BlendRender, EveryCudaKernelAgreesWithTheCpu) {
  WT_REQUIRE_CUDA();
  const Scene scene = blend_scene();
  test::expect_cuda_agrees_with_cpu(
      [&](Backend b, Kernel k, uint32_t seed) { return render(scene, options_for(b, k, 64, 36, 8, 8, 3, seed)); }, 3);
}

// ---- the scene format ----

TEST(BlendScene, ABlendReadsItsMaterialsWeightAndTexture) {
  const Scene s = sphere_scene(
      kTwoLambertians + R"({"name": "m", "type": "blend", "materials": ["b", "a"], "weight": 0.3, "weight_texture": "t"})",
      R"({"name": "t", "type": "checker", "size": 1, "even": [1, 1, 1], "odd": [0, 0, 0]})");
  const Material& m = s.materials.at(material_index_named(s, "m"));
  ASSERT_EQ(m.kind, MaterialKind::Blend);
  const MaterialParams& p = s.material_params.at(static_cast<size_t>(m.params));
  EXPECT_EQ(p.blend_materials[0], 1);
  EXPECT_EQ(p.blend_materials[1], 0);
  EXPECT_FLOAT_EQ(p.blend_weight, 0.3f);
  EXPECT_EQ(p.blend_texture, 0);
  EXPECT_NE(s.kernel_kinds() & kMicrofacet, 0u) << "the kernels that pick";
  const Scene d = sphere_scene(kTwoLambertians + R"({"name": "m", "type": "blend", "materials": ["a", "b"]})");
  EXPECT_FLOAT_EQ(d.material_params.at(static_cast<size_t>(d.materials.back().params)).blend_weight, 0.5f) << "the default";
}

TEST(BlendScene, BadBlendsNameTheFieldAndSayWhy) {
  auto expect_error = [](const std::string& materials, const std::string& field, const std::string& why) {
    const std::string e = error_of(materials);
    EXPECT_NE(e.find(field), std::string::npos) << e;
    EXPECT_NE(e.find(why), std::string::npos) << e;
  };
  expect_error(R"({"name": "a", "type": "lambertian"}, {"name": "m", "type": "blend", "materials": ["a"]})",
               "/materials/1/materials", "a list of two material names");
  expect_error(R"({"name": "m", "type": "blend", "materials": ["a", "b"]}, {"name": "a", "type": "lambertian"},
               {"name": "b", "type": "lambertian"})",
               "/materials/0/materials/0", "defined before it");
  expect_error(kTwoLambertians + R"({"name": "m", "type": "blend", "materials": ["a", "b"], "weight": 1.5})",
               "/materials/2/weight", "");
  expect_error(kTwoLambertians + R"({"name": "m", "type": "blend", "materials": ["a", "b"], "weight_texture": "none"})",
               "/materials/2/weight_texture", "unknown texture 'none'");
  expect_error(R"({"name": "a", "type": "lambertian"}, {"name": "lamp", "type": "emissive", "emission": [1, 1, 1]},
               {"name": "m", "type": "blend", "materials": ["a", "lamp"]})",
               "/materials/2/materials/1", "emits");
  expect_error(kTwoLambertians + R"({"name": "m", "type": "blend", "materials": ["a", "b"], "albedo": [1, 1, 1]})",
               "/materials/2", "albedo");
  // Five deep is one too many.
  std::string deep = kTwoLambertians + R"({"name": "l1", "type": "blend", "materials": ["a", "b"]},)";
  for (int i = 2; i <= 4; ++i) {
    deep += R"({"name": "l)" + std::to_string(i) + R"(", "type": "blend", "materials": ["a", "l)" + std::to_string(i - 1) + R"("]},)";
  }
  EXPECT_EQ(error_of(deep + R"({"name": "m", "type": "lambertian"})"), "") << "four deep is supported";
  expect_error(deep + R"({"name": "m", "type": "blend", "materials": ["l4", "a"]})", "/materials/6/materials",
               "5 deep");
}

}  // namespace
}  // namespace wt

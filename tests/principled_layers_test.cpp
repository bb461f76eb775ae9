// Principled's layers against the BSDF contract (bsdf.hpp), as bsdf_test.cpp holds
// every kind to it: the clear coat (KHR_materials_clearcoat), transmission through
// a thin wall (KHR_materials_transmission) and into a volume
// (KHR_materials_volume). Chi-square fits of the sampler on both sides, wrong lobe
// shares shown to fail, weight = eval / pdf, reciprocity, and the white furnace:
// never more than arrives; a white thin wall and a white volume return or pass all
// of it (within 1%); a white base under a full coat loses at most what the coat's
// reciprocal weighting costs (principled.hpp). The kernels without the layers
// (geometry.hpp's kLayersAndAlpha) shade a principled material without them as the
// kernels with them do, and the scenes that need the layers select them.
#include <gtest/gtest.h>

#include "bsdf_support.hpp"

namespace wt {
namespace {

const char* const kCoated[] = {
    R"({"name": "m", "type": "principled", "albedo": [0.8, 0.2, 0.1], "roughness": 0.6, "clearcoat": 1, "clearcoat_roughness": 0.1})",
    R"({"name": "m", "type": "principled", "albedo": [0.8, 0.2, 0.1], "roughness": 0.6, "clearcoat": 0.5, "clearcoat_roughness": 0.5, "metallic": 0.5})",
    R"({"name": "m", "type": "principled", "albedo": [0.8, 0.2, 0.1], "roughness": 0.3, "clearcoat": 1})",
};
// KHR_materials_specular's tinted f0 and its strength (alone, and with a thin wall).
const char* const kTinted[] = {
    R"({"name": "m", "type": "principled", "albedo": [0.8, 0.5, 0.3], "roughness": 0.4, "specular_color": [1, 0.6, 0.3], "specular": 0.7})",
    R"({"name": "m", "type": "principled", "albedo": [0.8, 0.5, 0.3], "roughness": 0.5, "specular_color": [0.5, 1, 1], "transmission": 0.7})",
};
const char* const kThin[] = {
    R"({"name": "m", "type": "principled", "albedo": [0.9, 0.7, 0.5], "roughness": 0.3, "transmission": 1})",
    R"({"name": "m", "type": "principled", "albedo": [0.9, 0.7, 0.5], "roughness": 0.7, "transmission": 0.6, "metallic": 0.2})",
    R"({"name": "m", "type": "principled", "albedo": [0.9, 0.7, 0.5], "roughness": 0.3, "transmission": 0.8, "clearcoat": 1, "clearcoat_roughness": 0.2})",
};
const char* const kVolume[] = {
    R"({"name": "m", "type": "principled", "albedo": [0.9, 0.7, 0.5], "roughness": 0.3, "transmission": 1, "thin": false})",
    R"({"name": "m", "type": "principled", "albedo": [0.9, 0.7, 0.5], "roughness": 0.6, "transmission": 0.7, "thin": false, "ior": 1.33})",
};

TEST(PrincipledLayers, TheFileSetsTheLayers) {
  const Case coat = material(kCoated[0]);
  EXPECT_FLOAT_EQ(coat.p.clearcoat, 1.0f);
  EXPECT_FLOAT_EQ(coat.p.coat_alpha, 0.01f);
  EXPECT_GE(coat.p.coat_table, 0);
  const Case thin = material(kThin[0]);
  EXPECT_TRUE(thin.m.flags & kMaterialThin);
  EXPECT_FLOAT_EQ(thin.p.transmission, 1.0f);
  EXPECT_LT(thin.p.glass_table, 0);
  const Case volume = material(
      R"({"name": "m", "type": "principled", "transmission": 1, "thin": false, "attenuation_color": [0.5, 1, 0.25], "attenuation_distance": 2})");
  EXPECT_FALSE(volume.m.flags & kMaterialThin);
  EXPECT_GE(volume.p.glass_table, 0);
  EXPECT_NEAR(volume.p.attenuation.x, std::log(2.0) / 2.0, 1e-6);
  EXPECT_EQ(volume.p.attenuation.y, 0.0f);
  EXPECT_NEAR(volume.p.attenuation.z, std::log(4.0) / 2.0, 1e-6);
  for (const auto& [json, what] : std::vector<std::pair<std::string, std::string>>{
           {R"({"name": "m", "type": "principled", "attenuation_distance": 1})", "a thin wall holds no volume"},
           {R"({"name": "m", "type": "principled", "clearcoat": 1.5})", "clearcoat"},
           {R"({"name": "m", "type": "principled", "transmission": 1, "thin": false, "attenuation_distance": 0})",
            "attenuation_distance"}}) {
    try {
      material(json);
      ADD_FAILURE() << json << " was accepted";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  }
}

TEST(PrincipledLayers, ChiSquareOfEachLayer) {
  for (const char* json : kCoated) {
    const Case c = material(json);
    for (double deg : kAngles) expect_fits(c, deg);
  }
  for (const char* json : kTinted) {
    const Case c = material(json);
    for (double deg : {0.0, 60.0}) {
      expect_fits(c, deg, true);
      if (c.p.transmission > 0.0f) expect_fits(c, deg, false);
    }
  }
  for (const char* const* list : {kThin, kVolume}) {
    for (int i = 0; i < (list == kThin ? 3 : 2); ++i) {
      const Case c = material(list[i]);
      for (double deg : {0.0, 45.0, 80.0}) {
        expect_fits(c, deg, true);
        expect_fits(c, deg, false);
      }
    }
  }
}

// The same fits fail where the density misstates a lobe's share: a coat of weight
// 0.3 claimed where it is 1, a thin wall passing 0.3 where it passes 1, and a
// volume whose density is its own scaled by 1.1 on the far side.
TEST(PrincipledLayers, WrongSharesFail) {
  const vec3 wo = incident(45.0);
  const Case coat = material(kCoated[0]);
  const BsdfAt b = at(coat, wo);
  BsdfAt less = b;
  less.p.clearcoat = 0.3f;
  EXPECT_LT(chi2_test(b, wo, pdf_of(b, wo), mirror(wo), 0, 17).z, kRejectZ) << "coat: the right density";
  EXPECT_GT(chi2_test(b, wo, pdf_of(less, wo), mirror(wo), 0, 17).z, kRejectZ) << "coat claimed 0.3";
  const Case thin = material(kThin[0]);
  const BsdfAt t = at(thin, wo);
  BsdfAt passes_less = t;
  passes_less.p.transmission = 0.3f;
  EXPECT_LT(chi2_test(t, wo, pdf_of(t, wo), -wo, -1, 17).z, kRejectZ) << "thin: the right density";
  EXPECT_GT(chi2_test(t, wo, pdf_of(passes_less, wo), -wo, -1, 17).z, kRejectZ) << "thin claimed 0.3";
  const Case volume = material(kVolume[0]);
  const BsdfAt v = at(volume, wo);
  const vec3 through = refracted(wo, volume.m.ior);
  EXPECT_LT(chi2_test(v, wo, pdf_of(v, wo), through, -1, 17).z, kRejectZ) << "volume: the right density";
  EXPECT_GT(chi2_test(v, wo, [&](const vec3& wi) { return 1.1f * pdf_bsdf(v, wo, wi); }, through, -1, 17).z, kRejectZ)
      << "volume scaled by 1.1";
}

TEST(PrincipledLayers, SampleWeightIsEvalOverPdf) {
  std::vector<std::string> cases(std::begin(kCoated), std::end(kCoated));
  cases.insert(cases.end(), std::begin(kTinted), std::end(kTinted));
  cases.insert(cases.end(), std::begin(kThin), std::end(kThin));
  cases.insert(cases.end(), std::begin(kVolume), std::end(kVolume));
  for (const std::string& json : cases) expect_weights_are_eval_over_pdf(material(json));
}

// f(wo, wi) = f(wi, wo), for pairs over the whole sphere; into a volume, f / n^2
// of wo's side is symmetric (the radiance scaling), as glass's, and as for glass
// without Turquin's compensation, whose 1 / E(mu_o) is not reciprocal.
TEST(PrincipledLayers, LayersAreReciprocal) {
  std::vector<std::string> cases(std::begin(kCoated), std::end(kCoated));
  cases.insert(cases.end(), std::begin(kTinted), std::end(kTinted));
  cases.insert(cases.end(), std::begin(kThin), std::end(kThin));
  cases.push_back(R"({"name": "m", "type": "principled", "albedo": [0.9, 0.7, 0.5], "roughness": 0.3, "transmission": 1,
      "thin": false, "energy_compensation": false})");
  cases.push_back(R"({"name": "m", "type": "principled", "albedo": [0.9, 0.7, 0.5], "roughness": 0.6, "transmission": 0.7,
      "thin": false, "ior": 1.33, "clearcoat": 1, "clearcoat_roughness": 0.3, "energy_compensation": false})");
  for (const std::string& json : cases) {
    const Case c = material(json);
    const bool volume = c.p.transmission > 0.0f && !(c.m.flags & kMaterialThin);
    const ReciprocalPairs pairs = reciprocal_pairs(c, volume ? c.m.ior : 1.0f);
    EXPECT_GT(pairs.nonzero, 500) << c.name;
    if (c.p.transmission > 0.0f) EXPECT_GT(pairs.crossing, 200) << c.name;
  }
}

TEST(PrincipledLayers, NoLayerReturnsMoreThanItReceives) {
  for (const char* json : {R"({"name": "m", "type": "principled", "roughness": 0.5, "clearcoat": 1})",
                           R"({"name": "m", "type": "principled", "roughness": 0.2, "metallic": 1, "clearcoat": 1, "clearcoat_roughness": 0.6})",
                           R"({"name": "m", "type": "principled", "roughness": 1, "clearcoat": 1, "clearcoat_roughness": 1})",
                           R"({"name": "m", "type": "principled", "roughness": 0.4, "transmission": 0.5})",
                           R"({"name": "m", "type": "principled", "roughness": 0, "transmission": 1})",
                           R"({"name": "m", "type": "principled", "roughness": 0.5, "transmission": 1, "thin": false})",
                           R"({"name": "m", "type": "principled", "roughness": 0, "transmission": 1, "thin": false})",
                           R"({"name": "m", "type": "principled", "roughness": 0.5, "transmission": 1, "clearcoat": 1})"}) {
    const Case c = material(json);
    for (double deg : kAngles) {
      for (bool outside : {true, false}) {
        const Furnace f = furnace(c, incident(deg, outside));
        EXPECT_LE(f.mean, 1.0 + 4.0 * f.error + 1e-3) << label(c, deg) << (outside ? "" : " inside") << ": " << f.mean;
      }
    }
  }
}

// A white thin wall reflects E_s and passes the rest; a white volume is compensated
// glass: each returns or passes everything (within 1%), on both sides.
TEST(PrincipledLayers, AWhiteWallAndAWhiteVolumeLoseNothing) {
  for (const std::string r : {"0", "0.3", "0.7", "1"}) {
    for (const char* kind : {R"(, "transmission": 1})", R"(, "transmission": 1, "thin": false})",
                             R"(, "transmission": 0.5})"}) {
      const Case c = material(R"({"name": "m", "type": "principled", "roughness": )" + r + kind);
      for (double deg : {0.0, 45.0, 80.0}) {
        for (bool outside : {true, false}) {
          const Furnace f = furnace(c, incident(deg, outside));
          EXPECT_NEAR(f.mean, 1.0, 0.01) << label(c, deg) << (outside ? "" : " inside") << " (error " << f.error << ")";
        }
      }
    }
  }
}

// A white base under a tinted specular layer returns everything in each channel: the
// layer's albedo for the tinted f0 is the index's rescaled (principled.hpp), exact
// for a smooth layer and within 1% for rough compensated ones; and no tint of f0 at
// most 1 returns more than arrives.
TEST(PrincipledLayers, ATintedSpecularLayerOverAWhiteBaseReturnsEverything) {
  for (const std::string r : {"0", "0.3", "0.7", "1"}) {
    const Case c = material(R"({"name": "m", "type": "principled", "specular_color": [1, 0.5, 0], "roughness": )" + r + "}");
    for (double deg : {0.0, 45.0, 80.0}) {
      const vec3 wo = incident(deg);
      const BsdfAt b = at(c, wo);
      vec3 sum(0.0f);
      constexpr int n = 160000;
      for (int i = 0; i < n; ++i) {
        const BsdfSample s = sample_bsdf(b, wo, Rng::at(3, static_cast<uint32_t>(i), 0, 0));
        if (s.lobe != 0u) sum += s.weight;
      }
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(sum[k] / n, 1.0, 0.01) << label(c, deg) << " channel " << k;
    }
  }
  const Case tinted = material(R"({"name": "m", "type": "principled", "specular_color": [1000, 0.5, 1], "roughness": 0.5})");
  for (double deg : kAngles) {
    const Furnace f = furnace(tinted, incident(deg));
    EXPECT_LE(f.mean, 1.0 + 4.0 * f.error + 1e-3) << label(tinted, deg);
  }
}

// Under a full coat a white base returns what the coat reflects and the share the
// coat's reciprocal weighting, min(1 - E_c(mu_o), 1 - E_c(mu_i)), lets through: at
// least 94% of the light (a smooth coat over a diffuse base at normal incidence
// loses 4.6%), and more at grazing angles, where the coat itself reflects most.
TEST(PrincipledLayers, AWhiteBaseUnderACoatLosesLittle) {
  for (const std::string base : {R"("roughness": 0.5)", R"("roughness": 0.4, "metallic": 1)"}) {
    for (const std::string coat : {"0", "0.3", "1"}) {
      const Case c = material(R"({"name": "m", "type": "principled", )" + base + R"(, "clearcoat": 1, "clearcoat_roughness": )" +
                              coat + "}");
      for (double deg : {0.0, 45.0, 80.0}) {
        const Furnace f = furnace(c, incident(deg));
        EXPECT_GT(f.mean, 0.94) << label(c, deg);
        EXPECT_LE(f.mean, 1.0 + 4.0 * f.error + 1e-3) << label(c, deg);
      }
    }
  }
}

// Textured layers: a coat weight, coat roughness and transmission under a constant
// texture are the values they scale to.
TEST(PrincipledLayers, TexturedLayersAreTheValuesTheyScaleTo) {
  const std::string half = R"({"name": "half", "type": "checker", "size": 1, "even": [0.5, 0.6, 0.9], "odd": [0.5, 0.6, 0.9]})";
  const Case textured = material(R"({"name": "m", "type": "principled", "albedo": [0.8, 0.5, 0.2], "roughness": 0.4,
      "clearcoat": 0.8, "clearcoat_texture": "half", "clearcoat_roughness": 0.5, "clearcoat_roughness_texture": "half",
      "transmission": 0.6, "transmission_texture": "half"})",
                                 half);
  const Case plain = material(R"({"name": "m", "type": "principled", "albedo": [0.8, 0.5, 0.2], "roughness": 0.4,
      "clearcoat": 0.4, "clearcoat_roughness": 0.3, "transmission": 0.3})");
  int compared = 0;
  for (int i = 0; i < 2000; ++i) {
    const Rng rng = Rng::at(21, static_cast<uint32_t>(i), 0, 0);
    const vec3 a = unit_sphere_point(rng.uniform(0), rng.uniform(1));
    const vec3 d = unit_sphere_point(rng.uniform(2), rng.uniform(3));
    if (std::fabs(a.z) < 0.05f || std::fabs(d.z) < 0.05f) continue;
    float p_t, p_p;
    const vec3 f_t = eval_bsdf(at(textured, a), a, d, p_t), f_p = eval_bsdf(at(plain, a), a, d, p_p);
    ASSERT_NEAR(p_t, p_p, 1e-4f * p_p + 1e-6f) << "pair " << i;
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(f_t[k], f_p[k], 1e-4f * f_p[k] + 1e-6f) << "pair " << i;
    if (p_p > 0.0f) ++compared;
  }
  EXPECT_GT(compared, 1000);
}

// A kernel compiled without the layers leaves their code out: on a principled
// material without a coat or transmission it samples and evaluates bit for bit as
// one with them, and on a coated one it does not (so the scene must select the
// layers' kernels: below).
TEST(PrincipledLayers, KernelsWithoutTheLayersShadeALayerlessMaterialAlike) {
  const char* const layerless[] = {
      R"({"name": "m", "type": "principled", "albedo": [0.8, 0.5, 0.3], "roughness": 0.5})",
      R"({"name": "m", "type": "principled", "albedo": [0.8, 0.5, 0.3], "roughness": 0.3, "metallic": 0.6})",
      R"({"name": "m", "type": "principled", "albedo": [0.8, 0.5, 0.3], "roughness": 0.4, "specular_color": [1, 0.6, 0.3], "specular": 0.7})",
      R"({"name": "m", "type": "principled", "albedo": [0.8, 0.5, 0.3], "roughness": 0, "metallic": 0.3})"};
  auto same = [](const Case& c) {
    int differ = 0;
    for (double deg : kAngles) {
      const vec3 wo = incident(deg);
      const BsdfAt with = at<true>(c, wo), without = at<false>(c, wo);
      for (uint32_t i = 0; i < 2000; ++i) {
        const Rng rng = Rng::at(7, i, 0, 0);
        const BsdfSample a = sample_bsdf<true, true>(with, wo, rng), b = sample_bsdf<true, false>(without, wo, rng);
        float pa = 0.0f, pb = 0.0f;
        const vec3 wi = a.lobe != 0u ? a.wi : -wo;
        const vec3 fa = eval_bsdf<true, true>(with, wo, wi, pa), fb = eval_bsdf<true, false>(without, wo, wi, pb);
        differ += a.lobe != b.lobe || a.wi != b.wi || a.weight != b.weight || a.pdf != b.pdf || fa != fb || pa != pb;
      }
    }
    return differ;
  };
  for (const char* json : layerless) EXPECT_EQ(same(material(json)), 0) << json;
  EXPECT_GT(same(material(kCoated[0])), 1000) << "a coat the kernel leaves out";
  EXPECT_GT(same(material(kThin[0])), 1000) << "a thin wall the kernel leaves out";
}

TEST(PrincipledLayers, TheLayersAndAlphaSelectTheirKernels) {
  auto kinds = [](const std::string& json) {
    return parse_scene(R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]}, "materials": [)" + json + R"(],
        "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})",
                       "kinds.json")
        .kernel_kinds();
  };
  const uint32_t plain = kinds(R"({"name": "m", "type": "principled", "roughness": 0.5, "metallic": 0.5})");
  EXPECT_TRUE(plain & kMicrofacet);
  EXPECT_FALSE(plain & kLayersAndAlpha) << "no coat, no transmission, no alpha";
  EXPECT_FALSE(kinds(R"({"name": "m", "type": "plastic", "roughness": 0.5})") & kLayersAndAlpha);
  for (const char* json : {kCoated[0], kThin[0], kVolume[0],
                           R"({"name": "m", "type": "principled", "transmission": 1, "thin": false, "attenuation_color": [0.5, 1, 1], "attenuation_distance": 2})"}) {
    const uint32_t k = kinds(json);
    EXPECT_TRUE(k & kLayersAndAlpha) << json;
    EXPECT_TRUE(k & kMicrofacet) << json;
  }
  EXPECT_FALSE(kinds(R"({"name": "m", "type": "principled", "clearcoat": 0, "transmission": 0})") & kLayersAndAlpha);
}

}  // namespace
}  // namespace wt

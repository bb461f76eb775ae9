// Every BSDF against its contract (bsdf.hpp), the way production renderers test
// theirs:
//   - chi-square goodness of fit of the sampler against pdf(), over roughnesses
//     0.05..1 and incident angles from normal to grazing, on both sides of glass;
//     and wrong densities (scaled, of another roughness, of another lobe share)
//     shown to fail;
//   - every sample's weight is eval / pdf and its pdf is pdf();
//   - reciprocity: f(wo, wi) = f(wi, wo) for reflection, and f / n_o^2 = f' / n_i^2
//     through glass (the radiance scaling);
//   - the white furnace: no BSDF returns more than it receives; a white conductor
//     of any roughness, compensated glass and a white smooth plastic return all of
//     it (within 1%).
//
// (The statistics: bsdf_support.hpp.) Principled's coat, transmission and volume:
// principled_layers_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "bsdf_support.hpp"

namespace wt {
namespace {

TEST(BsdfChiSquare, ConductorSamplesItsPdf) {
  for (const std::string& r : kRoughnesses) {
    for (const char* extra : {"", R"(, "anisotropy": 0.8)", R"(, "energy_compensation": false)", R"(, "masking": "separable")"}) {
      const Case c = material(R"({"name": "m", "type": "conductor", "metal": "gold", "roughness": )" + r + extra + "}");
      for (double deg : kAngles) expect_fits(c, deg);
    }
  }
}

TEST(BsdfChiSquare, GlassSamplesItsPdfOnBothSides) {
  for (const std::string& r : {std::string("0.05"), std::string("0.3"), std::string("1")}) {
    for (const char* extra : {"", R"(, "energy_compensation": false, "masking": "separable")"}) {
      const Case c = material(R"({"name": "m", "type": "glass", "ior": 1.5, "roughness": )" + r + extra + "}");
      for (double deg : {0.0, 45.0, 80.0}) {
        expect_fits(c, deg, true);
        expect_fits(c, deg, false);
      }
    }
  }
}

TEST(BsdfChiSquare, PlasticSamplesItsPdf) {
  for (const std::string& r : {std::string("0"), std::string("0.05"), std::string("0.3"), std::string("1")}) {
    const Case c = material(R"({"name": "m", "type": "plastic", "albedo": [0.7, 0.4, 0.2], "roughness": )" + r + "}");
    for (double deg : kAngles) expect_fits(c, deg);
  }
}

// A metallic plastic: the mixture of the plastic and its metal, each picked by its
// share, against the mixture's density.
TEST(BsdfChiSquare, MetallicPlasticSamplesItsPdf) {
  for (const std::string& r : {std::string("0"), std::string("0.05"), std::string("0.4"), std::string("1")}) {
    const Case c = material(R"({"name": "m", "type": "plastic", "albedo": [0.9, 0.6, 0.2], "metallic": 0.5, "roughness": )" +
                            r + "}");
    for (double deg : kAngles) expect_fits(c, deg);
  }
}

// glTF's metallic-roughness (principled): the diffuse and the glossy lobe picked
// by their shares, over roughness and metallic, against the mixture's density.
TEST(BsdfChiSquare, PrincipledSamplesItsPdf) {
  for (const std::string& rm : {std::string("0, \"metallic\": 0.3"), std::string("0.05, \"metallic\": 0.3"),
                                std::string("0.4, \"metallic\": 0.3"), std::string("1, \"metallic\": 0.3"),
                                std::string("0.5, \"metallic\": 0"), std::string("0.5, \"metallic\": 1"),
                                std::string("0.5, \"anisotropy\": 0.7, \"ior\": 1.8")}) {
    const Case c = material(R"({"name": "m", "type": "principled", "albedo": [0.9, 0.6, 0.2], "roughness": )" + rm + "}");
    for (double deg : kAngles) expect_fits(c, deg);
  }
}

// (The fuzzy metal's density grows without bound at the rim of its cone, which
// the midpoint rule here cannot integrate: metal_density_test.cpp tests fuzz below
// 1 with a quadrature made for that rim.)
TEST(BsdfChiSquare, TheStudysKindsSampleTheirPdfs) {
  for (const char* json : {R"({"name": "m", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]})",
                           R"({"name": "m", "type": "metal", "fuzz": 1})",
                           R"({"name": "m", "type": "coated", "albedo": [0.5, 0.5, 0.5], "ior": 1.5})"}) {
    const Case c = material(json);
    for (double deg : kAngles) expect_fits(c, deg);
  }
}

// The same tests fail where the density is not the sampler's: scaled by 1.1, of a
// roughness 25% larger, or (plastic) with the coat's share of the samples wrong.
TEST(BsdfChiSquare, WrongDensitiesFail) {
  auto z_of = [](const Case& c, const vec3& wo, const std::function<float(const vec3&)>& pdf, int side) {
    const BsdfAt b = at(c, wo);
    return chi2_test(b, wo, pdf, side < 0 ? refracted(wo, c.m.ior) : mirror(wo), side, 17).z;
  };
  const vec3 wo = incident(45.0);
  for (const char* json : {R"({"name": "m", "type": "conductor", "metal": "gold", "roughness": 0.3})",
                           R"({"name": "m", "type": "glass", "roughness": 0.3})",
                           R"({"name": "m", "type": "plastic", "albedo": [0.5, 0.5, 0.5], "roughness": 0.3})",
                           R"({"name": "m", "type": "principled", "albedo": [0.5, 0.5, 0.5], "roughness": 0.3, "metallic": 0.5})"}) {
    const Case c = material(json);
    const int side = c.m.kind == MaterialKind::Glass ? -1 : 0;  // glass: its transmission
    const BsdfAt b = at(c, wo);
    EXPECT_LT(z_of(c, wo, pdf_of(b, wo), side), kRejectZ) << c.name << ": the right density";
    EXPECT_GT(z_of(c, wo, [&](const vec3& wi) { return 1.1f * pdf_bsdf(b, wo, wi); }, side), kRejectZ)
        << c.name << ": scaled by 1.1";
    BsdfAt rougher = b;
    rougher.p.ax *= 1.25f;
    rougher.p.ay *= 1.25f;
    EXPECT_GT(z_of(c, wo, pdf_of(rougher, wo), side), kRejectZ) << c.name << ": 25% rougher";
  }
  // Plastic: the coat sampled half the time, as the density claims, where the
  // sampler draws it by its Fresnel share.
  const Case c = material(R"({"name": "m", "type": "plastic", "albedo": [0.5, 0.5, 0.5], "roughness": 0.3})");
  const BsdfAt b = at(c, wo);
  const auto half = [&](const vec3& wi) {
    const Frame fr = b.facing_frame();
    const vec3 lo = fr.to_local(wo), li = fr.to_local(wi);
    if (li.z <= 0.0f) return 0.0f;
    const Ggx g = plastic_ggx(b);
    const vec3 h = glm::normalize(lo + li);
    return 0.5f * li.z / kPi + 0.5f * g.visible_d(lo, h) / (4.0f * glm::dot(lo, h));
  };
  EXPECT_GT(z_of(c, wo, half, 0), kRejectZ) << "plastic with the coat's share 1/2";
  // A metallic plastic whose density claims a metal share of 0.3 where it is 0.6.
  const Case metallic = material(R"({"name": "m", "type": "plastic", "albedo": [0.5, 0.5, 0.5], "metallic": 0.6, "roughness": 0.3})");
  const BsdfAt mb = at(metallic, wo);
  BsdfAt claimed = mb;
  claimed.p.metallic = 0.3f;
  EXPECT_LT(z_of(metallic, wo, pdf_of(mb, wo), 0), kRejectZ) << "metallic plastic: the right density";
  EXPECT_GT(z_of(metallic, wo, pdf_of(claimed, wo), 0), kRejectZ) << "metallic plastic with the metal's share 0.3";
  // A principled material whose density claims metallic 0.2 (a smaller glossy
  // share) where it is 0.7.
  const Case principled =
      material(R"({"name": "m", "type": "principled", "albedo": [0.5, 0.5, 0.5], "metallic": 0.7, "roughness": 0.3})");
  const BsdfAt pb = at(principled, wo);
  BsdfAt less_metal = pb;
  less_metal.p.metallic = 0.2f;
  EXPECT_LT(z_of(principled, wo, pdf_of(pb, wo), 0), kRejectZ) << "principled: the right density";
  EXPECT_GT(z_of(principled, wo, pdf_of(less_metal, wo), 0), kRejectZ) << "principled claiming metallic 0.2";
}

// Every non-specular sample's weight is eval / pdf and its pdf pdf(), to float rounding.
TEST(BsdfContract, SampleWeightIsEvalOverPdf) {
  for (const char* json : {R"({"name": "m", "type": "lambertian", "albedo": [0.5, 0.6, 0.7]})",
                           R"({"name": "m", "type": "metal", "fuzz": 0.5, "albedo": [0.9, 0.8, 0.7]})",
                           R"({"name": "m", "type": "coated", "albedo": [0.5, 0.6, 0.7], "ior": 1.5})",
                           R"({"name": "m", "type": "conductor", "metal": "copper", "roughness": 0.4})",
                           R"({"name": "m", "type": "conductor", "f0": [0.9, 0.6, 0.3], "roughness": 0.7, "anisotropy": 0.5})",
                           R"({"name": "m", "type": "glass", "roughness": 0.4, "tint": [0.9, 0.8, 0.7]})",
                           R"({"name": "m", "type": "plastic", "albedo": [0.5, 0.6, 0.7], "roughness": 0.4})",
                           R"({"name": "m", "type": "plastic", "albedo": [0.5, 0.6, 0.7], "roughness": 0.4, "metallic": 0.5})",
                           R"({"name": "m", "type": "plastic", "albedo": [0.5, 0.6, 0.7], "metallic": 0.5})",
                           R"({"name": "m", "type": "plastic", "albedo": [0.5, 0.6, 0.7]})",
                           R"({"name": "m", "type": "principled", "albedo": [0.5, 0.6, 0.7], "roughness": 0.4, "metallic": 0.5})",
                           R"({"name": "m", "type": "principled", "albedo": [0.5, 0.6, 0.7], "roughness": 0, "metallic": 0.2})",
                           R"({"name": "m", "type": "principled", "albedo": [0.5, 0.6, 0.7], "roughness": 1, "anisotropy": 0.5})"}) {
    expect_weights_are_eval_over_pdf(material(json));
  }
}

// glTF's doubleSided false: the back face reflects nothing, the front face as a
// two-sided material does.
TEST(BsdfContract, AOneSidedPrincipledBackFaceReflectsNothing) {
  const Case one = material(R"({"name": "m", "type": "principled", "roughness": 0.5, "double_sided": false})");
  const Case two = material(R"({"name": "m", "type": "principled", "roughness": 0.5})");
  ASSERT_TRUE(one.m.flags & kMaterialOneSided);
  ASSERT_FALSE(two.m.flags & kMaterialOneSided);
  for (bool outside : {true, false}) {
    const vec3 wo = incident(30.0, outside), wi = incident(50.0, outside);
    const BsdfAt b1 = at(one, wo), b2 = at(two, wo);
    EXPECT_EQ(bsdf_samples_lights(b1), outside);
    EXPECT_TRUE(bsdf_samples_lights(b2));
    const vec3 f1 = eval_bsdf(b1, wo, wi), f2 = eval_bsdf(b2, wo, wi);
    EXPECT_GT(f2.x, 0.0f);
    EXPECT_EQ(f1.x, outside ? f2.x : 0.0f) << (outside ? "front" : "back");
    int scattered = 0;
    for (int i = 0; i < 100; ++i) scattered += sample_bsdf(b1, wo, Rng::at(2, static_cast<uint32_t>(i), 0, 0)).lobe != 0u;
    if (outside) EXPECT_GT(scattered, 90); else EXPECT_EQ(scattered, 0);
  }
}

// Pairs of directions drawn uniformly over the sphere, both ways round.
TEST(BsdfContract, ReflectionIsReciprocal) {
  for (const char* json : {R"({"name": "m", "type": "lambertian", "albedo": [0.5, 0.6, 0.7]})",
                           R"({"name": "m", "type": "conductor", "metal": "gold", "roughness": 0.3})",
                           R"({"name": "m", "type": "conductor", "metal": "iron", "roughness": 0.8, "anisotropy": 0.6})",
                           R"({"name": "m", "type": "conductor", "f0": [1, 1, 1], "roughness": 1, "energy_compensation": true})",
                           R"({"name": "m", "type": "conductor", "metal": "copper", "roughness": 0.6, "masking": "separable"})",
                           R"({"name": "m", "type": "glass", "roughness": 0.5, "energy_compensation": false, "masking": "separable"})",
                           R"({"name": "m", "type": "plastic", "albedo": [0.5, 0.6, 0.7], "roughness": 0.5})",
                           R"({"name": "m", "type": "plastic", "albedo": [0.5, 0.6, 0.7], "roughness": 0.5, "metallic": 0.4})",
                           R"({"name": "m", "type": "plastic", "albedo": [0.5, 0.6, 0.7]})",
                           R"({"name": "m", "type": "principled", "albedo": [0.5, 0.6, 0.7], "roughness": 0.5, "metallic": 0.4})",
                           R"({"name": "m", "type": "principled", "albedo": [0.9, 0.6, 0.3], "roughness": 0.8, "anisotropy": 0.6, "metallic": 1})",
                           R"({"name": "m", "type": "glass", "roughness": 0.5, "energy_compensation": false})"}) {
    const Case c = material(json);
    EXPECT_GT(reciprocal_pairs(c, c.m.ior).nonzero, 500) << c.name;
  }
}

TEST(BsdfFurnace, NoBsdfReturnsMoreThanItReceives) {
  for (const char* json : {R"({"name": "m", "type": "lambertian"})", R"({"name": "m", "type": "metal", "fuzz": 0.6})",
                           R"({"name": "m", "type": "coated", "ior": 1.5})", R"({"name": "m", "type": "dielectric", "ior": 1.5})",
                           R"({"name": "m", "type": "conductor", "metal": "silver", "roughness": 0.6})",
                           R"({"name": "m", "type": "conductor", "f0": [1, 1, 1], "roughness": 0.7, "anisotropy": 0.9})",
                           R"({"name": "m", "type": "conductor", "f0": [1, 1, 1], "roughness": 1, "energy_compensation": false})",
                           R"({"name": "m", "type": "glass", "roughness": 0.6, "energy_compensation": false})",
                           R"({"name": "m", "type": "glass", "thin": true})",
                           R"({"name": "m", "type": "plastic", "roughness": 0.6})",
                           R"({"name": "m", "type": "plastic", "roughness": 0.6, "metallic": 0.5})",
                           R"({"name": "m", "type": "principled", "roughness": 0})",
                           R"({"name": "m", "type": "principled", "roughness": 0.3})",
                           R"({"name": "m", "type": "principled", "roughness": 1})",
                           R"({"name": "m", "type": "principled", "roughness": 0.6, "metallic": 0.5})",
                           R"({"name": "m", "type": "principled", "roughness": 0.6, "ior": 2.5})"}) {
    const Case c = material(json);
    for (double deg : kAngles) {
      for (bool outside : {true, false}) {
        const Furnace f = furnace(c, incident(deg, outside));
        EXPECT_LE(f.mean, 1.0 + 4.0 * f.error + 1e-3) << label(c, deg) << (outside ? "" : " inside") << ": " << f.mean;
      }
    }
  }
}

// Kulla-Conty compensation: a white conductor returns all of the light, within 1%,
// at every roughness and angle; without it, GGX at roughness 1 loses over 10% at
// grazing incidence (what the compensation puts back).
TEST(BsdfFurnace, AWhiteConductorOfAnyRoughnessReturnsEverything) {
  for (const std::string r : {"0.05", "0.25", "0.5", "0.75", "1", R"(1, "masking": "separable")"}) {
    const Case c = material(R"({"name": "m", "type": "conductor", "f0": [1, 1, 1], "roughness": )" + r + "}");
    for (double deg : {0.0, 30.0, 60.0, 80.0, 88.0}) {
      const Furnace f = furnace(c, incident(deg));
      EXPECT_NEAR(f.mean, 1.0, 0.01) << label(c, deg) << " (standard error " << f.error << ")";
      EXPECT_LT(4.0 * f.error, 0.005) << label(c, deg);
    }
  }
  // A white fully metallic plastic is that conductor.
  for (const std::string r : {"0.3", "1"}) {
    const Case c = material(R"({"name": "m", "type": "plastic", "albedo": [1, 1, 1], "metallic": 1, "roughness": )" + r + "}");
    for (double deg : {0.0, 60.0, 88.0}) {
      const Furnace f = furnace(c, incident(deg));
      EXPECT_NEAR(f.mean, 1.0, 0.01) << label(c, deg) << " (standard error " << f.error << ")";
    }
  }
  // And so is a white fully metallic principled material.
  for (const std::string r : {"0.3", "1"}) {
    const Case c = material(R"({"name": "m", "type": "principled", "metallic": 1, "roughness": )" + r + "}");
    for (double deg : {0.0, 60.0, 88.0}) {
      const Furnace f = furnace(c, incident(deg));
      EXPECT_NEAR(f.mean, 1.0, 0.01) << label(c, deg) << " (standard error " << f.error << ")";
    }
  }
  const Case single = material(R"({"name": "m", "type": "conductor", "f0": [1, 1, 1], "roughness": 1, "energy_compensation": false})");
  EXPECT_LT(furnace(single, incident(80.0)).mean, 0.9) << "single scattering should lose energy at roughness 1";
}

// A white principled dielectric returns everything at any roughness: its base
// takes what the specular layer does not reflect (albedo scaling, principled.hpp),
// exactly when smooth, to the layer table's interpolation when rough; the glTF
// specification's sketch, the base weighed by 1 - F at the pair's half vector,
// returned 1.35 at 80 degrees when smooth.
TEST(BsdfFurnace, AWhitePrincipledDielectricReturnsEverything) {
  for (const std::string r : {"0", "0.3", "0.7", "1", R"(0.5, "ior": 2.2)"}) {
    const Case c = material(R"({"name": "m", "type": "principled", "roughness": )" + r + "}");
    for (double deg : {0.0, 45.0, 80.0}) {
      const Furnace f = furnace(c, incident(deg));
      EXPECT_NEAR(f.mean, 1.0, 0.01) << label(c, deg) << " (standard error " << f.error << ")";
    }
  }
}

// Compensated glass loses nothing on either side; a thin sheet and a white smooth
// plastic conserve energy by construction.
TEST(BsdfFurnace, CompensatedGlassThinGlassAndSmoothPlasticReturnEverything) {
  for (const char* json : {R"({"name": "m", "type": "glass", "roughness": 0.3})", R"({"name": "m", "type": "glass", "roughness": 1})",
                           R"({"name": "m", "type": "glass", "thin": true})", R"({"name": "m", "type": "plastic"})"}) {
    const Case c = material(json);
    for (double deg : {0.0, 30.0, 60.0, 80.0}) {
      for (bool outside : {true, false}) {
        if (!outside && c.m.kind == MaterialKind::Plastic) continue;
        const Furnace f = furnace(c, incident(deg, outside));
        EXPECT_NEAR(f.mean, 1.0, 0.01) << label(c, deg) << (outside ? "" : " inside") << " (error " << f.error << ")";
      }
    }
  }
}

// A textured roughness scales the roughness by the texture's green channel: a
// roughness 0.6 under a constant 0.5 is the roughness 0.3 (conductors exactly, for
// they share one table; glass and plastic within 1%, their tables by roughness read
// between rows), and compensated glass so textured still returns everything.
TEST(BsdfTextures, ATexturedRoughnessIsTheRoughnessItScalesTo) {
  const std::string half = R"({"name": "half", "type": "checker", "size": 1, "even": [0.9, 0.5, 0.1], "odd": [0.9, 0.5, 0.1]})";
  for (const std::string kind : {R"("type": "conductor", "metal": "gold")", R"("type": "glass")",
                                 R"("type": "plastic", "albedo": [0.5, 0.6, 0.7])"}) {
    const Case textured = material(R"({"name": "m", )" + kind + R"(, "roughness": 0.6, "roughness_texture": "half"})", half);
    const Case plain = material(R"({"name": "m", )" + kind + R"(, "roughness": 0.3})");
    EXPECT_EQ(textured.p.table_rows, textured.m.kind == MaterialKind::Conductor ? 1 : kEnergySize) << kind;
    const bool exact = textured.m.kind == MaterialKind::Conductor;
    int compared = 0;
    for (int i = 0; i < 2000; ++i) {
      const Rng rng = Rng::at(13, static_cast<uint32_t>(i), 0, 0);
      const vec3 a = unit_sphere_point(rng.uniform(0), rng.uniform(1));
      const vec3 d = unit_sphere_point(rng.uniform(2), rng.uniform(3));
      if (std::fabs(a.z) < 0.05f || std::fabs(d.z) < 0.05f) continue;
      float p_t, p_p;
      const vec3 f_t = eval_bsdf(at(textured, a), a, d, p_t), f_p = eval_bsdf(at(plain, a), a, d, p_p);
      const float tol = exact ? 1e-5f : 0.01f;
      ASSERT_NEAR(p_t, p_p, tol * p_p + 1e-6f) << kind << " pair " << i;
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(f_t[k], f_p[k], tol * f_p[k] + 1e-6f) << kind << " pair " << i;
      if (p_p > 0.0f) ++compared;
    }
    EXPECT_GT(compared, 500) << kind;
  }
  const Case glass = material(R"({"name": "m", "type": "glass", "roughness": 1, "roughness_texture": "half"})", half);
  for (double deg : {0.0, 60.0}) {
    for (bool outside : {true, false}) {
      const Furnace f = furnace(glass, incident(deg, outside));
      EXPECT_NEAR(f.mean, 1.0, 0.01) << "textured rough glass at " << deg << (outside ? "" : " inside");
    }
  }
}

// A metallic texture scales metallic by its blue channel: metallic 0.8 under a
// constant 0.5 is metallic 0.4, to rounding.
TEST(BsdfTextures, AMetallicTextureIsTheMetallicItScalesTo) {
  const std::string half = R"({"name": "half", "type": "checker", "size": 1, "even": [0.1, 0.9, 0.5], "odd": [0.1, 0.9, 0.5]})";
  const Case textured = material(
      R"({"name": "m", "type": "plastic", "albedo": [0.8, 0.5, 0.2], "roughness": 0.4, "metallic": 0.8, "metallic_texture": "half"})",
      half);
  const Case plain = material(R"({"name": "m", "type": "plastic", "albedo": [0.8, 0.5, 0.2], "roughness": 0.4, "metallic": 0.4})");
  int compared = 0;
  for (int i = 0; i < 2000; ++i) {
    const Rng rng = Rng::at(21, static_cast<uint32_t>(i), 0, 0);
    const vec3 a = unit_sphere_point(rng.uniform(0), rng.uniform(1));
    const vec3 d = unit_sphere_point(rng.uniform(2), rng.uniform(3));
    if (a.z < 0.05f || d.z < 0.05f) continue;
    float p_t, p_p;
    const vec3 f_t = eval_bsdf(at(textured, a), a, d, p_t), f_p = eval_bsdf(at(plain, a), a, d, p_p);
    ASSERT_NEAR(p_t, p_p, 1e-5f * p_p + 1e-6f) << "pair " << i;
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(f_t[k], f_p[k], 1e-5f * f_p[k] + 1e-6f) << "pair " << i;
    ++compared;
  }
  EXPECT_GT(compared, 300);
}

}  // namespace
}  // namespace wt

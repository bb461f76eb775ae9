// Mitsuba 3 scenes as wavetrace scenes (scene/mitsuba_scene.hpp): each plugin's
// parameters mapped as docs/scene-format.md ("Mitsuba 3 scenes") says, what is not
// supported refused in one line naming the file and the line, and a scene read from
// XML rendering exactly as its converted JSON does. The built-in shapes, the
// `lights` section, the UV checker and a mesh's alpha, which the mapping writes into
// the JSON, are tested here too.
#include "scene/mitsuba_scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "app/convert.hpp"
#include "app/job.hpp"
#include "dispatch/renderer.hpp"
#include "errors/errors.hpp"
#include "render_support.hpp"
#include "scene/bsdf_tables.hpp"
#include "scene/mesh_shapes.hpp"
#include "scene/mitsuba_metals.hpp"
#include "scene/scene_file.hpp"
#include "test_support.hpp"
#include "wavetrace/texture.hpp"

namespace wt::mitsuba {
namespace {

using json = nlohmann::json;

// A sensor the tests share: 40 x 30 pixels, looking down -z from z = 4.
const char* const kSensor = R"(
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="40"/><integer name="height" value="30"/><rfilter type="box"/></film>
  </sensor>)";

class MitsubaScene : public testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& text) const {
    const std::string path = (folder_.root() / name).string();
    std::ofstream(path) << text;
    return path;
  }
  // A scene of the shared sensor and `body`.
  std::string scene(const std::string& body, const std::string& name = "s.xml") const {
    return write(name, std::string("<scene version=\"3.0.0\">") + kSensor + body + "</scene>");
  }
  json mapped(const std::string& body) const { return read_mitsuba_scene(scene(body)); }
  // The one material of a rectangle with `bsdf`.
  json material(const std::string& bsdf) const {
    const json doc = mapped("<shape type=\"rectangle\">" + bsdf + "</shape>");
    EXPECT_EQ(doc["materials"].size(), 1u) << doc.dump();
    return doc["materials"][0];
  }
  std::string refusal(const std::string& body) const {
    try {
      read_mitsuba_scene(scene(body));
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }
  test::TestFolder folder_;
};

double num(const json& j) { return j.get<double>(); }

TEST_F(MitsubaScene, TheSensorIsTheCameraWithItsFieldOfViewOnTheAxisMitsubaMeasures) {
  const json doc = mapped("<shape type=\"rectangle\"/>");
  EXPECT_EQ(doc["camera"]["look_from"], json::array({0.0, 0.0, 4.0}));
  EXPECT_EQ(doc["camera"]["look_at"], json::array({0.0, 0.0, 3.0}));
  EXPECT_EQ(doc["camera"]["up"], json::array({0.0, 1.0, 0.0}));
  // fov 40 across x of a 4:3 film: tan(v/2) = tan(20 deg) * 3/4.
  EXPECT_NEAR(num(doc["camera"]["vfov"]), 2 * std::atan(std::tan(20 * M_PI / 180) * 0.75) * 180 / M_PI, 1e-9);
  EXPECT_EQ(doc["render"]["width"], 40);
  EXPECT_EQ(doc["render"]["height"], 30);
  EXPECT_EQ(doc["render"]["spp"], 4);
  // No integrator: Mitsuba's path tracer, unbounded, to wavetrace's deepest.
  EXPECT_EQ(doc["render"]["depth"], 1024);
  EXPECT_EQ(doc["render"]["roulette_depth"], 5);
  EXPECT_EQ(doc["sky"], json({{"type", "uniform"}, {"radiance", {0, 0, 0}}}));

  auto vfov = [&](const std::string& axis, int w, int h) {
    const std::string s = "<scene version=\"3.0.0\"><sensor type=\"perspective\"><float name=\"fov\" value=\"60\"/>"
                          "<string name=\"fov_axis\" value=\"" + axis + "\"/><film type=\"hdrfilm\"><integer name=\"width\" value=\"" +
                          std::to_string(w) + "\"/><integer name=\"height\" value=\"" + std::to_string(h) +
                          "\"/><rfilter type=\"box\"/></film></sensor><shape type=\"rectangle\"/></scene>";
    return num(read_mitsuba_scene(write("f.xml", s))["camera"]["vfov"]);
  };
  const double t = std::tan(30 * M_PI / 180);
  auto deg = [](double tangent) { return 2 * std::atan(tangent) * 180 / M_PI; };
  EXPECT_NEAR(vfov("y", 200, 100), 60, 1e-9);
  EXPECT_NEAR(vfov("x", 200, 100), deg(t / 2), 1e-9);
  EXPECT_NEAR(vfov("diagonal", 300, 400), deg(t * 400 / 500), 1e-9);
  EXPECT_NEAR(vfov("smaller", 200, 100), 60, 1e-9);             // y is the smaller
  EXPECT_NEAR(vfov("smaller", 100, 200), deg(t * 2), 1e-9);     // x is
  EXPECT_NEAR(vfov("larger", 200, 100), deg(t / 2), 1e-9);
  // A focal length (Mitsuba's default 50mm): 35 mm film's diagonal angle on the film's
  // diagonal. Mitsuba 3.7.1 gives x_fov 38.1848 degrees for 50mm on 400 x 300.
  const std::string focal = "<scene version=\"3.0.0\"><sensor type=\"perspective\">"
                            "<film type=\"hdrfilm\"><integer name=\"width\" value=\"400\"/><integer name=\"height\" "
                            "value=\"300\"/><rfilter type=\"box\"/></film></sensor><shape type=\"rectangle\"/></scene>";
  const double vertical = num(read_mitsuba_scene(write("l.xml", focal))["camera"]["vfov"]);
  const double x_fov = 2 * std::atan(std::tan(vertical / 2 * M_PI / 180) * 4 / 3) * 180 / M_PI;
  EXPECT_NEAR(x_fov, 38.1848, 1e-4);
}

TEST_F(MitsubaScene, AThinLensGivesTheApertureAsADiameterAndItsFocus) {
  const std::string body = R"(<scene version="3.0.0"><sensor type="thinlens"><float name="fov" value="30"/>
    <float name="aperture_radius" value="0.05"/><float name="focus_distance" value="7"/>
    <transform name="to_world"><translate x="1"/></transform>
    <film type="hdrfilm"><rfilter type="box"/></film></sensor><shape type="rectangle"/></scene>)";
  const json doc = read_mitsuba_scene(write("t.xml", body));
  EXPECT_DOUBLE_EQ(num(doc["camera"]["aperture"]), 0.1);
  EXPECT_DOUBLE_EQ(num(doc["camera"]["focus_distance"]), 7);
  EXPECT_EQ(doc["camera"]["look_from"], json::array({1.0, 0.0, 0.0}));
  EXPECT_EQ(doc["camera"]["look_at"], json::array({1.0, 0.0, 1.0}));  // Mitsuba's camera looks down +z
  EXPECT_EQ(doc["render"]["width"], 768);  // hdrfilm's defaults
  EXPECT_EQ(doc["render"]["height"], 576);
}

TEST_F(MitsubaScene, IntegratorsAndFiltersMapOrWarn) {
  auto with = [&](const std::string& integrator) {
    return mapped(integrator + "<shape type=\"rectangle\"/>");
  };
  json doc = with(R"(<integrator type="path"><integer name="max_depth" value="6"/><integer name="rr_depth" value="3"/></integrator>)");
  EXPECT_EQ(doc["render"]["depth"], 6);
  EXPECT_EQ(doc["render"]["roulette_depth"], 3);
  EXPECT_FALSE(doc.contains("warnings"));
  doc = with(R"(<integrator type="direct"/>)");
  EXPECT_EQ(doc["render"]["depth"], 2);  // the camera ray and one bounce
  EXPECT_EQ(doc["render"]["nee"], 1);
  doc = with(R"(<integrator type="path"><integer name="max_depth" value="-1"/></integrator>)");
  EXPECT_EQ(doc["render"]["depth"], 1024);
  ASSERT_EQ(doc["warnings"].size(), 1u);
  EXPECT_NE(doc["warnings"][0].get<std::string>().find("s.xml:"), std::string::npos);
  EXPECT_NE(doc["warnings"][0].get<std::string>().find("1024"), std::string::npos);

  const std::string gaussian = R"(<scene version="3.0.0"><sensor type="perspective"><float name="fov" value="30"/>
    <film type="hdrfilm"><rfilter type="gaussian"><float name="stddev" value="0.5"/></rfilter></film></sensor>
    <shape type="rectangle"/></scene>)";
  doc = read_mitsuba_scene(write("g.xml", gaussian));
  ASSERT_EQ(doc["warnings"].size(), 1u);
  EXPECT_NE(doc["warnings"][0].get<std::string>().find("g.xml:2: gaussian: the reconstruction filter"), std::string::npos)
      << doc["warnings"][0];
}

TEST_F(MitsubaScene, BsdfsMapOntoWavetracesModelsAsDocumented) {
  json m = material(R"(<bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.4, 0.6"/></bsdf>)");
  EXPECT_EQ(m["type"], "lambertian");
  EXPECT_EQ(m["albedo"], json::array({0.2, 0.4, 0.6}));
  EXPECT_EQ(material("")["albedo"], json::array({0.5, 0.5, 0.5}));  // no bsdf: Mitsuba's diffuse 0.5

  // twosided is the BSDF it wraps (wavetrace's surfaces reflect on both sides).
  m = material(R"(<bsdf type="twosided"><bsdf type="conductor"><string name="material" value="Au"/></bsdf></bsdf>)");
  EXPECT_EQ(m["type"], "conductor");
  EXPECT_EQ(m["metal"], "gold");
  EXPECT_EQ(m["roughness"], 0);
  EXPECT_EQ(m["masking"], "separable");  // Mitsuba's Smith term
  EXPECT_EQ(m["energy_compensation"], false);
  EXPECT_EQ(material(R"(<bsdf type="conductor"/>)")["f0"], json::array({1.0, 1.0, 1.0}));  // "none": a perfect mirror

  m = material(R"(<bsdf type="roughconductor"><rgb name="eta" value="0.2, 0.3, 0.4"/><rgb name="k" value="3, 2, 1"/>
    <float name="alpha" value="0.09"/><string name="distribution" value="ggx"/></bsdf>)");
  EXPECT_EQ(m["eta"], json::array({0.2, 0.3, 0.4}));
  EXPECT_EQ(m["k"], json::array({3.0, 2.0, 1.0}));
  EXPECT_NEAR(num(m["roughness"]), 0.3, 1e-12);  // alpha = roughness^2

  // Anisotropic alphas: their geometric mean, and the stretch a along the tangent
  // with alpha_u / alpha_v = 1 / (1 - 0.9 a).
  m = material(R"(<bsdf type="roughconductor"><float name="alpha_u" value="0.4"/><float name="alpha_v" value="0.1"/>
    <string name="distribution" value="ggx"/></bsdf>)");
  EXPECT_NEAR(num(m["roughness"]), std::sqrt(0.2), 1e-12);
  EXPECT_NEAR(num(m["anisotropy"]), 0.75 / 0.9, 1e-12);

  m = material(R"(<bsdf type="dielectric"><string name="int_ior" value="water"/><float name="ext_ior" value="1.0"/></bsdf>)");
  EXPECT_EQ(m["type"], "glass");
  EXPECT_DOUBLE_EQ(num(m["ior"]), 1.333);
  EXPECT_EQ(m["roughness"], 0);
  m = material(R"(<bsdf type="roughdielectric"><float name="alpha" value="0.25"/><string name="distribution" value="ggx"/>
    <rgb name="specular_transmittance" value="0.9, 0.8, 0.7"/></bsdf>)");
  EXPECT_DOUBLE_EQ(num(m["ior"]), 1.5046 / 1.000277);  // bk7 in air, Mitsuba's defaults
  EXPECT_DOUBLE_EQ(num(m["roughness"]), 0.5);
  EXPECT_EQ(m["tint"], json::array({0.9, 0.8, 0.7}));
  EXPECT_EQ(material(R"(<bsdf type="thindielectric"/>)")["thin"], true);

  // Plastic with nonlinear: wavetrace's model as it is.
  m = material(R"(<bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.5"/><boolean name="nonlinear" value="true"/>
    <float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/><float name="alpha" value="0.16"/>
    <string name="distribution" value="ggx"/></bsdf>)");
  EXPECT_EQ(m["type"], "plastic");
  EXPECT_EQ(m["albedo"], json::array({0.5, 0.5, 0.5}));
  EXPECT_DOUBLE_EQ(num(m["roughness"]), 0.4);
  EXPECT_DOUBLE_EQ(num(m["ior"]), 1.5);
  // Without nonlinear (Mitsuba's default) the base is a / (1 - R_int); wavetrace's
  // a' / (1 - a' R_int) equals it for a' = a / (1 - R_int + a R_int).
  m = material(R"(<bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.5"/><float name="int_ior" value="1.5"/>
    <float name="ext_ior" value="1"/></bsdf>)");
  const double a = num(m["albedo"][0]);
  const double r_int = plastic_internal_reflectance(1.5f, Ggx{0.0f, 0.0f, true});
  EXPECT_NEAR(a, 0.5 / (1 - r_int + 0.5 * r_int), 1e-6);
  EXPECT_NEAR(a / (1 - a * r_int), 0.5 / (1 - r_int), 1e-6);  // the reflectance Mitsuba's linear model gives
  EXPECT_GT(a, 0.5);  // wavetrace's model sums the coat's inner bounces in proportion to the albedo

  const json doc = mapped(R"(<shape type="rectangle"><bsdf type="phong"><float name="exponent" value="98"/></bsdf></shape>)");
  EXPECT_EQ(doc["materials"][0]["type"], "plastic");
  EXPECT_NEAR(num(doc["materials"][0]["roughness"]), std::sqrt(std::sqrt(2.0 / 100)), 1e-12);
  ASSERT_EQ(doc["warnings"].size(), 1u);
  EXPECT_NE(doc["warnings"][0].get<std::string>().find("phong: phong is rendered as the nearest roughplastic"), std::string::npos);

  const json beckmann = mapped(R"(<shape type="rectangle"><bsdf type="roughconductor"/></shape>)");
  ASSERT_EQ(beckmann["warnings"].size(), 1u);
  EXPECT_NE(beckmann["warnings"][0].get<std::string>().find("Beckmann distribution is rendered as GGX"), std::string::npos);
  EXPECT_NEAR(num(beckmann["materials"][0]["roughness"]), std::sqrt(0.1), 1e-12);  // Mitsuba's default alpha
}

TEST_F(MitsubaScene, EveryNamedConductorOfMitsubaMaps) {
  // Outside the six that map onto wavetrace's presets: the RGB eta and k Mitsuba's
  // RGB variants load (scene/mitsuba_metals.hpp, tools/mitsuba_metals.py).
  for (const std::string name : {"Hg", "a-C", "Cu_palik"}) {
    const MitsubaMetal* row = nullptr;
    for (const MitsubaMetal& metal : kMitsubaMetals) {
      if (name == metal.name) row = &metal;
    }
    ASSERT_NE(row, nullptr) << name;
    const json m = material("<bsdf type=\"roughconductor\"><string name=\"material\" value=\"" + name +
                            "\"/><string name=\"distribution\" value=\"ggx\"/></bsdf>");
    EXPECT_EQ(m["type"], "conductor") << name;
    EXPECT_FALSE(m.contains("metal")) << name;
    const auto numbers = [](const vec3& v) { return json::array({double(v.x), double(v.y), double(v.z)}); };
    EXPECT_EQ(m["eta"], numbers(row->eta)) << name;
    EXPECT_EQ(m["k"], numbers(row->k)) << name;
  }
  // The six keep wavetrace's presets and are not in the table; every row is one a
  // JSON conductor takes (eta > 0, k >= 0).
  EXPECT_EQ(material(R"(<bsdf type="conductor"><string name="material" value="Ni_palik"/></bsdf>)")["metal"], "nickel");
  for (const MitsubaMetal& metal : kMitsubaMetals) {
    for (const std::string own : {"Au", "Ag", "Cu", "Al", "Cr", "Ni_palik"}) EXPECT_NE(own, metal.name);
    for (int c = 0; c < 3; ++c) {
      EXPECT_GT(metal.eta[c], 0.0f) << metal.name;
      EXPECT_GE(metal.k[c], 0.0f) << metal.name;
    }
  }
  // A name Mitsuba does not know: one line naming the file, the line and the six.
  const std::string message = refusal(
      "\n<shape type=\"rectangle\"><bsdf type=\"conductor\"><string name=\"material\" value=\"Unobtainium\"/></bsdf></shape>");
  EXPECT_NE(message.find("s.xml:8: conductor: material 'Unobtainium' is not one of Mitsuba's named conductors "
                         "(Ag, Al, Au, Cr, Cu, Ni_palik, "),
            std::string::npos)
      << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST_F(MitsubaScene, PrincipledMapsDisneysParametersWhereTheyMeanTheSame) {
  json m = material(R"(<bsdf type="principled"><rgb name="base_color" value="0.8, 0.2, 0.1"/><float name="metallic" value="0.3"/>
    <float name="roughness" value="0.6"/><float name="anisotropic" value="0.5"/><float name="spec_trans" value="0.4"/>
    <float name="eta" value="1.33"/></bsdf>)");
  EXPECT_EQ(m["type"], "principled");
  EXPECT_EQ(m["albedo"], json::array({0.8, 0.2, 0.1}));
  EXPECT_DOUBLE_EQ(num(m["metallic"]), 0.3);
  EXPECT_DOUBLE_EQ(num(m["roughness"]), 0.6);
  EXPECT_DOUBLE_EQ(num(m["anisotropy"]), 0.5);
  EXPECT_DOUBLE_EQ(num(m["transmission"]), 0.4);
  EXPECT_EQ(m["thin"], false);
  EXPECT_DOUBLE_EQ(num(m["ior"]), 1.33);
  // Without eta, Disney's specular 0.5 is the index 1.5 (f0 = 0.08 x 0.5).
  EXPECT_NEAR(num(material(R"(<bsdf type="principled"/>)")["ior"]), 1.5, 1e-12);
  EXPECT_NE(refusal(R"(<shape type="rectangle"><bsdf type="principled"><float name="sheen" value="0.5"/></bsdf></shape>)")
                .find("principled: 'sheen' other than 0 is not supported"),
            std::string::npos);
}

TEST_F(MitsubaScene, TexturesMaskNormalAndBumpMapsMap) {
  write("t.png", "");  // existence is the converter's check; the reader reads it
  json doc = mapped(R"(<shape type="rectangle"><bsdf type="diffuse"><texture type="bitmap" name="reflectance">
      <string name="filename" value="t.png"/><string name="wrap_mode" value="mirror"/>
      <transform name="to_uv"><scale x="2" y="3"/><translate x="0.5" y="0.25"/></transform></texture></bsdf></shape>)");
  json t = doc["textures"][0];
  EXPECT_EQ(t["type"], "image");
  EXPECT_EQ(t["file"], "t.png");
  EXPECT_EQ(t["colorspace"], "srgb");
  EXPECT_EQ(t["filter"], "bilinear");  // Mitsuba's bitmap: no mip-maps
  EXPECT_EQ(t["wrap"], "mirror");
  EXPECT_EQ(t["uv_scale"], json::array({2.0, 3.0}));
  EXPECT_EQ(t["uv_offset"], json::array({0.5, 0.25}));
  EXPECT_DOUBLE_EQ(num(t["uv_rotation"]), 0.0);
  EXPECT_EQ(doc["materials"][0]["texture"], t["name"]);
  EXPECT_EQ(doc["materials"][0]["albedo"], json::array({1.0, 1.0, 1.0}));

  // A quarter turn: wavetrace's (u, v) -> (u cos r + v sin r, v cos r - u sin r).
  doc = mapped(R"(<shape type="rectangle"><bsdf type="diffuse"><texture type="checkerboard" name="reflectance">
      <rgb name="color0" value="0.9"/><rgb name="color1" value="0.1"/>
      <transform name="to_uv"><rotate z="1" angle="-90"/></transform></texture></bsdf></shape>)");
  t = doc["textures"][0];
  EXPECT_EQ(t["type"], "uv_checker");
  EXPECT_EQ(t["even"], json::array({0.9, 0.9, 0.9}));
  EXPECT_NEAR(num(t["uv_rotation"]), M_PI / 2, 1e-12);
  EXPECT_NEAR(num(t["uv_scale"][0]), 1, 1e-12);
  EXPECT_NEAR(num(t["uv_scale"][1]), 1, 1e-12);

  doc = mapped(R"(<shape type="rectangle"><bsdf type="mask"><float name="opacity" value="0.3"/>
      <bsdf type="bumpmap"><texture type="bitmap"><string name="filename" value="t.png"/><boolean name="raw" value="true"/></texture>
      <float name="scale" value="0.01"/><bsdf type="diffuse"/></bsdf></bsdf></shape>)");
  EXPECT_EQ(doc["meshes"][0]["alpha"], json({{"mode", "blend"}, {"opacity", 0.3}}));
  EXPECT_EQ(doc["materials"][0]["bump_scale"], 0.01);
  EXPECT_EQ(doc["textures"][0]["colorspace"], "linear");
  EXPECT_EQ(doc["materials"][0]["bump_texture"], doc["textures"][0]["name"]);

  doc = mapped(R"(<shape type="rectangle"><bsdf type="normalmap"><texture type="bitmap" name="normalmap">
      <string name="filename" value="t.png"/><boolean name="raw" value="true"/></texture>
      <bsdf type="roughplastic"><string name="distribution" value="ggx"/></bsdf></bsdf></shape>)");
  EXPECT_EQ(doc["materials"][0]["normal_texture"], doc["textures"][0]["name"]);
  EXPECT_NE(refusal(R"(<shape type="rectangle"><bsdf type="normalmap"><texture type="bitmap" name="normalmap">
      <string name="filename" value="t.png"/></texture><bsdf type="diffuse"/></bsdf></shape>)")
                .find("bitmap: a normal map holds vectors or heights: read its bitmap raw"),
            std::string::npos);
  doc = mapped(R"(<shape type="rectangle"><bsdf type="mask"><texture type="bitmap" name="opacity">
      <string name="filename" value="t.png"/></texture><bsdf type="diffuse"/></bsdf></shape>)");
  EXPECT_EQ(doc["meshes"][0]["alpha"]["channel"], "luminance");
}

// blendbsdf: wavetrace's blend of its two BSDFs in order (the first at weight 0),
// its weight a number or a texture (read by its luminance, as Mitsuba reads one).
TEST_F(MitsubaScene, ABlendbsdfIsABlendOfItsTwoBsdfs) {
  json doc = mapped(R"(<bsdf type="diffuse" id="grey"/><shape type="rectangle"><bsdf type="blendbsdf">
      <float name="weight" value="0.3"/><ref id="grey"/><bsdf type="roughconductor"><string name="material" value="Au"/>
      </bsdf></bsdf></shape>)");
  ASSERT_EQ(doc["materials"].size(), 3u);
  const json& blend = doc["materials"][2];
  EXPECT_EQ(blend["type"], "blend");
  EXPECT_EQ(blend["weight"], 0.3);
  EXPECT_EQ(blend["materials"], json::array({doc["materials"][0]["name"], doc["materials"][1]["name"]}));
  EXPECT_EQ(doc["materials"][0]["type"], "lambertian");
  EXPECT_EQ(doc["materials"][1]["type"], "conductor");
  EXPECT_EQ(doc["meshes"][0]["material"], blend["name"]);

  doc = mapped(R"(<shape type="rectangle"><bsdf type="blendbsdf"><texture type="checkerboard" name="weight"/>
      <bsdf type="diffuse"/><bsdf type="dielectric"/></bsdf></shape>)");
  EXPECT_EQ(doc["materials"][2]["weight"], 1);
  EXPECT_EQ(doc["materials"][2]["weight_texture"], doc["textures"][0]["name"]);
  EXPECT_EQ(doc["textures"][0]["type"], "uv_checker");

  // A mask around a blend masks the mesh; within one it is refused, as a normal map
  // around one is (it would be its materials').
  doc = mapped(R"(<shape type="rectangle"><bsdf type="mask"><float name="opacity" value="0.5"/><bsdf type="blendbsdf">
      <bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf></bsdf></shape>)");
  EXPECT_EQ(doc["meshes"][0]["alpha"]["opacity"], 0.5);
  EXPECT_NE(refusal(R"(<shape type="rectangle"><bsdf type="blendbsdf"><bsdf type="mask"><bsdf type="diffuse"/></bsdf>
      <bsdf type="diffuse"/></bsdf></shape>)").find("mask: a mask within a blendbsdf is not supported"), std::string::npos);
  write("t.png", "");
  EXPECT_NE(refusal(R"(<shape type="rectangle"><bsdf type="normalmap"><texture type="bitmap" name="normalmap">
      <string name="filename" value="t.png"/><boolean name="raw" value="true"/></texture><bsdf type="blendbsdf">
      <bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf></bsdf></shape>)").find("normalmap: a normalmap around a blendbsdf"),
            std::string::npos);
  EXPECT_NE(refusal(R"(<shape type="rectangle"><bsdf type="blendbsdf"><bsdf type="diffuse"/><bsdf type="diffuse"/>
      <bsdf type="diffuse"/></bsdf></shape>)").find("blendbsdf: takes two nested BSDFs, not more"), std::string::npos);
  EXPECT_NE(refusal(R"(<shape type="rectangle"><bsdf type="blendbsdf"><float name="weight" value="2"/><bsdf type="diffuse"/>
      <bsdf type="diffuse"/></bsdf></shape>)").find("blendbsdf: weight must be in [0, 1]"), std::string::npos);
}

TEST_F(MitsubaScene, ShapesBecomeMeshesPlacedByInstancesAndSpheresStayAnalytic) {
  write("m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const json doc = mapped(R"(
    <bsdf type="diffuse" id="grey"/>
    <shape type="obj"><string name="filename" value="m.obj"/><boolean name="face_normals" value="true"/>
      <transform name="to_world"><translate x="2"/></transform><ref id="grey"/></shape>
    <shape type="obj"><string name="filename" value="m.obj"/><boolean name="face_normals" value="true"/><ref id="grey"/></shape>
    <shape type="cylinder"><point name="p0" x="0" y="0" z="0"/><point name="p1" x="0" y="2" z="0"/><float name="radius" value="0.5"/>
      <boolean name="flip_normals" value="true"/></shape>
    <shape type="sphere"><point name="center" x="1" y="0" z="0"/><float name="radius" value="2"/>
      <transform name="to_world"><scale value="3"/><translate z="1"/></transform>
      <emitter type="area"><rgb name="radiance" value="5, 4, 3"/></emitter></shape>
    <shape type="shapegroup" id="g"><shape type="disk"><transform name="to_world"><translate y="1"/></transform></shape></shape>
    <shape type="instance"><ref id="g"/><transform name="to_world"><translate x="5"/></transform></shape>
    <shape type="instance"><ref id="g"/><transform name="to_world"><scale value="2"/></transform></shape>)");
  // A BSDF referenced under a name of its own is the one BSDF.
  const json named = mapped(R"(<bsdf type="diffuse" id="grey"/>
    <shape type="rectangle"><ref id="grey" name="bsdf"/></shape><shape type="cube"><ref id="grey"/></shape>)");
  EXPECT_EQ(named["materials"].size(), 1u);
  // One mesh entry per file and set of options: the two OBJ shapes share one.
  ASSERT_EQ(doc["meshes"].size(), 3u);
  EXPECT_EQ(doc["meshes"][0]["file"], "m.obj");
  EXPECT_EQ(doc["meshes"][0]["face_normals"], true);
  EXPECT_EQ(doc["meshes"][1]["shape"], "cylinder");
  EXPECT_EQ(doc["meshes"][1]["flip_normals"], true);
  EXPECT_EQ(doc["meshes"][2]["shape"], "disk");
  ASSERT_EQ(doc["instances"].size(), 5u);
  EXPECT_EQ(doc["instances"][0]["matrix"], json::array({1, 0, 0, 2, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}));
  EXPECT_FALSE(doc["instances"][1].contains("matrix"));  // in place
  // The cylinder from p0 to p1 of radius 0.5: the unit one, z along p1 - p0.
  const json& c = doc["instances"][2]["matrix"];
  EXPECT_NEAR(num(c[1 * 4 + 2]), 2, 1e-12);  // z -> +2 y
  EXPECT_NEAR(std::hypot(num(c[0]), std::hypot(num(c[4]), num(c[8]))), 0.5, 1e-12);
  // An instance places the group's shape by its own transform times the shape's.
  EXPECT_EQ(doc["instances"][3]["matrix"], json::array({1, 0, 0, 5, 0, 1, 0, 1, 0, 0, 1, 0, 0, 0, 0, 1}));
  EXPECT_EQ(doc["instances"][4]["matrix"], json::array({2, 0, 0, 0, 0, 2, 0, 2, 0, 0, 2, 0, 0, 0, 0, 1}));
  // The sphere placed: centre 3 (1, 0, 0) + (0, 0, 1), radius 6; its area light an emitter.
  ASSERT_EQ(doc["spheres"].size(), 1u);
  EXPECT_EQ(doc["spheres"][0]["center"], json::array({3.0, 0.0, 1.0}));
  EXPECT_EQ(doc["spheres"][0]["radius"], 6.0);
  const std::string lamp = doc["spheres"][0]["material"];
  bool found = false;
  for (const json& m : doc["materials"]) {
    if (m["name"] != lamp) continue;
    found = true;
    EXPECT_EQ(m["type"], "emissive");
    EXPECT_EQ(m["emission"], json::array({5.0, 4.0, 3.0}));
  }
  EXPECT_TRUE(found);
  EXPECT_NE(refusal(R"(<shape type="sphere"><transform name="to_world"><scale x="2"/></transform></shape>)")
                .find("sphere: to_world must scale a sphere alike in every direction"),
            std::string::npos);
}

TEST_F(MitsubaScene, EmittersBecomeTheSkyOrLights) {
  write("sky.hdr", "");
  json doc = mapped(R"(<emitter type="envmap"><string name="filename" value="sky.hdr"/><float name="scale" value="2"/>
      <transform name="to_world"><rotate y="1" angle="30"/></transform></emitter><shape type="rectangle"/>)");
  EXPECT_EQ(doc["sky"]["type"], "environment");
  EXPECT_EQ(doc["sky"]["file"], "sky.hdr");
  EXPECT_EQ(doc["sky"]["intensity"], 2.0);
  EXPECT_NEAR(num(doc["sky"]["rotation"]), 30, 1e-9);
  EXPECT_NE(refusal(R"(<emitter type="envmap"><string name="filename" value="sky.hdr"/>
      <transform name="to_world"><rotate x="1" angle="30"/></transform></emitter><shape type="rectangle"/>)")
                .find("envmap: to_world other than a rotation about +y is not supported"),
            std::string::npos);
  doc = mapped(R"(<emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
    <emitter type="point"><point name="position" x="1" y="2" z="3"/><rgb name="intensity" value="10"/></emitter>
    <emitter type="spot"><transform name="to_world"><lookat origin="0, 5, 0" target="0, 0, 0" up="0, 0, 1"/></transform>
      <rgb name="intensity" value="7"/><float name="cutoff_angle" value="30"/></emitter>
    <emitter type="directional"><vector name="direction" x="0" y="-2" z="0"/><rgb name="irradiance" value="3"/></emitter>
    <shape type="rectangle"/>)");
  EXPECT_EQ(doc["sky"], json({{"type", "uniform"}, {"radiance", {0.5, 0.5, 0.5}}}));
  ASSERT_EQ(doc["lights"].size(), 3u);
  EXPECT_EQ(doc["lights"][0], json({{"type", "point"}, {"position", {1.0, 2.0, 3.0}}, {"intensity", {10.0, 10.0, 10.0}}}));
  EXPECT_EQ(doc["lights"][1]["position"], json::array({0.0, 5.0, 0.0}));
  EXPECT_NEAR(num(doc["lights"][1]["direction"][1]), -1, 1e-12);
  EXPECT_DOUBLE_EQ(num(doc["lights"][1]["outer_angle"]), 30);
  EXPECT_DOUBLE_EQ(num(doc["lights"][1]["inner_angle"]), 22.5);  // Mitsuba's beam_width: 3/4 of the cutoff
  EXPECT_EQ(doc["lights"][2]["direction"], json::array({0.0, -1.0, 0.0}));
  EXPECT_EQ(doc["lights"][2]["irradiance"], json::array({3.0, 3.0, 3.0}));
  EXPECT_NE(refusal(R"(<emitter type="sunsky"/><shape type="rectangle"/>)").find("sunsky: not supported"), std::string::npos);
}

TEST_F(MitsubaScene, WhatIsNotSupportedIsOneLineNamingTheFileAndTheLine) {
  const struct {
    const char* body;
    const char* message;
  } cases[] = {
      {"\n<shape type=\"rectangle\"><bsdf type=\"roughplastic\"><float name=\"foo\" value=\"1\"/></bsdf></shape>",
       "s.xml:8: roughplastic: parameter 'foo' is not supported"},
      {"\n<shape type=\"teapot\"/>", "s.xml:8: teapot: shape type 'teapot' is not supported"},
      {"\n<shape type=\"obj\"><string name=\"filename\" value=\"missing.obj\"/></shape>",
       "s.xml:8: obj: file 'missing.obj' does not exist"},
      {"\n<shape type=\"rectangle\"><bsdf type=\"blendbsdf\"/></shape>", "s.xml:8: blendbsdf: needs two nested BSDFs"},
      {"\n<shape type=\"rectangle\"><bsdf type=\"conductor\"><string name=\"material\" value=\"Unobtainium\"/></bsdf></shape>",
       "s.xml:8: conductor: material 'Unobtainium' is not one of Mitsuba's named conductors"},
      {"\n<shape type=\"rectangle\"><bsdf type=\"roughconductor\"><float name=\"alpha_u\" value=\"0.1\"/>"
       "<float name=\"alpha_v\" value=\"0.3\"/></bsdf></shape>",
       "s.xml:8: roughconductor: alpha_v > alpha_u"},
      {"\n<shape type=\"rectangle\"><medium type=\"homogeneous\"/></shape>", "s.xml:8: rectangle: a nested <medium"},
      {"\n<integrator type=\"volpath\"/><shape type=\"rectangle\"/>", "s.xml:8: volpath: integrator type 'volpath' is not supported"},
  };
  for (const auto& c : cases) {
    const std::string message = refusal(c.body);
    EXPECT_NE(message.find(c.message), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  const std::string old_format = write("o.xml", "<scene version=\"0.6.0\"><shape type=\"rectangle\"/></scene>");
  try {
    read_mitsuba_scene(old_format);
    ADD_FAILURE() << "a Mitsuba 0.6 scene was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("o.xml:1: scene: version 0.6.0: a Mitsuba 0.x scene"), std::string::npos)
        << e.what();
  }
  const std::string no_sensor = write("n.xml", "<scene version=\"3.0.0\"><shape type=\"rectangle\"/></scene>");
  EXPECT_THROW(read_mitsuba_scene(no_sensor), InputError);
}

TEST_F(MitsubaScene, BuiltInShapesAreMitsubasInTheirOwnSpace) {
  auto area = [](const TriangleMesh& m) {
    double a = 0;
    for (const auto& t : m.triangles) {
      a += 0.5 * glm::length(glm::cross(m.positions[t[1]] - m.positions[t[0]], m.positions[t[2]] - m.positions[t[0]]));
    }
    return a;
  };
  // Every triangle faces where its normals point (counter-clockwise seen from there).
  auto faces_its_normals = [](const TriangleMesh& m) {
    for (const auto& t : m.triangles) {
      const vec3 g = glm::cross(m.positions[t[1]] - m.positions[t[0]], m.positions[t[2]] - m.positions[t[0]]);
      if (!(glm::dot(g, m.normals[t[0]]) > 0)) return false;
    }
    return true;
  };
  const TriangleMesh rect = shape_mesh("rectangle");
  EXPECT_DOUBLE_EQ(area(rect), 4);
  EXPECT_TRUE(faces_its_normals(rect));
  for (size_t v = 0; v < rect.positions.size(); ++v) {
    EXPECT_EQ(rect.normals[v], vec3(0, 0, 1));
    EXPECT_EQ(rect.uvs[v], vec2((rect.positions[v].x + 1) / 2, (rect.positions[v].y + 1) / 2));
  }
  const TriangleMesh cube = shape_mesh("cube");
  EXPECT_EQ(cube.triangles.size(), 12u);
  EXPECT_DOUBLE_EQ(area(cube), 24);
  EXPECT_TRUE(faces_its_normals(cube));
  for (size_t v = 0; v < cube.positions.size(); ++v) EXPECT_GT(glm::dot(cube.positions[v], cube.normals[v]), 0.99f);
  const double polygon = kDiskSegments / 2.0 * std::sin(2 * M_PI / kDiskSegments);  // the inscribed polygon's area
  EXPECT_NEAR(area(shape_mesh("disk")), polygon, 1e-5);
  EXPECT_NEAR(polygon, M_PI, 1e-4 * M_PI);
  EXPECT_TRUE(faces_its_normals(shape_mesh("disk")));
  const TriangleMesh cyl = shape_mesh("cylinder");
  EXPECT_NEAR(area(cyl), 2 * kCylinderSegments * std::sin(M_PI / kCylinderSegments), 1e-5);  // perimeter x 1
  EXPECT_TRUE(faces_its_normals(cyl));
  for (size_t v = 0; v < cyl.positions.size(); ++v) {
    EXPECT_NEAR(glm::length(vec2(cyl.positions[v])), 1, 1e-6);
    EXPECT_GT(glm::dot(vec2(cyl.positions[v]), vec2(cyl.normals[v])), 0.99f);
  }
}

// A scene read from XML is the scene its JSON form describes: the same image, bit
// for bit, and `convert` writes that JSON where the files it names still resolve.
TEST_F(MitsubaScene, AnXmlSceneRendersBitIdenticallyToItsConvertedJson) {
  std::filesystem::create_directories(folder_.root() / "scene");
  write("scene/m.obj", "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n");
  const std::string xml = scene(R"(
    <default name="red" value="0.8"/>
    <bsdf type="diffuse" id="red"><rgb name="reflectance" value="$red, 0.1, 0.1"/></bsdf>
    <shape type="rectangle"><transform name="to_world"><scale value="3"/></transform>
      <bsdf type="diffuse"><texture type="checkerboard" name="reflectance"><transform name="to_uv"><scale value="4"/></transform></texture></bsdf></shape>
    <shape type="obj"><string name="filename" value="m.obj"/><transform name="to_world"><translate x="-0.8" z="0.5"/><scale value="0.5"/></transform>
      <bsdf type="roughplastic"><string name="distribution" value="ggx"/></bsdf></shape>
    <shape type="cube"><transform name="to_world"><scale value="0.3"/><translate x="0.6" z="0.3"/></transform><ref id="red"/></shape>
    <shape type="disk"><transform name="to_world"><translate z="3"/><scale value="0.5"/></transform>
      <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>
    <emitter type="point"><point name="position" x="0" y="1" z="2"/><rgb name="intensity" value="3"/></emitter>
    <integrator type="path"><integer name="max_depth" value="5"/></integrator>)", "scene/s.xml");
  const std::string xml_path = xml;
  std::filesystem::create_directories(folder_.root() / "out");
  const std::string json_path = (folder_.root() / "out/s.json").string();
  ASSERT_EQ(app::run_convert(xml_path, json_path, {{"red", "0.6"}}), 0);
  const Scene from_xml = load_scene(xml_path, {{"red", "0.6"}});
  const Scene from_json = load_scene(json_path);
  for (const Backend b : {Backend::Cpu}) {
    const RenderOptions o = test::options_for(b, Kernel::Megakernel, 40, 30, 4, 5, 5, 7);
    const RenderResult a = render(from_xml, o), c = render(from_json, o);
    ASSERT_EQ(a.rgb.size(), c.rgb.size());
    EXPECT_EQ(a.rgb, c.rgb);
    EXPECT_GT(test::mean(a.rgb), 0.01);
  }
  // The JSON names the mesh file from its own folder.
  std::ifstream in(json_path);
  const json doc = json::parse(in);
  EXPECT_EQ(doc["meshes"][1]["file"], "../scene/m.obj");
  // A bad scene writes nothing.
  const std::string bad = (folder_.root() / "out/bad.json").string();
  EXPECT_EQ(app::run_convert(write("bad.xml", "<scene><shape type=\"teapot\"/></scene>"), bad, {}), app::kExitBadInput);
  EXPECT_FALSE(std::filesystem::exists(bad));
}

TEST_F(MitsubaScene, ParametersComeFromTheCallerAndAJsonSceneTakesNone) {
  const std::string xml = scene(R"(<default name="r" value="0.25"/>
    <shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="$r"/></bsdf></shape>)");
  EXPECT_FLOAT_EQ(load_scene(xml, {}).materials[0].albedo.x, 0.25f);
  EXPECT_FLOAT_EQ(load_scene(xml, {{"r", "0.5"}}).materials[0].albedo.x, 0.5f);
  try {
    load_scene(test::repo_path("scenes/quick.json"), {{"r", "1"}});
    FAIL() << "parameters for a JSON scene were taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("apply to a Mitsuba scene (.xml) only"), std::string::npos) << e.what();
  }
}

// The JSON that the mapping writes, read: a point light of the `lights` section
// over a white Lambertian floor gives the radiance albedo / pi x I / h^2 below it.
TEST_F(MitsubaScene, APointLightOfTheLightsSectionLightsAFloorAsTheInverseSquareSays) {
  const std::string xml = write("p.xml", R"(<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="1"/>
    <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/><rfilter type="box"/></film></sensor>
  <integrator type="path"><integer name="max_depth" value="2"/></integrator>
  <emitter type="point"><point name="position" x="0" y="0" z="2"/><rgb name="intensity" value="8"/></emitter>
  <shape type="rectangle"><transform name="to_world"><scale value="10"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
</scene>)");
  const Scene s = load_scene(xml, {});
  const RenderResult r = render(s, test::options_for(Backend::Cpu, Kernel::Megakernel, 4, 4, 16, 2, 5, 1));
  const double expected = 0.5 / M_PI * 8 / 4;  // h = 2; the 1-degree view sees cos 1 within 1e-5
  ASSERT_EQ(r.radiance, Radiance::MeanOfSamples);
  for (float v : r.rgb) EXPECT_NEAR(v, expected, 1e-3 * expected);
}

TEST_F(MitsubaScene, TheUvCheckerIsTwoSquaresToTheUnitInUvSpace) {
  const std::string path = write("c.json", R"({"camera": {"look_from": [0, 0, 5], "look_at": [0, 0, 0]},
    "textures": [{"name": "c", "type": "uv_checker", "even": [0.9, 0.8, 0.7], "odd": [0.1, 0.2, 0.3], "uv_scale": [2, 2]}],
    "materials": [{"name": "m", "type": "lambertian", "texture": "c"}],
    "meshes": [{"name": "r", "shape": "rectangle", "material": "m"}], "instances": [{"mesh": "r"}]})");
  const Scene s = load_scene(path);
  ASSERT_EQ(s.textures.size(), 1u);
  const Texture& t = s.textures[0];
  std::vector<ImageView> views;
  const SceneView view = host_view(s, 4, 4, views);
  auto at = [&](float u, float v) {
    SurfacePoint sp{};
    sp.has_uv = true;
    sp.uv = vec2(u, v);
    return eval_texture<false>(t, view.images, sp);
  };
  // uv x 2: the squares are a quarter of the unit wide; even where both halves agree.
  EXPECT_EQ(at(0.1f, 0.1f), vec3(0.9f, 0.8f, 0.7f));
  EXPECT_EQ(at(0.35f, 0.1f), vec3(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(at(0.1f, 0.35f), vec3(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(at(0.35f, 0.35f), vec3(0.9f, 0.8f, 0.7f));
  EXPECT_EQ(at(0.6f, 0.1f), vec3(0.9f, 0.8f, 0.7f));  // repeated
}

TEST_F(MitsubaScene, AMeshAlphaMakesItsSceneMaterialAlphaTested) {
  const std::string path = write("a.json", R"({"camera": {"look_from": [0, 0, 5], "look_at": [0, 0, 0]},
    "materials": [{"name": "m", "type": "lambertian"}],
    "meshes": [{"name": "r", "shape": "rectangle", "material": "m", "alpha": {"mode": "blend", "opacity": 0.3}}],
    "instances": [{"mesh": "r"}]})");
  const Scene s = load_scene(path);
  ASSERT_EQ(s.alpha_tests.size(), 1u);
  EXPECT_EQ(s.alpha_tests[0].mode, AlphaMode::Blend);
  EXPECT_FLOAT_EQ(s.alpha_tests[0].factor, 0.3f);
  for (const TriangleGeom& g : s.triangles) EXPECT_EQ(g.alpha, 1u);
  // A black sheet before a sky of 1: the camera sees the sky through it 0.7 of the time.
  const std::string seen = write("c.json", R"({"camera": {"look_from": [0, 0, 5], "look_at": [0, 0, 0], "vfov": 5},
    "sky": {"type": "uniform", "radiance": [1, 1, 1]},
    "materials": [{"name": "m", "type": "lambertian", "albedo": [0, 0, 0]}],
    "meshes": [{"name": "r", "shape": "rectangle", "material": "m", "alpha": {"mode": "blend", "opacity": 0.3}}],
    "instances": [{"mesh": "r"}]})");
  const RenderResult r = render(load_scene(seen), test::options_for(Backend::Cpu, Kernel::Megakernel, 8, 8, 256, 2, 5, 3));
  // 16384 samples of a Bernoulli(0.7): standard error 0.0036.
  EXPECT_NEAR(test::mean(r.rgb), 0.7, 0.02);
  const std::string bad = write("b.json", R"({"camera": {"look_from": [0, 0, 5], "look_at": [0, 0, 0]},
    "materials": [{"name": "m", "type": "lambertian"}],
    "meshes": [{"name": "r", "shape": "rectangle", "alpha": {"mode": "blend"}}], "instances": [{"mesh": "r"}]})");
  EXPECT_THROW(load_scene(bad), InputError);
}

}  // namespace
}  // namespace wt::mitsuba

namespace wt::mitsuba {
namespace {

// The shipped Mitsuba scenes (scenes/mitsuba/, tools/make_mitsuba_scenes.py): each
// renders exactly as the JSON `convert` writes of it.
TEST(MitsubaShippedScenes, EachRendersExactlyAsItsConvertedJson) {
  test::TestFolder folder;
  int scenes = 0;
  for (const auto& e : std::filesystem::directory_iterator(test::repo_path("scenes/mitsuba"))) {
    if (e.path().extension() != ".xml") continue;
    ++scenes;
    const std::string xml = e.path().string();
    // Written elsewhere: the files it names are referenced from there.
    const std::string converted = (folder.root() / (e.path().stem().string() + ".json")).string();
    SCOPED_TRACE(xml);
    ASSERT_EQ(app::run_convert(xml, converted, {}), 0);
    const Scene a = load_scene(xml, {}), b = load_scene(converted);
    const RenderOptions o = test::options_for(Backend::Cpu, Kernel::Megakernel, 24, 16, 1, 6, 3, 5);
    EXPECT_EQ(render(a, o).rgb, render(b, o).rgb);
  }
  EXPECT_EQ(scenes, 4);
}

// The round trip: a scene of the project's, written as Mitsuba XML by the peer's
// converter and read back, renders what its JSON renders: 48 x 36 pixels at 64 spp
// of one seed, whose paths follow the same random numbers in both, so that what
// differs is the scenes (the meshes split by material, flat-shaded, the materials
// as Mitsuba's parameters and back): the image's mean within 1%, each quadrant's
// within 2% of the image's mean. (Independent seeds differ by up to 4.5% in the
// quadrants with the lamp's edge at this size.)
TEST(MitsubaShippedScenes, TheRoundTripScenesRenderAsTheirJsonSources) {
  for (const char* name : {"cornell-box", "cornell-materials-single", "bump-single"}) {
    SCOPED_TRACE(name);
    const Scene xml = load_scene(test::repo_path(std::string("scenes/mitsuba/") + name + ".xml"), {});
    const Scene source = load_scene(test::repo_path(std::string("scenes/") + name + ".json"));
    const int w = 48, h = 36;
    const RenderOptions o = test::options_for(Backend::Cpu, Kernel::Megakernel, w, h, 64, 8, 5, 11);
    const RenderResult a = render(xml, o), b = render(source, o);
    auto quadrant_means = [&](const std::vector<float>& rgb) {
      std::vector<double> q(5, 0.0);
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const size_t i = 3 * (static_cast<size_t>(y) * w + x);
          const double v = (rgb[i] + rgb[i + 1] + rgb[i + 2]) / 3.0;
          q[(y < h / 2 ? 0 : 2) + (x < w / 2 ? 0 : 1)] += v / (w * h / 4);
          q[4] += v / (w * h);
        }
      }
      return q;
    };
    const std::vector<double> qa = quadrant_means(a.rgb), qb = quadrant_means(b.rgb);
    EXPECT_NEAR(qa[4], qb[4], 0.01 * qb[4]);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(qa[k], qb[k], 0.02 * qb[4]) << "quadrant " << k;
  }
}

}  // namespace
}  // namespace wt::mitsuba

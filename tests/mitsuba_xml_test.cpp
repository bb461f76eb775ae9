// The first layer of Mitsuba 3 XML scenes (scene/mitsuba_xml.hpp): parameters and
// their defaults, includes and references, transforms and typed properties as
// Mitsuba's documentation gives them, and one line naming the file and the line for
// each thing wrong.
#include "scene/mitsuba_xml.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "errors/errors.hpp"
#include "test_support.hpp"

namespace wt::mitsuba {
namespace {

class MitsubaXml : public testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& text) const {
    const std::string path = (folder_.root() / name).string();
    std::ofstream(path) << text;
    return path;
  }

  // The message of reading `path` (with `defines`), or "no error".
  std::string refusal(const std::string& path, const std::map<std::string, std::string>& defines = {}) const {
    try {
      read_scene_xml(path, defines);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }

  test::TestFolder folder_;
};

template <class T>
T value_of(const Object& o, const std::string& name) {
  const Property* p = o.find(name);
  if (p == nullptr) throw std::runtime_error("no property " + name);
  return std::get<T>(p->value);
}

// A point through a matrix (row-major, points as columns).
Vec3 apply(const Matrix& m, Vec3 p) {
  return {m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
          m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
}

TEST_F(MitsubaXml, DefaultsGiveParametersTheirValuesUnlessTheCallerDoes) {
  const std::string path = write("s.xml", R"(<scene version="3.0.0">
  <default name="spp" value="64"/>
  <default name="albedo" value="0.25"/>
  <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
  <bsdf type="diffuse" id="grey"><rgb name="reflectance" value="$albedo, 0.5, $albedo"/></bsdf>
</scene>)");
  const auto scene = read_scene_xml(path);
  ASSERT_EQ(scene->children.size(), 2u);
  EXPECT_EQ(scene->children[0]->tag, "sampler");
  EXPECT_EQ(value_of<int64_t>(*scene->children[0], "sample_count"), 64);
  const Rgb rgb = value_of<Rgb>(*scene->children[1], "reflectance");
  EXPECT_EQ(rgb.r, 0.25);
  EXPECT_EQ(rgb.g, 0.5);
  EXPECT_EQ(rgb.b, 0.25);
  EXPECT_EQ(scene->children[1]->id, "grey");
  // -D comes first.
  const auto given = read_scene_xml(path, {{"spp", "1024"}});
  EXPECT_EQ(value_of<int64_t>(*given->children[0], "sample_count"), 1024);
  EXPECT_EQ(value_of<Rgb>(*given->children[1], "reflectance").r, 0.25);
}

TEST_F(MitsubaXml, IncludesAndReferencesPutObjectsWhereTheyStand) {
  write("materials.xml", R"(<scene version="3.0.0">
  <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.8"/></bsdf>
</scene>)");
  const std::string path = write("s.xml", R"(<scene version="3.0.0">
  <include filename="materials.xml"/>
  <shape type="sphere">
    <float name="radius" value="2"/>
    <ref id="white" name="bsdf"/>
  </shape>
</scene>)");
  const auto scene = read_scene_xml(path);
  ASSERT_EQ(scene->children.size(), 2u);
  const Object& shape = *scene->children[1];
  EXPECT_EQ(shape.type, "sphere");
  EXPECT_EQ(value_of<double>(shape, "radius"), 2.0);
  ASSERT_EQ(shape.children.size(), 1u);
  EXPECT_EQ(shape.children[0]->type, "diffuse");
  EXPECT_EQ(shape.children[0]->name, "bsdf");
  EXPECT_EQ(value_of<Rgb>(*shape.children[0], "reflectance").g, 0.8);
}

// Each operation multiplies the matrix from the left, in the order given.
TEST_F(MitsubaXml, TransformsComposeInTheOrderGiven) {
  const std::string path = write("s.xml", R"(<scene version="3.0.0">
  <shape type="cube">
    <transform name="to_world">
      <translate x="1"/>
      <scale value="2"/>
      <rotate z="1" angle="90"/>
    </transform>
  </shape>
  <sensor type="perspective">
    <transform name="to_world"><lookat origin="1, 2, 3" target="2, 2, 3" up="0, 1, 0"/></transform>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><matrix value="1 0 0 5  0 1 0 6  0 0 1 7  0 0 0 1"/></transform></shape>
</scene>)");
  const auto scene = read_scene_xml(path);
  // (0, 0, 0): translated to (1, 0, 0), scaled to (2, 0, 0), turned to (0, 2, 0).
  const Vec3 p = apply(value_of<Matrix>(*scene->children[0], "to_world"), {0, 0, 0});
  EXPECT_NEAR(p.x, 0.0, 1e-12);
  EXPECT_NEAR(p.y, 2.0, 1e-12);
  EXPECT_NEAR(p.z, 0.0, 1e-12);
  // The camera at (1, 2, 3) looking down +x: its z axis is +x, its y axis up, its x
  // axis up x z = -z (Mitsuba's camera looks down +z with +x to its left).
  const Matrix cam = value_of<Matrix>(*scene->children[1], "to_world");
  const Vec3 origin = apply(cam, {0, 0, 0}), ahead = apply(cam, {0, 0, 1}), left = apply(cam, {1, 0, 0});
  EXPECT_NEAR(origin.x, 1.0, 1e-12);
  EXPECT_NEAR(origin.y, 2.0, 1e-12);
  EXPECT_NEAR(origin.z, 3.0, 1e-12);
  EXPECT_NEAR(ahead.x, 2.0, 1e-12);
  EXPECT_NEAR(left.z, 2.0, 1e-12);
  const Vec3 q = apply(value_of<Matrix>(*scene->children[2], "to_world"), {1, 1, 1});
  EXPECT_EQ(q.x, 6.0);
  EXPECT_EQ(q.y, 7.0);
  EXPECT_EQ(q.z, 8.0);
}

TEST_F(MitsubaXml, PropertiesAreTyped) {
  const std::string path = write("s.xml", R"(<scene version="3.0.0">
  <emitter type="point">
    <point name="position" x="1" y="2" z="3"/>
    <spectrum name="intensity" value="5"/>
    <boolean name="flag" value="true"/>
    <string name="label" value="a lamp"/>
    <vector name="direction" value="0 -1 0"/>
  </emitter>
</scene>)");
  const auto scene = read_scene_xml(path);
  const Object& e = *scene->children[0];
  EXPECT_EQ(value_of<Vec3>(e, "position").z, 3.0);
  EXPECT_EQ(value_of<Rgb>(e, "intensity").g, 5.0);
  EXPECT_TRUE(value_of<bool>(e, "flag"));
  EXPECT_EQ(value_of<std::string>(e, "label"), "a lamp");
  EXPECT_EQ(value_of<Vec3>(e, "direction").y, -1.0);
  EXPECT_EQ(e.find("intensity")->kind, "spectrum");
  EXPECT_EQ(e.find("intensity")->line, 4);
}

// Wavelength:value pairs become linear sRGB (spectrum_to_rgb): a flat spectrum is its
// grey, and narrow bands are red, green and blue where the eye sees them so.
TEST_F(MitsubaXml, SpectraOfPairsBecomeTheirColour) {
  const std::string path = write("s.xml", R"(<scene version="3.0.0">
  <bsdf type="diffuse">
    <spectrum name="flat" value="360:0.5, 830:0.5"/>
    <spectrum name="red" value="600:0, 620:1, 640:0"/>
    <spectrum name="green" value="520:0, 540:1, 560:0"/>
    <spectrum name="blue" value="440:0, 455:1, 470:0"/>
  </bsdf>
</scene>)");
  const auto scene = read_scene_xml(path);
  const Object& b = *scene->children[0];
  const Rgb flat = value_of<Rgb>(b, "flat");
  EXPECT_NEAR(flat.r, 0.5, 1e-9);
  EXPECT_NEAR(flat.g, 0.5, 1e-9);
  EXPECT_NEAR(flat.b, 0.5, 1e-9);
  const Rgb red = value_of<Rgb>(b, "red"), green = value_of<Rgb>(b, "green"), blue = value_of<Rgb>(b, "blue");
  EXPECT_GT(red.r, 4 * std::max(red.g, red.b));
  EXPECT_GT(green.g, 2 * std::max(green.r, green.b));
  EXPECT_GT(blue.b, 4 * std::max(blue.r, blue.g));
  // Linear in the spectrum: twice the values, twice the colour.
  const Rgb twice = spectrum_to_rgb({{600, 0}, {620, 2}, {640, 0}});
  EXPECT_NEAR(twice.r, 2 * red.r, 1e-12);
}

// Each thing wrong is one line: the file, the line, the element and what is wrong.
TEST_F(MitsubaXml, EveryErrorNamesTheFileTheLineAndTheElement) {
  const std::string header = "<scene version=\"3.0.0\">\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {header + "  <bsdf type=\"diffuse\">\n    <rgb name=\"reflectance\" value=\"$albedo\"/>\n  </bsdf>\n</scene>",
       ":3: rgb: parameter '$albedo' has no value (no <default> or -D gives it one)"},
      {header + "  <shape type=\"sphere\"><ref id=\"nowhere\"/></shape>\n</scene>",
       ":2: ref: no object has the id 'nowhere' (an id is given before it is used)"},
      {header + "  <bsdf type=\"diffuse\" id=\"a\"/>\n  <bsdf type=\"diffuse\" id=\"a\"/>\n</scene>",
       ":3: bsdf: the id 'a' is given twice"},
      {header + "  <shape type=\"cube\"><transform name=\"to_world\"><shear value=\"1\"/></transform></shape>\n</scene>",
       ":2: transform: unknown operation <shear> (expected translate, rotate, scale, matrix or lookat)"},
      {header + "  <shape type=\"cube\"><transform name=\"to_world\"><matrix value=\"1 2 3\"/></transform></shape>\n</scene>",
       ":2: matrix: 'value' must hold 9 or 16 numbers (row by row)"},
      {header + "  <integer name=\"n\" value=\"2.5\"/>\n</scene>", ":2: integer: '2.5' is not an integer"},
      {header + "  <boolean name=\"b\" value=\"yes\"/>\n</scene>", ":2: boolean: 'yes' is neither true nor false"},
      {header + "  <float name=\"f\" value=\"abc\"/>\n</scene>", ":2: float: 'abc' is not a list of numbers"},
      {header + "  <spectrum name=\"s\" value=\"700:0.1, 400:0.5\"/>\n</scene>",
       ":2: spectrum: the wavelengths must rise ('700:0.1, 400:0.5')"},
      {header + "  <spectrum name=\"s\" value=\"400:0.1, 500\"/>\n</scene>",
       ":2: spectrum: '500' is not a wavelength:value pair"},
      {header + "  <spectrum name=\"s\" value=\"400:0.1\"/>\n</scene>",
       ":2: spectrum: a spectrum of wavelength:value pairs needs two at least"},
      {header + "  <widget name=\"w\"/>\n</scene>",
       ":2: widget: unknown element (expected a plugin object, a property, default, include or ref)"},
      {header + "  <bsdf type=\"diffuse\">\n</scene>", ":3: xml: malformed XML ("},
      {"<world/>\n", ":1: world: the document's root must be <scene>"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const std::string path = write("bad" + std::to_string(i) + ".xml", cases[i].first);
    const std::string why = refusal(path);
    SCOPED_TRACE(cases[i].first);
    EXPECT_EQ(why.rfind(path + cases[i].second, 0), 0u) << why;
    EXPECT_EQ(why.find('\n'), std::string::npos) << why;
  }
  EXPECT_NE(refusal((folder_.root() / "missing.xml").string()).find("missing.xml"), std::string::npos);
}

TEST_F(MitsubaXml, ACycleOfIncludesIsRefused) {
  write("a.xml", "<scene version=\"3.0.0\">\n  <include filename=\"b.xml\"/>\n</scene>");
  const std::string b = write("b.xml", "<scene version=\"3.0.0\">\n\n  <include filename=\"a.xml\"/>\n</scene>");
  const std::string why = refusal((folder_.root() / "a.xml").string());
  EXPECT_EQ(why, b + ":3: include: '" + (folder_.root() / "a.xml").string() + "' includes itself (a cycle of <include>)");
}

}  // namespace
}  // namespace wt::mitsuba

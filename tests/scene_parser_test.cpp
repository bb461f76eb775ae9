// The scene-file parser: values and defaults of valid scenes, and one message per
// kind of mistake that names the file, the JSON path and the problem.
#include <stb/stb_image_write.h>
#include <stdlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>

#include "scene/scene.hpp"
#include "errors/errors.hpp"
#include "test_support.hpp"
#include "wavetrace/film.hpp"

namespace wt {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const std::string kSource = "scenes/t.json";

json base_scene() {
  return json::parse(R"({
    "camera": {"look_from": [0, 2, -10], "look_at": [0, 0.5, 0], "up": [0, 1, 0],
               "vfov": 30, "aperture": 0.1, "focus_distance": 9.5},
    "sky": {"type": "gradient", "horizon": [0.9, 0.8, 0.7], "zenith": [0.1, 0.2, 2]},
    "render": {"width": 320, "height": 200, "spp": 4, "depth": 6, "roulette_depth": 2, "seed": 4000000000},
    "textures": [
      {"name": "floor", "type": "checker", "size": 2, "even": [1, 1, 1], "odd": [0, 0, 0]},
      {"name": "veins", "type": "noise", "scale": 3, "octaves": 5, "high": [0.9, 0.9, 0.9], "low": [0.1, 0.2, 0.3]}
    ],
    "materials": [
      {"name": "ground", "type": "lambertian", "albedo": [0.5, 0.5, 0.5], "texture": "floor"},
      {"name": "mirror", "type": "metal", "albedo": [0.9, 0.8, 0.7], "fuzz": 0.25},
      {"name": "glass", "type": "dielectric", "ior": 1.5},
      {"name": "lacquer", "type": "coated", "albedo": [0.8, 0.1, 0.1], "ior": 1.4, "texture": "veins"},
      {"name": "lamp", "type": "emissive", "emission": [4, 3, 2]}
    ],
    "spheres": [
      {"center": [0, -1000, 0], "radius": 1000, "material": "ground"},
      {"center": [-2, 1, 0], "radius": 1, "material": "mirror"},
      {"center": [0, 1, 0], "radius": 1, "material": "glass"},
      {"center": [2, 1, 0], "radius": 1, "material": "lacquer"},
      {"center": [0, 3, 2], "radius": 0.5, "material": "lamp"}
    ]
  })");
}

json with(json doc, const std::string& pointer, const json& value) {
  doc[json::json_pointer(pointer)] = value;
  return doc;
}

json without(json doc, const std::string& pointer) {
  json::json_pointer p(pointer);
  doc[p.parent_pointer()].erase(p.back());
  return doc;
}

std::string error_of_text(const std::string& text, const std::string& source = kSource) {
  try {
    parse_scene(text, source);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// The message is one line: "<file>: <path>: <problem...>".
void expect_error(const std::string& message, const std::string& path, const std::string& problem,
                  const std::string& source = kSource) {
  EXPECT_EQ(message.rfind(source + ": " + path + ": ", 0), 0u) << message;
  EXPECT_NE(message.find(problem), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

void expect_error(const json& doc, const std::string& path, const std::string& problem) {
  SCOPED_TRACE(path);
  expect_error(error_of_text(doc.dump()), path, problem);
}

// A fresh folder under the system's temporary folder, removed afterwards.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "wavetrace-scene-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() { fs::remove_all(path_); }

  std::string write(const std::string& relative, const std::string& content) const {
    fs::path p = path_ / relative;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << content;
    return p.string();
  }

  // An RGBA PNG written by stb; pixels are width * height * 4 bytes.
  std::string write_png(const std::string& relative, int width, int height,
                        const std::vector<unsigned char>& pixels) const {
    fs::path p = path_ / relative;
    fs::create_directories(p.parent_path());
    EXPECT_NE(stbi_write_png(p.string().c_str(), width, height, 4, pixels.data(), width * 4), 0);
    return p.string();
  }

  std::string path() const { return path_.string(); }

 private:
  fs::path path_;
};

json image_texture_scene(const std::string& file, const std::string& colorspace) {
  json doc = base_scene();
  doc["textures"].push_back({{"name", "picture"}, {"type", "image"}, {"file", file}, {"colorspace", colorspace}});
  doc["materials"][0]["texture"] = "picture";
  return doc;
}

const Material& material_named(const Scene& s, const std::string& name) {
  for (size_t i = 0; i < s.material_names.size(); ++i) {
    if (s.material_names[i] == name) return s.materials[i];
  }
  throw std::runtime_error("no material " + name);
}

TEST(SceneParser, ValidSceneParsesWithItsValues) {
  Scene s = parse_scene(base_scene().dump(), kSource);
  EXPECT_EQ(s.source, kSource);
  EXPECT_EQ(s.camera.look_from, vec3(0, 2, -10));
  EXPECT_EQ(s.camera.look_at, vec3(0, 0.5f, 0));
  EXPECT_EQ(s.camera.vfov_degrees, 30.0f);
  EXPECT_EQ(s.camera.aperture, 0.1f);
  EXPECT_EQ(s.camera.focus_distance, 9.5f);
  EXPECT_EQ(s.sky.kind, SkyKind::Gradient);
  EXPECT_EQ(s.sky.horizon, vec3(0.9f, 0.8f, 0.7f));
  EXPECT_EQ(s.sky.zenith, vec3(0.1f, 0.2f, 2.0f));
  EXPECT_EQ(s.render.width, 320);
  EXPECT_EQ(s.render.height, 200);
  EXPECT_EQ(s.render.spp, 4);
  EXPECT_EQ(s.render.depth, 6);
  EXPECT_EQ(s.render.roulette_depth, 2);
  EXPECT_EQ(s.render.seed, 4000000000u);

  ASSERT_EQ(s.textures.size(), 2u);
  EXPECT_EQ(s.textures[0].kind, TextureKind::Checker);
  EXPECT_EQ(s.textures[0].scale, 2.0f);
  EXPECT_EQ(s.textures[0].a, vec3(1.0f));
  EXPECT_EQ(s.textures[0].b, vec3(0.0f));
  EXPECT_EQ(s.textures[1].kind, TextureKind::Noise);
  EXPECT_EQ(s.textures[1].scale, 3.0f);
  EXPECT_EQ(s.textures[1].octaves, 5);
  EXPECT_EQ(s.textures[1].a, vec3(0.9f));
  EXPECT_EQ(s.textures[1].b, vec3(0.1f, 0.2f, 0.3f));
  EXPECT_TRUE(s.images.empty());

  ASSERT_EQ(s.material_names, (std::vector<std::string>{"ground", "mirror", "glass", "lacquer", "lamp"}));
  EXPECT_EQ(s.materials[0].kind, MaterialKind::Lambertian);
  EXPECT_EQ(s.materials[0].albedo, vec3(0.5f));
  EXPECT_EQ(s.materials[0].texture, 0);
  EXPECT_EQ(s.materials[1].kind, MaterialKind::Metal);
  EXPECT_EQ(s.materials[1].fuzz, 0.25f);
  EXPECT_EQ(s.materials[1].albedo, vec3(0.9f, 0.8f, 0.7f));
  EXPECT_EQ(s.materials[1].texture, -1);
  EXPECT_EQ(s.materials[2].kind, MaterialKind::Dielectric);
  EXPECT_EQ(s.materials[2].ior, 1.5f);
  EXPECT_EQ(s.materials[3].kind, MaterialKind::Coated);
  EXPECT_EQ(s.materials[3].ior, 1.4f);
  EXPECT_EQ(s.materials[3].texture, 1);
  EXPECT_EQ(s.materials[4].kind, MaterialKind::Emissive);
  EXPECT_EQ(s.materials[4].emission, vec3(4, 3, 2));

  // The BVH reorders spheres; each must still carry its own material.
  ASSERT_EQ(s.spheres.size(), 5u);
  ASSERT_EQ(s.sphere_materials.size(), 5u);
  ASSERT_FALSE(s.nodes.empty());
  const std::vector<std::pair<SphereGeom, std::string>> expected = {
      {{0, -1000, 0, 1000}, "ground"}, {{-2, 1, 0, 1}, "mirror"}, {{0, 1, 0, 1}, "glass"},
      {{2, 1, 0, 1}, "lacquer"},       {{0, 3, 2, 0.5f}, "lamp"}};
  for (const auto& [geom, material] : expected) {
    int found = 0;
    for (size_t i = 0; i < s.spheres.size(); ++i) {
      const SphereGeom& g = s.spheres[i];
      if (g.x == geom.x && g.y == geom.y && g.z == geom.z && g.w == geom.w) {
        ++found;
        EXPECT_EQ(s.material_names[s.sphere_materials[i]], material);
      }
    }
    EXPECT_EQ(found, 1) << material;
  }
}

TEST(SceneParser, OmittedFieldsTakeTheDocumentedDefaults) {
  Scene s = parse_scene(R"({
    "camera": {"look_from": [0, 0, 5], "look_at": [0, 0, 0]},
    "textures": [{"name": "n", "type": "noise", "scale": 1, "high": [1, 1, 1], "low": [0, 0, 0]}],
    "materials": [{"name": "m", "type": "lambertian"}, {"name": "g", "type": "dielectric", "ior": 1.3},
                  {"name": "c", "type": "metal"}],
    "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]
  })",
                        kSource);
  EXPECT_EQ(s.camera.up, vec3(0, 1, 0));
  EXPECT_EQ(s.camera.vfov_degrees, 40.0f);
  EXPECT_EQ(s.camera.aperture, 0.0f);
  EXPECT_LE(s.camera.focus_distance, 0.0f);  // i.e. |look_from - look_at|
  EXPECT_EQ(s.sky.kind, SkyKind::Gradient);
  EXPECT_EQ(s.sky.horizon, vec3(1.0f));
  EXPECT_EQ(s.sky.zenith, vec3(0.5f, 0.7f, 1.0f));
  RenderDefaults defaults;
  EXPECT_EQ(s.render.width, defaults.width);
  EXPECT_EQ(s.render.height, defaults.height);
  EXPECT_EQ(s.render.spp, defaults.spp);
  EXPECT_EQ(s.render.depth, defaults.depth);
  EXPECT_EQ(s.render.roulette_depth, defaults.roulette_depth);
  EXPECT_EQ(s.render.seed, defaults.seed);
  EXPECT_EQ(s.textures[0].octaves, 7);
  EXPECT_EQ(s.materials[0].albedo, vec3(1.0f));
  EXPECT_EQ(s.materials[0].texture, -1);
  EXPECT_EQ(s.materials[1].albedo, vec3(1.0f));
  EXPECT_EQ(s.materials[2].albedo, vec3(1.0f));
  EXPECT_EQ(s.materials[2].fuzz, 0.0f);
  ASSERT_EQ(s.nodes.size(), 2u);  // one sphere: the top level's leaf, over the spheres' leaf
  EXPECT_EQ(s.nodes[0].count, 1);
  EXPECT_EQ(s.nodes[1].count, 1);
}

TEST(SceneParser, UniformSkyUsesItsRadianceEverywhere) {
  json doc = with(base_scene(), "/sky", {{"type", "uniform"}, {"radiance", {0.2, 3, 0.4}}});
  Scene s = parse_scene(doc.dump(), kSource);
  EXPECT_EQ(s.sky.kind, SkyKind::Uniform);
  EXPECT_EQ(s.sky.radiance(vec3(0, 1, 0), nullptr), vec3(0.2f, 3.0f, 0.4f));
  EXPECT_EQ(s.sky.radiance(vec3(0, -1, 0), nullptr), vec3(0.2f, 3.0f, 0.4f));
}

TEST(SceneParser, MissingFileIsReported) {
  TempDir dir;
  std::string path = dir.path() + "/absent.json";
  try {
    load_scene(path);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": cannot open scene file (No such file or directory)");
  }
}

TEST(SceneParser, SceneFileIsReadFromDisk) {
  TempDir dir;
  std::string path = dir.write("s.json", base_scene().dump(2));
  Scene s = load_scene(path);
  EXPECT_EQ(s.source, path);
  EXPECT_EQ(s.spheres.size(), 5u);
}

TEST(SceneParser, MalformedJsonIsReportedWithLineAndColumn) {
  std::string message = error_of_text("{\n  \"camera\": {,\n}");
  EXPECT_EQ(message.rfind(kSource + ": malformed JSON: ", 0), 0u) << message;
  EXPECT_NE(message.find("line 2, column 14"), std::string::npos) << message;
  EXPECT_EQ(message.find("[json.exception"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(SceneParser, RootMustBeAnObject) {
  expect_error(error_of_text("[1, 2]"), "/", "must be an object (got array)");
}

TEST(SceneParser, UnknownKeysAreRejectedAtEveryLevel) {
  json doc = base_scene();
  expect_error(with(doc, "/cameras", json::object()), "/cameras", "unknown key (expected camera, sky,");
  expect_error(with(doc, "/camera/fov", 30), "/camera/fov", "unknown key (expected look_from,");
  expect_error(with(doc, "/sky/radiance", {1, 1, 1}), "/sky/radiance",
               "unknown key for type 'gradient' (expected type, horizon, zenith)");
  expect_error(with(doc, "/render/samples", 4), "/render/samples", "unknown key");
  expect_error(with(doc, "/textures/0/colour", {1, 1, 1}), "/textures/0/colour",
               "unknown key for type 'checker'");
  expect_error(with(doc, "/materials/2/fuzz", 0), "/materials/2/fuzz",
               "unknown key for type 'dielectric' (expected name, type, ior, albedo, normal_texture, normal_strength, bump_texture, bump_scale)");
  expect_error(with(doc, "/spheres/1/mat", "glass"), "/spheres/1/mat", "unknown key");
  expect_error(with(doc, "/spheres/1/a~0b", 1), "/spheres/1/a~0b", "unknown key");
}

TEST(SceneParser, RepeatedKeysAreRejected) {
  std::string text = base_scene().dump();
  std::string camera = text;
  camera.replace(camera.find("\"vfov\""), 0, "\"vfov\":50,");
  expect_error(error_of_text(camera), "/camera/vfov", "duplicate key");
  std::string sphere = text;
  size_t third = sphere.find("\"radius\"", sphere.find("\"radius\"", sphere.find("\"radius\"") + 1) + 1);
  sphere.replace(third, 0, "\"radius\":-1,");
  expect_error(error_of_text(sphere), "/spheres/2/radius", "duplicate key");
}

TEST(SceneParser, RequiredKeysMustBePresent) {
  json doc = base_scene();
  for (const char* path : {"/camera", "/camera/look_at", "/materials", "/spheres/3/radius",
                           "/spheres/0/material", "/materials/2/ior", "/materials/4/emission", "/materials/1/name",
                           "/textures/0/size", "/textures/1/high", "/sky/type"}) {
    expect_error(without(doc, path), path, "required key is missing");
  }
}

TEST(SceneParser, WrongTypesAreRejected) {
  json doc = base_scene();
  expect_error(with(doc, "/camera/vfov", "30"), "/camera/vfov", "must be a number (got string)");
  expect_error(with(doc, "/spheres/0/radius", true), "/spheres/0/radius", "must be a number (got boolean)");
  expect_error(with(doc, "/spheres/0/center", 5), "/spheres/0/center", "must be an array of 3 numbers (got number)");
  expect_error(with(doc, "/spheres/0/center", {1, 2}), "/spheres/0/center",
               "must be an array of 3 numbers (got 2 elements)");
  expect_error(with(doc, "/spheres/0/center/1", nullptr), "/spheres/0/center/1", "must be a number (got null)");
  expect_error(with(doc, "/materials/0/name", 3), "/materials/0/name", "must be a string (got number)");
  expect_error(with(doc, "/render/spp", 2.5), "/render/spp", "must be an integer in 1..1000000 (got 2.5)");
  expect_error(with(doc, "/spheres", json::object()), "/spheres", "must be an array (got object)");
  expect_error(with(doc, "/camera", json::array()), "/camera", "must be an object (got array)");
  expect_error(with(doc, "/materials/1", "mirror"), "/materials/1", "must be an object (got string)");
}

TEST(SceneParser, IntegralFloatsAreAcceptedAsIntegers) {
  Scene s = parse_scene(with(base_scene(), "/render/width", 1e3).dump(), kSource);
  EXPECT_EQ(s.render.width, 1000);
}

TEST(SceneParser, NumbersBeyondFloatRangeAreRejected) {
  json doc = base_scene();
  expect_error(with(doc, "/spheres/1/radius", 1e39), "/spheres/1/radius",
               "must be a finite number within float range (got 1e+39)");
  expect_error(with(doc, "/camera/look_from/0", -1e300), "/camera/look_from/0", "within float range");
  // Beyond double range the JSON reader itself refuses the number.
  std::string text = doc.dump();
  text.replace(text.find("\"radius\":1000"), 13, "\"radius\":1e400");
  std::string message = error_of_text(text);
  EXPECT_EQ(message.rfind(kSource + ": malformed JSON: ", 0), 0u) << message;
  EXPECT_NE(message.find("1e400"), std::string::npos) << message;
}

TEST(SceneParser, NonPositiveRadiusIsRejected) {
  json doc = base_scene();
  EXPECT_EQ(error_of_text(with(doc, "/spheres/3/radius", -1).dump()),
            kSource + ": /spheres/3/radius: must be > 0 (got -1)");
  expect_error(with(doc, "/spheres/0/radius", 0), "/spheres/0/radius", "must be > 0 (got 0)");
  // Positive in JSON but zero as a float.
  expect_error(with(doc, "/spheres/0/radius", 1e-50), "/spheres/0/radius", "must be > 0 (got 1e-50)");
}

TEST(SceneParser, NonPositiveIorIsRejected) {
  json doc = base_scene();
  expect_error(with(doc, "/materials/2/ior", 0), "/materials/2/ior", "must be > 0 (got 0)");
  expect_error(with(doc, "/materials/3/ior", -1.5), "/materials/3/ior", "must be > 0 (got -1.5)");
}

TEST(SceneParser, FuzzOutsideUnitIntervalIsRejected) {
  json doc = base_scene();
  expect_error(with(doc, "/materials/1/fuzz", -0.1), "/materials/1/fuzz", "must be in [0, 1] (got -0.1)");
  expect_error(with(doc, "/materials/1/fuzz", 1.5), "/materials/1/fuzz", "must be in [0, 1] (got 1.5)");
  EXPECT_EQ(parse_scene(with(doc, "/materials/1/fuzz", 1).dump(), kSource).materials[1].fuzz, 1.0f);
}

TEST(SceneParser, ColoursOutsideUnitIntervalAreRejected) {
  json doc = base_scene();
  expect_error(with(doc, "/materials/0/albedo/1", 1.2), "/materials/0/albedo/1", "must be in [0, 1] (got 1.2)");
  expect_error(with(doc, "/materials/2/albedo", {1, 1, -0.5}), "/materials/2/albedo/2", "must be in [0, 1]");
  expect_error(with(doc, "/textures/0/odd/0", -0.5), "/textures/0/odd/0", "must be in [0, 1] (got -0.5)");
  expect_error(with(doc, "/textures/1/high/2", 2), "/textures/1/high/2", "must be in [0, 1] (got 2)");
}

TEST(SceneParser, EmissionAndSkyMustBeNonNegative) {
  json doc = base_scene();
  expect_error(with(doc, "/materials/4/emission/2", -1), "/materials/4/emission/2", "must be >= 0 (got -1)");
  expect_error(with(doc, "/sky/horizon/0", -0.1), "/sky/horizon/0", "must be >= 0 (got -0.1)");
  Scene s = parse_scene(with(doc, "/materials/4/emission", {50, 0, 1000}).dump(), kSource);
  EXPECT_EQ(material_named(s, "lamp").emission, vec3(50, 0, 1000));
}

// Radiance past 1e9 would overflow the film's float sums after a few samples.
TEST(SceneParser, EmissionAndSkyRadianceAreAtMostABillion) {
  json doc = base_scene();
  expect_error(with(doc, "/materials/4/emission/1", 3e38), "/materials/4/emission/1",
               "must be at most 1e9, the most radiance a scene may hold (got 3e+38)");
  expect_error(with(doc, "/sky/zenith/2", 1.5e9), "/sky/zenith/2", "must be at most 1e9, the most radiance a scene may hold");
  json uniform = with(doc, "/sky", json::parse(R"({"type": "uniform", "radiance": [1, 1e10, 1]})"));
  expect_error(uniform, "/sky/radiance/1", "must be at most 1e9");
  Scene s = parse_scene(with(doc, "/materials/4/emission", {1e9, 0, 1}).dump(), kSource);  // the limit itself
  EXPECT_EQ(material_named(s, "lamp").emission.x, 1e9f);
}

// Coordinates past 1e15 lose every digit of a scene's detail in float.
TEST(SceneParser, CoordinatesAndRadiiAreWithinAQuadrillion) {
  json doc = base_scene();
  expect_error(with(doc, "/spheres/1/center/0", 1e20), "/spheres/1/center/0",
               "must be within +-1e15, the largest coordinate a scene may hold (got 1e+20)");
  expect_error(with(doc, "/spheres/1/center/2", -1e20), "/spheres/1/center/2", "must be within +-1e15");
  expect_error(with(doc, "/spheres/0/radius", 1e20), "/spheres/0/radius", "must be at most 1e15");
  expect_error(with(doc, "/camera/look_from/1", 1e20), "/camera/look_from/1", "must be within +-1e15");
  expect_error(with(doc, "/camera/look_at/0", -1e16), "/camera/look_at/0", "must be within +-1e15");
}

TEST(SceneParser, UnknownMaterialReferenceIsRejected) {
  expect_error(with(base_scene(), "/spheres/1/material", "chrome"), "/spheres/1/material",
               "unknown material 'chrome'");
}

TEST(SceneParser, UnknownTextureReferenceIsRejected) {
  expect_error(with(base_scene(), "/materials/0/texture", "wood"), "/materials/0/texture", "unknown texture 'wood'");
}

TEST(SceneParser, DuplicateNamesAreRejected) {
  json doc = base_scene();
  expect_error(with(doc, "/materials/3/name", "mirror"), "/materials/3/name",
               "duplicate material name 'mirror' (first defined at /materials/1)");
  expect_error(with(doc, "/textures/1/name", "floor"), "/textures/1/name",
               "duplicate texture name 'floor' (first defined at /textures/0)");
  expect_error(with(doc, "/materials/0/name", ""), "/materials/0/name", "must not be empty");
}

TEST(SceneParser, UnknownTypesAreRejected) {
  json doc = base_scene();
  EXPECT_EQ(error_of_text(with(doc, "/materials/2/type", "plastik").dump()),
            kSource +
                ": /materials/2/type: unknown material type 'plastik' (expected lambertian, metal, dielectric, "
                "coated, emissive, conductor, glass, plastic, principled, blend)");
  expect_error(with(doc, "/textures/1/type", "wood"), "/textures/1/type",
               "unknown texture type 'wood' (expected checker, noise, image, uv_checker)");
  expect_error(with(doc, "/sky/type", "hdri"), "/sky/type", "unknown sky type 'hdri' (expected gradient, uniform, environment)");
}

TEST(SceneParser, RenderValuesOutsideTheirRangesAreRejected) {
  json doc = base_scene();
  expect_error(with(doc, "/render/width", 0), "/render/width", "must be an integer in 1..16384 (got 0)");
  expect_error(with(doc, "/render/height", 16385), "/render/height", "must be an integer in 1..16384 (got 16385)");
  expect_error(with(doc, "/render/spp", 0), "/render/spp", "1..1000000 (got 0)");
  expect_error(with(doc, "/render/depth", 1025), "/render/depth", "1..1024 (got 1025)");
  expect_error(with(doc, "/render/roulette_depth", -1), "/render/roulette_depth", "(got -1)");
  expect_error(with(doc, "/render/seed", -1), "/render/seed", "0..4294967295 (got -1)");
  expect_error(with(doc, "/render/seed", 4294967296), "/render/seed", "0..4294967295 (got 4294967296)");
  expect_error(with(doc, "/render/seed", 18446744073709551615u), "/render/seed", "(got 18446744073709551615)");
}

TEST(SceneParser, ASceneWithNoSpheresAndNoInstancesIsRejected) {
  const char* problem = "it needs at least one sphere or one instance";
  expect_error(with(base_scene(), "/spheres", json::array()), "/spheres", problem);
  expect_error(without(base_scene(), "/spheres"), "/spheres", problem);
}

TEST(SceneParser, VfovMustLieStrictlyBetweenZeroAnd180) {
  json doc = base_scene();
  expect_error(with(doc, "/camera/vfov", 0), "/camera/vfov", "must be in (0, 180) degrees (got 0)");
  expect_error(with(doc, "/camera/vfov", 180), "/camera/vfov", "must be in (0, 180) degrees (got 180)");
  expect_error(with(doc, "/camera/vfov", -5), "/camera/vfov", "(got -5)");
  EXPECT_EQ(parse_scene(with(doc, "/camera/vfov", 179.5).dump(), kSource).camera.vfov_degrees, 179.5f);
}

TEST(SceneParser, ApertureAndFocusDistanceRangesAreEnforced) {
  json doc = base_scene();
  expect_error(with(doc, "/camera/aperture", -0.1), "/camera/aperture", "must be >= 0 (got -0.1)");
  expect_error(with(doc, "/camera/focus_distance", 0), "/camera/focus_distance", "must be > 0 (got 0)");
}

TEST(SceneParser, CoincidentLookFromAndLookAtAreRejected) {
  expect_error(with(base_scene(), "/camera/look_at", {0, 2, -10}), "/camera/look_at", "must differ from look_from");
}

TEST(SceneParser, UpParallelToViewDirectionIsRejected) {
  json doc = with(with(base_scene(), "/camera/look_from", {0, 10, 0}), "/camera/look_at", {0, 0, 0});
  expect_error(doc, "/camera/up", "must not be parallel to the view direction");
  expect_error(with(doc, "/camera/up", {0, -3, 0}), "/camera/up", "must not be parallel");
  expect_error(without(doc, "/camera/up"), "/camera/up", "(up defaults to [0, 1, 0])");
  expect_error(with(base_scene(), "/camera/up", {0, 0, 0}), "/camera/up", "must not be the zero vector");
  EXPECT_NO_THROW(parse_scene(with(doc, "/camera/up", {0, 0, 1}).dump(), kSource));
}

TEST(SceneParser, UnreadableTextureIsReported) {
  TempDir dir;
  std::string scene = dir.write("s.json", image_texture_scene("missing.png", "srgb").dump());
  try {
    load_scene(scene);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    expect_error(e.what(), "/textures/2/file", "cannot read image '" + dir.path() + "/missing.png' (", scene);
  }

  dir.write("corrupt.png", "\x89PNG\r\n\x1a\n but not really a PNG");
  std::string corrupt = dir.write("c.json", image_texture_scene("corrupt.png", "srgb").dump());
  try {
    load_scene(corrupt);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    std::string message = e.what();
    expect_error(message, "/textures/2/file", "cannot read image '" + dir.path() + "/corrupt.png' (", corrupt);
    EXPECT_EQ(message.find("()"), std::string::npos) << "stb's reason is missing: " << message;
  }
}

// An image texture that is no image file: each says what it is instead.
TEST(SceneParser, TextureThatIsADirectorySaysSo) {
  TempDir dir;
  fs::create_directories(fs::path(dir.path()) / "folder.png");
  const std::string scene = dir.write("s.json", image_texture_scene("folder.png", "srgb").dump());
  try {
    load_scene(scene);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), scene + ": /textures/2/file: cannot read image '" + dir.path() +
                                         "/folder.png' (it is a directory, not a file)");
  }
}

TEST(SceneParser, TextureThatIsALoopOfLinksSaysSo) {
  TempDir dir;
  const fs::path a = fs::path(dir.path()) / "a.png", b = fs::path(dir.path()) / "b.png";
  fs::create_symlink(b, a);
  fs::create_symlink(a, b);
  const std::string scene = dir.write("s.json", image_texture_scene("a.png", "srgb").dump());
  try {
    load_scene(scene);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), scene + ": /textures/2/file: cannot read image '" + a.string() +
                                         "' (cannot open it (a loop of symbolic links))");
  }
}

// A PNG cut short (a copy interrupted): the message says the file ends early, not
// only the decoder's word for it.
TEST(SceneParser, TruncatedPngTextureSaysItIsCutShort) {
  TempDir dir;
  std::vector<unsigned char> pixels(32 * 32 * 4);
  uint32_t state = 12345;
  for (unsigned char& p : pixels) {
    state = state * 1664525u + 1013904223u;  // noise, so that the compressed data is not a few bytes
    p = static_cast<unsigned char>(state >> 24);
  }
  const std::string whole = dir.write_png("whole.png", 32, 32, pixels);
  std::ifstream in(whole, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1000u);
  EXPECT_NO_THROW(load_scene(dir.write("whole.json", image_texture_scene("whole.png", "srgb").dump())));
  dir.write("cut.png", bytes.substr(0, bytes.size() / 2));
  const std::string scene = dir.write("s.json", image_texture_scene("cut.png", "srgb").dump());
  try {
    load_scene(scene);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string message = e.what();
    expect_error(message, "/textures/2/file",
                 "cannot read image '" + dir.path() + "/cut.png' (the file is cut short: it ends before its image does (",
                 scene);
  }
}

// A BMP whose header claims no rows (which stb decodes into an image of no
// pixels) is refused, not filtered.
TEST(SceneParser, AnImageOfNoPixelsIsRefused) {
  TempDir dir;
  // 54-byte header: 3 x 0 pixels, 24 bits, uncompressed.
  std::string bmp(54, '\0');
  auto put32 = [&](size_t at, uint32_t v) {
    for (int i = 0; i < 4; ++i) bmp[at + i] = static_cast<char>((v >> (8 * i)) & 255);
  };
  bmp[0] = 'B';
  bmp[1] = 'M';
  put32(2, 54);
  put32(10, 54);
  put32(14, 40);
  put32(18, 3);
  put32(22, 0);
  bmp[26] = 1;
  bmp[28] = 24;
  dir.write("empty.bmp", bmp);
  const std::string scene = dir.write("s.json", image_texture_scene("empty.bmp", "srgb").dump());
  try {
    load_scene(scene);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    expect_error(e.what(), "/textures/2/file", "cannot read image '" + dir.path() + "/empty.bmp' (the image has no pixels (3 x 0))",
                 scene);
  }
}

TEST(SceneParser, UnknownColorspaceIsRejected) {
  expect_error(image_texture_scene("x.png", "rec2020"), "/textures/2/colorspace",
               "unknown colorspace 'rec2020' (expected srgb, linear)");
}

TEST(SceneParser, TexturePathIsRelativeToTheSceneFile) {
  TempDir dir;
  dir.write_png("scenes/tex/pic.png", 3, 2, std::vector<unsigned char>(3 * 2 * 4, 200));
  std::string scene = dir.write("scenes/s.json", image_texture_scene("tex/pic.png", "linear").dump());
  Scene s = load_scene(scene);
  ASSERT_EQ(s.images.size(), 1u);
  EXPECT_EQ(s.images[0].width, 3);
  EXPECT_EQ(s.images[0].height, 2);
  EXPECT_TRUE(fs::equivalent(s.images[0].path, dir.path() + "/scenes/tex/pic.png"));
  ASSERT_EQ(s.textures.size(), 3u);
  EXPECT_EQ(s.textures[2].kind, TextureKind::Image);
  EXPECT_EQ(s.textures[2].image, 0);
}

TEST(SceneParser, SrgbTexturesAreDecodedAndLinearOnesAreNot) {
  TempDir dir;
  // Two pixels, top row first: (128, 64, 255, 128) then (0, 10, 200, 255).
  const std::vector<unsigned char> pixels = {128, 64, 255, 128, 0, 10, 200, 255};
  dir.write_png("p.png", 1, 2, pixels);
  std::vector<float> expect_srgb, expect_linear;
  for (size_t i = 0; i < pixels.size(); ++i) {
    float v = pixels[i] / 255.0f;
    expect_linear.push_back(v);
    expect_srgb.push_back(i % 4 == 3 ? v : decode_srgb(v));
  }
  Scene srgb = load_scene(dir.write("a.json", image_texture_scene("p.png", "srgb").dump()));
  Scene linear = load_scene(dir.write("b.json", image_texture_scene("p.png", "linear").dump()));
  ASSERT_EQ(srgb.images.size(), 1u);
  ASSERT_EQ(linear.images.size(), 1u);
  EXPECT_EQ(srgb.images[0].texels, expect_srgb);
  EXPECT_EQ(linear.images[0].texels, expect_linear);
  EXPECT_NEAR(srgb.images[0].texels[0], 0.2158f, 1e-4f);  // sRGB 128 is about 21.6% linear
}

TEST(SceneParser, TexturesSharingAFileAndColorspaceShareOneImage) {
  TempDir dir;
  dir.write_png("p.png", 2, 2, std::vector<unsigned char>(16, 90));
  json doc = image_texture_scene("p.png", "srgb");
  doc["textures"].push_back({{"name", "again"}, {"type", "image"}, {"file", "./p.png"}});
  doc["textures"].push_back({{"name", "raw"}, {"type", "image"}, {"file", "p.png"}, {"colorspace", "linear"}});
  Scene s = load_scene(dir.write("s.json", doc.dump()));
  EXPECT_EQ(s.images.size(), 2u);
  EXPECT_EQ(s.textures[2].image, 0);
  EXPECT_EQ(s.textures[4].image, 1);
}

TEST(SceneParser, SortKeysFollowMaterialAndTextureKind) {
  TempDir dir;
  dir.write_png("p.png", 1, 1, {1, 2, 3, 4});
  json doc = image_texture_scene("p.png", "srgb");
  doc["materials"].push_back({{"name", "plain"}, {"type", "lambertian"}});
  Scene s = load_scene(dir.write("s.json", doc.dump()));
  EXPECT_EQ(material_named(s, "ground").sort_key, material_sort_key(MaterialKind::Lambertian, 2));  // image
  EXPECT_EQ(material_named(s, "plain").sort_key, material_sort_key(MaterialKind::Lambertian, -1));
  EXPECT_EQ(material_named(s, "mirror").sort_key, material_sort_key(MaterialKind::Metal, -1));
  EXPECT_EQ(material_named(s, "glass").sort_key, material_sort_key(MaterialKind::Dielectric, -1));
  EXPECT_EQ(material_named(s, "lacquer").sort_key, material_sort_key(MaterialKind::Coated, 1));  // noise
  EXPECT_EQ(material_named(s, "lamp").sort_key, material_sort_key(MaterialKind::Emissive, -1));
  std::set<uint32_t> distinct;
  for (const Material& m : s.materials) distinct.insert(m.sort_key);
  EXPECT_EQ(distinct.size(), s.materials.size());
}

TEST(SceneParser, SortKeyBitsHoldEveryMaterialKeyAndNoMore) {
  Scene s = parse_scene(base_scene().dump(), kSource);
  int bits = s.sort_key_bits();
  uint32_t largest = 0;
  for (const Material& m : s.materials) largest = std::max(largest, static_cast<uint32_t>(m.sort_key));
  EXPECT_GT(1u << bits, largest);
  if (largest > 0) {
    EXPECT_LE(1u << (bits - 1), largest);  // no more bits than that
  }
  // The reference scene uses Lambertian, checker, image, metal and dielectric keys (the
  // largest 8): four bits, where the emissive kind would need five.
  EXPECT_EQ(load_scene(test::repo_path("scenes/seed57.json")).sort_key_bits(), 4);
}

TEST(SceneParser, HostViewPointsIntoTheSceneWithTheRendersCamera) {
  TempDir dir;
  dir.write_png("p.png", 2, 1, {1, 2, 3, 4, 5, 6, 7, 8});
  Scene s = load_scene(dir.write("s.json", image_texture_scene("p.png", "linear").dump()));
  std::vector<ImageView> images;
  // The render's size, not the scene file's defaults, shapes the camera.
  SceneView v = host_view(s, 160, 90, images);
  EXPECT_EQ(v.spheres, s.spheres.data());
  EXPECT_EQ(v.sphere_materials, s.sphere_materials.data());
  EXPECT_EQ(v.nodes, s.nodes.data());
  EXPECT_EQ(v.instances, s.instances.data());
  EXPECT_EQ(v.materials, s.materials.data());
  EXPECT_EQ(v.textures, s.textures.data());
  // Every array of the scene's list (scene_view.hpp), by name.
#define WT_EXPECT_POINTS_INTO_THE_SCENE(T, array, at, Return, Index) EXPECT_EQ(v.array, s.array.data()) << #array;
  WT_SCENE_ARRAYS(WT_EXPECT_POINTS_INTO_THE_SCENE)
#undef WT_EXPECT_POINTS_INTO_THE_SCENE
  EXPECT_EQ(s.spheres.size(), 5u);
  EXPECT_EQ(v.node_count(), static_cast<int>(s.nodes.size()));
  EXPECT_EQ(v.light_count(), static_cast<int>(s.lights.size()));
  EXPECT_EQ(v.kinds, s.kernel_kinds());
  ASSERT_EQ(images.size(), 1u);
  EXPECT_EQ(v.images, images.data());
  EXPECT_EQ(images[0].object, 0u);
  EXPECT_EQ(images[0].texels, s.images[0].texels.data());
  EXPECT_EQ(images[0].width, 2);
  EXPECT_EQ(images[0].height, 1);
  EXPECT_EQ(v.sky.zenith, s.sky.zenith);
  ASSERT_NE(s.render.width, 160);
  Camera c = Camera::make(s.camera, 160, 90);
  EXPECT_EQ(v.camera.origin, c.origin);
  EXPECT_EQ(v.camera.upper_left, c.upper_left);
  EXPECT_EQ(v.camera.horizontal, c.horizontal);
  EXPECT_EQ(v.camera.vertical, c.vertical);
  EXPECT_EQ(v.camera.lens_radius, c.lens_radius);
}

TEST(SceneParser, RepositoryScenesLoad) {
  for (const char* name : {"quick.json", "rtiow-cover.json", "seed57.json", "divergent.json"}) {
    SCOPED_TRACE(name);
    Scene s = load_scene(test::repo_path(std::string("scenes/") + name));
    EXPECT_FALSE(s.spheres.empty());
    EXPECT_FALSE(s.nodes.empty());
    EXPECT_EQ(s.sphere_materials.size(), s.spheres.size());
  }
}

}  // namespace
}  // namespace wt

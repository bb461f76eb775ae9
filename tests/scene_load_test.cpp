// Big scenes: a generated scene of many spheres loads whole, in time that grows
// linearly (the parser used to be quadratic in the length of the sphere list;
// these sizes took seconds there), and errors deep in it still name their path.
#include <gtest/gtest.h>

#include <string>

#include "errors/errors.hpp"
#include "scene/scene.hpp"

namespace wt {
namespace {

// n spheres on a grid, cycling through four materials. `bad`: the index of a
// sphere given a second "radius" key, or -1.
std::string spheres_scene(int n, int bad = -1) {
  std::string s = R"({"camera": {"look_from": [-10, 10, -10], "look_at": [0, 0, 0]},
  "materials": [{"name": "m0", "type": "lambertian"}, {"name": "m1", "type": "metal", "fuzz": 0.1},
                {"name": "m2", "type": "dielectric", "ior": 1.5}, {"name": "m3", "type": "emissive", "emission": [1, 1, 1]}],
  "spheres": [)";
  s.reserve(s.size() + static_cast<size_t>(n) * 80);
  for (int i = 0; i < n; ++i) {
    s += i ? ",\n" : "\n";
    s += "{\"center\": [" + std::to_string(i % 100) + ".5, " + std::to_string(i / 100 % 100) + ", " +
         std::to_string(i / 10000) + "], \"radius\": 0.25, \"material\": \"m" + std::to_string(i % 4) + "\"" +
         (i == bad ? ", \"radius\": 1" : "") + "}";
  }
  return s + "]}";
}

void expect_loads(int n) {
  Scene scene = parse_scene(spheres_scene(n), "big.json");
  ASSERT_EQ(scene.spheres.size(), static_cast<size_t>(n));
  ASSERT_EQ(scene.sphere_materials.size(), static_cast<size_t>(n));
  size_t per_material[4] = {};
  for (uint32_t m : scene.sphere_materials) ++per_material[m];
  for (size_t count : per_material) EXPECT_EQ(count, static_cast<size_t>(n / 4));
  // Every sphere sits in exactly one leaf (the first node is the top level's one
  // leaf, over the spheres' tree).
  ASSERT_EQ(scene.instances.size(), 1u);
  ASSERT_EQ(scene.instances[0].root, 1);
  size_t in_leaves = 0;
  for (size_t i = 1; i < scene.nodes.size(); ++i) in_leaves += scene.nodes[i].count;
  EXPECT_EQ(in_leaves, static_cast<size_t>(n));
}

TEST(BigScene, HundredThousandSpheresLoad) { expect_loads(100000); }

TEST(BigScene, TwoHundredThousandSpheresLoad) { expect_loads(200000); }

TEST(BigScene, RepeatedKeyDeepInABigSceneNamesItsPath) {
  try {
    parse_scene(spheres_scene(50000, 45678), "big.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "big.json: /spheres/45678/radius: duplicate key");
  }
}

}  // namespace
}  // namespace wt

// Instances: a mesh placed by a transform renders as the same mesh with the
// transform applied to its vertices; materials come from the instance, else the
// mesh's entry, else the file; a mesh placed many times is stored once.
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <fstream>
#include <numeric>
#include <sstream>

#include "mesh_support.hpp"
#include "dispatch/renderer.hpp"
#include "render_support.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"
#include "wavetrace/path.hpp"

namespace wt {
namespace {

using test::mean_abs_diff;

// A ground quad (two triangles, y = -1) under the object, so that the object
// casts shadows and light bounces between the two.
test::MeshData ground() {
  test::MeshData m;
  m.v = {vec3(-6, -1, -6), vec3(6, -1, -6), vec3(6, -1, 6), vec3(-6, -1, 6)};
  m.f = {{0, 2, 1}, {0, 3, 2}};
  return m;
}

// An icosphere and, beside it, a cube: one mesh, so one transform moves both.
test::MeshData object() {
  test::MeshData m = test::icosphere(2);
  const test::MeshData c = test::cube();
  const uint32_t base = static_cast<uint32_t>(m.v.size());
  for (const vec3& v : c.v) m.v.push_back(0.4f * v + vec3(1.4f, -0.2f, 0.3f));
  for (auto f : c.f) m.f.push_back({f[0] + base, f[1] + base, f[2] + base});
  return m;
}

std::string scene_json(const std::string& object_file, const std::string& placing) {
  return R"({
    "camera": {"look_from": [0.5, 1.5, 6], "look_at": [0.5, 0, 0], "vfov": 45},
    "materials": [{"name": "grey", "type": "lambertian", "albedo": [0.7, 0.7, 0.7]},
                  {"name": "floor", "type": "lambertian", "albedo": [0.5, 0.4, 0.3]}],
    "meshes": [{"name": "object", "file": ")" +
         object_file + R"(", "material": "grey"},
               {"name": "ground", "file": "ground.obj", "material": "floor"}],
    "instances": [{"mesh": "ground"}, {"mesh": "object")" +
         placing + R"(}]
  })";
}

RenderResult render_cpu(const Scene& scene, Kernel kernel = Kernel::Megakernel) {
  // No roulette: paths differ only where the geometry does.
  return render(scene, test::options_for(Backend::Cpu, kernel, 48, 32, 4, 4, 100, 9));
}

size_t values_apart(const std::vector<float>& a, const std::vector<float>& b, float tolerance) {
  size_t n = 0;
  for (size_t i = 0; i < a.size(); ++i) n += std::fabs(a[i] - b[i]) > tolerance;
  return n;
}

class InstanceRender : public testing::Test {
 protected:
  void SetUp() override {
    test::write_obj(path("ground.obj"), ground());
    test::write_obj(path("object.obj"), object());
    test::write_obj(path("moved.obj"), object(), transform_);
  }
  std::string path(const std::string& name) const { return (folder_.root() / name).string(); }
  Scene scene(const std::string& object_file, const std::string& placing) const {
    return parse_scene(scene_json(object_file, placing), path("scene.json"));
  }

  test::TestFolder folder_;
  const glm::dmat4 transform_ = test::trs({0.3, -0.1, 0.4}, {20, 35, -10}, {1.2, 0.8, 1.1});
  const std::string placing_ = R"(, "translate": [0.3, -0.1, 0.4], "rotate": [20, 35, -10], "scale": [1.2, 0.8, 1.1])";
};

// Both scenes trace the same paths (same seed, same camera); only float rounding
// separates the instance's rays (carried into object space) from the moved mesh's
// (against vertices rounded once from double). Where rounding flips a hit at an
// edge or a silhouette, that one path differs, by up to a quarter (4 spp) of a
// pixel's value: so almost every value must agree to 1e-4 (rounding only; at most
// 0.5% of them may not), and the mean absolute difference must stay under 1e-4,
// about four such diverged paths in these 1536 pixels. (When written, the two
// images agreed to 1e-9.) A turn of 3 degrees more moves the image by ~2e-3, over
// ten times the bound, which is checked too: the comparison can tell.
constexpr float kValueTolerance = 1e-4f;
constexpr double kMeanAbsBound = 1e-4;

TEST_F(InstanceRender, TransformedInstanceRendersAsThePreTransformedMesh) {
  const RenderResult instanced = render_cpu(scene("object.obj", placing_));
  const RenderResult moved = render_cpu(scene("moved.obj", ""));
  ASSERT_EQ(instanced.rgb.size(), moved.rgb.size());
  EXPECT_LE(values_apart(instanced.rgb, moved.rgb, kValueTolerance), instanced.rgb.size() / 200);
  EXPECT_LT(mean_abs_diff(instanced.rgb, moved.rgb), kMeanAbsBound);
  const double mean = std::accumulate(moved.rgb.begin(), moved.rgb.end(), 0.0) / moved.rgb.size();
  EXPECT_GT(mean, 0.05) << "the image should not be black";

  const RenderResult turned = render_cpu(
      scene("object.obj", R"(, "translate": [0.3, -0.1, 0.4], "rotate": [20, 38, -10], "scale": [1.2, 0.8, 1.1])"));
  EXPECT_GT(mean_abs_diff(instanced.rgb, turned.rgb), 10 * kMeanAbsBound);
}

// The same transform given as a matrix (the double matrix printed to round-trip)
// places the mesh as translate/rotate/scale do. Scene files' numbers are read as
// floats, so the matrix's entries are rounded to float before it is inverted,
// where the other form rounds only its angles and factors: the placements agree
// to a few ulps (2e-6 relative), and the images as in the test above.
TEST_F(InstanceRender, MatrixFormPlacesAsTranslateRotateScale) {
  std::ostringstream m;
  m.precision(17);
  m << R"(, "matrix": [)";
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m << (r + c ? ", " : "") << transform_[c][r];
  }
  m << "]";
  const Scene a = scene("object.obj", placing_), b = scene("object.obj", m.str());
  ASSERT_EQ(a.placements.size(), 2u);
  ASSERT_EQ(b.placements.size(), 2u);
  for (int i = 0; i < 12; ++i) {
    const float wa = a.placements[1].world_from_object.m[i], oa = a.placements[1].object_from_world.m[i];
    EXPECT_NEAR(b.placements[1].world_from_object.m[i], wa, 2e-6f * std::max(1.0f, std::fabs(wa))) << i;
    EXPECT_NEAR(b.placements[1].object_from_world.m[i], oa, 2e-6f * std::max(1.0f, std::fabs(oa))) << i;
  }
  const RenderResult ra = render_cpu(a), rb = render_cpu(b);
  EXPECT_LE(values_apart(ra.rgb, rb.rgb, kValueTolerance), ra.rgb.size() / 200);
  EXPECT_LT(mean_abs_diff(ra.rgb, rb.rgb), kMeanAbsBound);
}

// ---- Materials ----

class InstanceMaterials : public testing::Test {
 protected:
  std::string path(const std::string& name) const { return (folder_.root() / name).string(); }
  test::TestFolder folder_;
};

// Which material a ray down -z at x hits, by its albedo and name.
struct Shaded {
  std::string name;
  vec3 albedo;
};

Shaded shade_at(const Scene& s, float x) {
  std::vector<ImageView> images;
  const SceneView view = host_view(s, 8, 8, images);
  const Hit h = intersect_closest(view, Ray{vec3(x, 0.1f, 10), vec3(0, 0, -1)}, kRayTMax);
  if (h.missed()) return {"(missed)", vec3(-1)};
  const uint32_t m = material_index(view, h);
  return {s.material_names.at(m), s.materials.at(m).albedo};
}

TEST_F(InstanceMaterials, InstanceOverrideBeatsMeshOverrideBeatsTheFilesOwn) {
  std::ofstream(path("m.mtl")) << "newmtl red\nKd 0.8 0.1 0.1\n";
  test::write_obj(path("m.obj"), test::cube(), glm::dmat4(1.0), "m.mtl", "red");
  const Scene s = parse_scene(R"({
    "camera": {"look_from": [0, 0, 10], "look_at": [0, 0, 0]},
    "materials": [{"name": "blue", "type": "lambertian", "albedo": [0.1, 0.1, 0.8]},
                  {"name": "green", "type": "lambertian", "albedo": [0.1, 0.8, 0.1]}],
    "meshes": [{"name": "own", "file": "m.obj"}, {"name": "over", "file": "m.obj", "material": "blue"}],
    "instances": [{"mesh": "own", "translate": [-6, 0, 0]},
                  {"mesh": "own", "material": "green", "translate": [-2, 0, 0]},
                  {"mesh": "over", "translate": [2, 0, 0]},
                  {"mesh": "over", "material": "green", "translate": [6, 0, 0]}]
  })",
                              path("scene.json"));
  const struct {
    float x;
    const char* name;
    vec3 albedo;
  } expect[] = {{-6, "own/red", vec3(0.8f, 0.1f, 0.1f)},
                {-2, "green", vec3(0.1f, 0.8f, 0.1f)},
                {2, "blue", vec3(0.1f, 0.1f, 0.8f)},
                {6, "green", vec3(0.1f, 0.8f, 0.1f)}};
  for (const auto& e : expect) {
    const Shaded got = shade_at(s, e.x);
    EXPECT_EQ(got.name, e.name) << "x = " << e.x;
    EXPECT_FLOAT_EQ(got.albedo.x, e.albedo.x) << "x = " << e.x;
    EXPECT_FLOAT_EQ(got.albedo.y, e.albedo.y) << "x = " << e.x;
    EXPECT_FLOAT_EQ(got.albedo.z, e.albedo.z) << "x = " << e.x;
  }
  // The overridden mesh does not bring the file's materials in; the other does, once.
  EXPECT_EQ(std::count(s.material_names.begin(), s.material_names.end(), "own/red"), 1);
  EXPECT_EQ(std::count(s.material_names.begin(), s.material_names.end(), "over/red"), 0);
  EXPECT_EQ(s.materials.size(), 3u);
}

// ---- Storage ----

TEST_F(InstanceMaterials, MeshPlacedFiveTimesIsStoredOnce) {
  const test::MeshData ball = test::icosphere(2);
  test::write_obj(path("ball.obj"), ball);
  std::string instances;
  for (int i = 0; i < 5; ++i) {
    instances += std::string(i ? ", " : "") + R"({"mesh": "ball", "translate": [)" + std::to_string(3 * i) +
                 R"(, 0, 0], "rotate": [0, )" + std::to_string(17 * i) + ", 0]}";
  }
  const Scene s = parse_scene(R"({"camera": {"look_from": [0, 0, 10], "look_at": [0, 0, 0]},
    "materials": [{"name": "m", "type": "lambertian"}],
    "meshes": [{"name": "ball", "file": "ball.obj", "material": "m"}],
    "instances": [)" + instances + "]}",
                              path("scene.json"));
  const size_t count = ball.f.size();
  EXPECT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].triangle_count, count);
  EXPECT_EQ(s.triangles.size(), count);
  EXPECT_EQ(s.triangle_materials.size(), count);
  EXPECT_EQ(s.instances.size(), 5u);
  EXPECT_EQ(s.instanced_triangles(), 5 * count);
  // Every placement is there to be hit, at its own place.
  std::vector<ImageView> images;
  const SceneView view = host_view(s, 8, 8, images);
  std::vector<int> hit_instances;
  for (int i = 0; i < 5; ++i) {
    // Off the axis: a ray exactly along a box face (x = 0, direction x = 0) is the
    // slab test's case (TriangleWatertight.AxisRaysThroughACubesDiagonalsAndEdgesNeverMiss).
    const Hit h = intersect_closest(view, Ray{vec3(3.0f * i + 0.013f, 0.1f, 10), vec3(0, 0, -1)}, kRayTMax);
    ASSERT_FALSE(h.missed()) << "placement " << i;
    EXPECT_NEAR(h.t, 9.0f, 0.05f) << "placement " << i;  // a unit icosphere's facets are within 0.05 of the sphere
    hit_instances.push_back(h.instance);
  }
  std::sort(hit_instances.begin(), hit_instances.end());
  EXPECT_EQ(std::unique(hit_instances.begin(), hit_instances.end()) - hit_instances.begin(), 5);
}

}  // namespace
}  // namespace wt

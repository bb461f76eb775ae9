// Scene files' `meshes` and `instances` sections: each mistake is one line that
// names the scene file and the JSON path of the field (or, for a bad mesh file,
// that file), and through the command a mistake is bad input (exit code 2) with
// no image written.
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <sys/wait.h>
#include <unistd.h>

#include <climits>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "app/job.hpp"
#include "dispatch/renderer.hpp"
#include "errors/errors.hpp"
#include "mesh_support.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

namespace fs = std::filesystem;

class MeshScene : public testing::Test {
 protected:
  void SetUp() override {
    std::ofstream(path("tri.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  }

  std::string path(const std::string& name) const { return (folder_.root() / name).string(); }

  // A scene with `meshes` and `instances` as given (JSON text of the arrays).
  std::string write_scene(const std::string& meshes, const std::string& instances) const {
    const std::string p = path("scene.json");
    std::ofstream(p) << R"({"camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
      "materials": [{"name": "m", "type": "lambertian"}],
      "meshes": )" << meshes
                     << R"(, "instances": )" << instances << "}";
    return p;
  }

  // load_scene must fail with one line that starts with `file` and holds each of `parts`.
  // The message starts with `file: ` (for a mesh file's error: the scene file, the
  // field that names the mesh file, then the mesh file).
  void expect_error(const std::string& scene, const std::string& file, std::initializer_list<std::string> parts) {
    try {
      load_scene(scene);
      ADD_FAILURE() << scene << " loaded";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind(file + ": ", 0), 0u) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
      for (const std::string& part : parts) EXPECT_NE(message.find(part), std::string::npos) << message;
    }
  }

  void expect_instance_error(const std::string& instance, std::initializer_list<std::string> parts) {
    const std::string scene = write_scene(R"([{"name": "tri", "file": "tri.obj"}])", "[" + instance + "]");
    expect_error(scene, scene, parts);
  }

  test::TestFolder folder_;
};

TEST_F(MeshScene, GoodSceneLoads) {
  // The baseline the errors below depart from.
  const Scene s = load_scene(write_scene(R"([{"name": "tri", "file": "tri.obj", "material": "m"}])",
                                         R"([{"mesh": "tri", "translate": [1, 2, 3], "scale": 2}])"));
  EXPECT_EQ(s.triangles.size(), 1u);
  EXPECT_EQ(s.instances.size(), 1u);
}

TEST_F(MeshScene, MissingMeshFileNamesTheFile) {
  const std::string scene = write_scene(R"([{"name": "a", "file": "no-such.obj"}])", R"([{"mesh": "a"}])");
  expect_error(scene, scene + ": /meshes/0/file: " + path("no-such.obj"), {"cannot open mesh file"});
}

TEST_F(MeshScene, UnreadableMeshFileNamesTheFile) {
  fs::create_directories(path("folder.obj"));  // opens, but cannot be read
  const std::string scene = write_scene(R"([{"name": "a", "file": "folder.obj"}])", R"([{"mesh": "a"}])");
  expect_error(scene, scene + ": /meshes/0/file: " + path("folder.obj"), {"mesh file"});
}

TEST_F(MeshScene, MalformedObjNamesTheFile) {
  std::ofstream(path("bad.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n";  // a corner that does not exist
  const std::string scene = write_scene(R"([{"name": "a", "file": "bad.obj"}])", R"([{"mesh": "a"}])");
  expect_error(scene, scene + ": /meshes/0/file: " + path("bad.obj"), {"malformed OBJ: line 4: index 7 is out of range: the file has 3 vertex positions"});
}

TEST_F(MeshScene, ObjWithAMissingMtlNamesTheFile) {
  std::ofstream(path("mtl.obj")) << "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n";
  const std::string scene = write_scene(R"([{"name": "a", "file": "mtl.obj"}])", R"([{"mesh": "a"}])");
  expect_error(scene, scene + ": /meshes/0/file: " + path("mtl.obj"),
               {"mtllib nowhere.mtl: " + path("nowhere.mtl") + ": cannot open material library"});
}

// A mesh given by its own arrays (what the Python module passes for numpy arrays)
// is the mesh its OBJ file holds: the same triangles, normals and UVs (OBJ's v up),
// so the renders are bit for bit the same.
TEST_F(MeshScene, AMeshOfItsOwnArraysIsItsObj) {
  std::ofstream(path("quad.obj")) << "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                     "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";
  const std::string textures = R"("textures": [{"name": "t", "type": "image", "file": "t.png", "colorspace": "linear"}],)";
  {
    // A 2x2 image whose texels differ, so that a flipped v shows.
    const unsigned char px[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
    ASSERT_NE(stbi_write_png(path("t.png").c_str(), 2, 2, 4, px, 8), 0);
  }
  auto scene_with = [&](const std::string& mesh) {
    const std::string p = path("arrays.json");
    std::ofstream(p) << R"({"camera": {"look_from": [0, 0, 3], "look_at": [0, 0, 0]}, )" << textures
                     << R"("materials": [{"name": "m", "type": "lambertian", "texture": "t"}],
      "meshes": [)" << mesh << R"(], "instances": [{"mesh": "q"}]})";
    return load_scene(p);
  };
  const Scene from_file = scene_with(R"({"name": "q", "file": "quad.obj", "material": "m"})");
  const Scene from_arrays = scene_with(R"({"name": "q", "material": "m",
      "positions": [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], "indices": [[0, 1, 2], [0, 2, 3]],
      "normals": [[0, 0, 1], [0, 0, 1], [0, 0, 1], [0, 0, 1]], "uvs": [[0, 0], [1, 0], [1, 1], [0, 1]]})");
  RenderOptions o;
  o.backend = Backend::Cpu;
  o.params = RenderParams{16, 16, 2, 4, 4, 1};
  EXPECT_EQ(render(from_file, o).rgb, render(from_arrays, o).rgb);
  EXPECT_EQ(from_file.uvs.size(), from_arrays.uvs.size());
}

TEST_F(MeshScene, BadMeshArraysNameTheField) {
  auto expect = [&](const std::string& mesh, std::initializer_list<std::string> parts) {
    const std::string scene = write_scene("[" + mesh + "]", R"([{"mesh": "a"}])");
    expect_error(scene, scene, parts);
  };
  const std::string tri = R"("positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]])";
  expect({R"({"name": "a", )" + tri + "}"}, {"/meshes/0: a mesh given by \"positions\" needs \"indices\""});
  expect({R"({"name": "a", )" + tri + R"(, "indices": [[0, 1, 3]]})"}, {"/meshes/0/indices/0/2"});
  expect({R"({"name": "a", )" + tri + R"(, "indices": [[0, 1]]})"}, {"/meshes/0/indices/0: must be a row of 3 numbers"});
  expect({R"({"name": "a", )" + tri + R"(, "indices": [[0, 1, 2]], "normals": [[0, 0, 1]]})"},
         {"/meshes/0/normals: has 1 rows for 3 positions"});
  expect({R"({"name": "a", "file": "tri.obj", )" + tri + R"(, "indices": [[0, 1, 2]]})"},
         {"/meshes/0: give one of \"file\", \"shape\" or \"positions\""});
  expect({R"({"name": "a", "file": "tri.obj", "uvs": [[0, 0]]})"}, {"/meshes/0/uvs: belongs to a mesh given by \"positions\""});
  expect({R"({"name": "a", "positions": [[0, 0, 0], [1, 0, 0], [2, 0, 0]], "indices": [[0, 1, 2]]})"},
         {"/meshes/0/positions: mesh 'a'"});
}

TEST_F(MeshScene, UnknownMeshInAnInstance) {
  expect_instance_error(R"({"mesh": "nope"})", {"/instances/0/mesh", "unknown mesh 'nope'"});
}

TEST_F(MeshScene, UnknownMaterialOverrideOfAnInstance) {
  expect_instance_error(R"({"mesh": "tri", "material": "gold"})", {"/instances/0/material", "unknown material 'gold'"});
}

TEST_F(MeshScene, UnknownMaterialOverrideOfAMesh) {
  const std::string scene = write_scene(R"([{"name": "a", "file": "tri.obj", "material": "gold"}])", R"([{"mesh": "a"}])");
  expect_error(scene, scene, {"/meshes/0/material", "unknown material 'gold'"});
}

TEST_F(MeshScene, DuplicateMeshName) {
  const std::string scene = write_scene(R"([{"name": "a", "file": "tri.obj"}, {"name": "a", "file": "tri.obj"}])",
                                        R"([{"mesh": "a"}])");
  expect_error(scene, scene, {"/meshes/1/name", "duplicate mesh name 'a'", "/meshes/0"});
}

TEST_F(MeshScene, MatrixOfWrongLength) {
  expect_instance_error(R"({"mesh": "tri", "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0]})",
                        {"/instances/0/matrix", "16 numbers", "got 12"});
}

TEST_F(MeshScene, MatrixWithANonAffineLastRow) {
  expect_instance_error(R"({"mesh": "tri", "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0.5, 0, 1]})",
                        {"/instances/0/matrix", "last row must be 0 0 0 1"});
  expect_instance_error(R"({"mesh": "tri", "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 2]})",
                        {"/instances/0/matrix", "last row must be 0 0 0 1"});
}

TEST_F(MeshScene, MatrixTogetherWithTranslate) {
  expect_instance_error(
      R"({"mesh": "tri", "translate": [1, 0, 0], "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]})",
      {"/instances/0/translate", "cannot be given with 'matrix'"});
}

TEST_F(MeshScene, ZeroScale) {
  expect_instance_error(R"({"mesh": "tri", "scale": 0})", {"/instances/0/scale", "must not be zero"});
  expect_instance_error(R"({"mesh": "tri", "scale": [1, 0, 1]})", {"/instances/0/scale", "must not be zero"});
}

TEST_F(MeshScene, SingularMatrix) {
  // Rows 1 and 2 alike: the linear part has rank 2.
  expect_instance_error(R"({"mesh": "tri", "matrix": [1, 2, 3, 0, 1, 2, 3, 0, 0, 0, 1, 0, 0, 0, 0, 1]})",
                        {"/instances/0", "singular"});
}

TEST_F(MeshScene, ErrorInTheSecondInstanceNamesIt) {
  expect_instance_error(R"({"mesh": "tri"}, {"mesh": "tri", "scale": [2, 0, 1]})", {"/instances/1/scale"});
}

// ---- Through the command ----

// `wavetrace render` runs run_job and exits with its code (src/app/main.cpp).
TEST_F(MeshScene, RenderJobWithABadInstanceIsBadInputAndWritesNothing) {
  app::Job job;
  job.scene = write_scene(R"([{"name": "tri", "file": "tri.obj"}])", R"([{"mesh": "nope"}])");
  job.output = path("out.png");
  job.stats = path("stats.json");
  job.backend = "cpu";
  job.width = 8;
  job.height = 8;
  job.spp = 1;
  job.progress = false;
  const app::JobOutcome o = app::run_job(job);
  EXPECT_EQ(o.exit_code, app::kExitBadInput);
  EXPECT_NE(o.message.find(job.scene + ": /instances/0/mesh: unknown mesh 'nope'"), std::string::npos) << o.message;
  EXPECT_EQ(o.message.find('\n'), std::string::npos) << o.message;
  EXPECT_FALSE(fs::exists(job.output));
  EXPECT_FALSE(fs::exists(job.stats));
}

// The built program itself, where it stands beside this test binary (the build folder).
TEST_F(MeshScene, WavetraceRenderExitsWithTwoAndWritesNothing) {
  char self[PATH_MAX] = {};
  const ssize_t n = ::readlink("/proc/self/exe", self, sizeof self - 1);
  const fs::path program = n > 0 ? fs::path(std::string(self, n)).parent_path() / "wavetrace" : fs::path();
  if (program.empty() || !fs::exists(program)) GTEST_SKIP() << "no wavetrace program beside this test binary";
  const std::string scene = write_scene(R"([{"name": "tri", "file": "tri.obj"}])",
                                        R"([{"mesh": "tri", "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0]}])");
  const std::string out = path("out.png"), err = path("err.txt");
  const std::string command = "'" + program.string() + "' render '" + scene + "' -o '" + out +
                              "' --backend cpu --width 8 --height 8 --spp 1 2>'" + err + "' >/dev/null";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << command;
  EXPECT_EQ(WEXITSTATUS(status), 2) << command;
  EXPECT_FALSE(fs::exists(out));
  std::ifstream in(err);
  const std::string message((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(message.find(scene + ": /instances/0/matrix: must be an array of 16 numbers"), std::string::npos)
      << message;
  EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << "one line: " << message;
}

}  // namespace
}  // namespace wt

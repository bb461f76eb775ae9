// Mesh loading (src/scene/mesh_load.cpp): small OBJ, glTF and GLB files written
// here with known contents, each error, dropped triangles, and the real models of
// ../shared/models where that folder is present.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "scene/mesh_load.hpp"
#include "errors/errors.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"

// tinygltf's own encoder (compiled in src/scene/mesh_libraries.cpp), for embedded buffers.
namespace tinygltf {
std::string base64_encode(unsigned char const* bytes, unsigned int len);
}

namespace wt {
namespace {

class MeshLoad : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& text) {
    std::string path = (folder_.root() / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  // load_mesh must throw a InputError that starts with the file and contains `what`.
  void expect_error(const std::string& path, const std::string& what) {
    try {
      load_mesh(path);
      ADD_FAILURE() << path << " loaded; expected: " << what;
    } catch (const InputError& e) {
      std::string message = e.what();
      EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
      EXPECT_NE(message.find(what), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }

  // A triangle over the materials of MTL text `mtl` (the OBJ names the library and no
  // material: its face takes the default one, appended after the library's, which
  // are all kept in their order). Returns the OBJ's path.
  std::string mtl_obj(const std::string& mtl) {
    write("lib.mtl", mtl);
    return write("lib.obj", "mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  }
  TriangleMesh load_mtl(const std::string& mtl) { return load_mesh(mtl_obj(mtl)); }

  std::string at_root(const std::string& file) const { return (folder_.root() / file).string(); }

  test::TestFolder folder_;
};

// The mesh's material named `name` (nullptr, and a failure, where it has none).
const MeshMaterial* find(const TriangleMesh& m, const std::string& name) {
  for (const MeshMaterial& mm : m.materials) {
    if (mm.name == name) return &mm;
  }
  ADD_FAILURE() << "no material '" << name << "'";
  return nullptr;
}

void expect_vec(const vec3& got, const vec3& want) {
  EXPECT_FLOAT_EQ(got.x, want.x);
  EXPECT_FLOAT_EQ(got.y, want.y);
  EXPECT_FLOAT_EQ(got.z, want.z);
}

constexpr const char* kMtl = R"(newmtl matte
Kd 0.5 0.25 0.125
map_Kd tex/wood.png
newmtl steel
Kd 0 0 0
Ks 0.9 0.8 0.7
Ns 48
newmtl lacquer
Kd 0.2 0.3 0.4
Ks 0.5 0.5 0.5
Ni 1.4
newmtl glass
Kd 0 0 0
illum 7
Ni 1.33
newmtl lamp
Kd 0.5 0.5 0.5
Ke 4 3 2
)";

// A unit quad (two triangles through the library's triangulation) with normals and
// UVs, and one triangle per further material.
constexpr const char* kObj = R"(mtllib quad.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vn 0 0 2
vt 0 0
vt 1 0
vt 1 1
vt 0 1
usemtl matte
f 1/1/1 2/2/1 3/3/1 4/4/1
usemtl steel
f 1/1/1 2/2/1 3/3/1
usemtl lacquer
f 1/1/1 3/3/1 4/4/1
usemtl glass
f 1/1/1 2/2/1 4/4/1
usemtl lamp
f 2/2/1 3/3/1 4/4/1
)";

TEST_F(MeshLoad, ObjGivesPositionsNormalsUvsTrianglesAndMaterials) {
  write("quad.mtl", kMtl);
  const std::string path = write("quad.obj", kObj);
  TriangleMesh m = load_mesh(path);
  EXPECT_EQ(m.source, path);
  // One vertex per distinct (position, normal, uv) corner: the four of the quad, in
  // the order the library's triangulation reaches them. Here the file's uv is the
  // position's (x, y), read with v flipped (OBJ's v = 0 is the image's bottom row).
  ASSERT_EQ(m.positions.size(), 4u);
  ASSERT_EQ(m.normals.size(), 4u);
  ASSERT_EQ(m.uvs.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    expect_vec(m.normals[i], vec3(0, 0, 1));  // normalized
    EXPECT_EQ(m.positions[i].z, 0.0f);
    EXPECT_EQ(m.uvs[i].x, m.positions[i].x);
    EXPECT_EQ(m.uvs[i].y, 1.0f - m.positions[i].y);
  }
  ASSERT_EQ(m.triangles.size(), 6u);
  auto corners = [&](size_t t) {
    std::vector<vec3> c;
    for (uint32_t v : m.triangles[t]) c.push_back(m.positions[v]);
    return c;
  };
  // The quad's split is the library's: two triangles of area 1/2 each, together over the four corners.
  std::vector<int> seen(4, 0);
  for (size_t t = 0; t < 2; ++t) {
    std::vector<vec3> c = corners(t);
    EXPECT_FLOAT_EQ(glm::length(glm::cross(c[1] - c[0], c[2] - c[0])), 1.0f);
    for (uint32_t v : m.triangles[t]) ++seen[v];
  }
  for (int count : seen) EXPECT_GE(count, 1);
  const vec3 p1(0, 0, 0), p2(1, 0, 0), p3(1, 1, 0), p4(0, 1, 0);
  EXPECT_EQ(corners(2), (std::vector<vec3>{p1, p2, p3}));
  EXPECT_EQ(corners(3), (std::vector<vec3>{p1, p3, p4}));
  EXPECT_EQ(corners(4), (std::vector<vec3>{p1, p2, p4}));
  EXPECT_EQ(corners(5), (std::vector<vec3>{p2, p3, p4}));
  EXPECT_EQ(m.triangle_material, (std::vector<uint32_t>{0, 0, 1, 2, 3, 4}));
  EXPECT_EQ(m.dropped_degenerate, 0u);
  EXPECT_EQ(m.dropped_nan, 0u);

  ASSERT_EQ(m.materials.size(), 5u);
  const MeshMaterial& matte = m.materials[0];
  EXPECT_EQ(matte.name, "matte");
  EXPECT_EQ(matte.material.kind, MaterialKind::Lambertian);
  expect_vec(matte.material.albedo, vec3(0.5f, 0.25f, 0.125f));
  EXPECT_EQ(matte.albedo_map.image, (folder_.root() / "tex/wood.png").string());
  EXPECT_EQ(matte.material.texture, -1);

  const Material& steel = m.materials[1].material;
  EXPECT_EQ(steel.kind, MaterialKind::Metal);
  expect_vec(steel.albedo, vec3(0.9f, 0.8f, 0.7f));
  EXPECT_FLOAT_EQ(steel.fuzz, 0.2f);  // sqrt(2 / (48 + 2))

  const Material& lacquer = m.materials[2].material;
  EXPECT_EQ(lacquer.kind, MaterialKind::Coated);
  expect_vec(lacquer.albedo, vec3(0.2f, 0.3f, 0.4f));
  EXPECT_FLOAT_EQ(lacquer.ior, 1.4f);

  // A glass (illum 7 is refraction): principled, transmitting, white where Tf is not written.
  const MeshMaterial& glass = m.materials[3];
  EXPECT_EQ(glass.material.kind, MaterialKind::Principled);
  EXPECT_FLOAT_EQ(glass.material.ior, 1.33f);
  expect_vec(glass.material.albedo, vec3(1.0f));
  EXPECT_EQ(glass.transmission, 1.0f);

  const Material& lamp = m.materials[4].material;
  EXPECT_EQ(lamp.kind, MaterialKind::Emissive);
  expect_vec(lamp.emission, vec3(4, 3, 2));
  for (const MeshMaterial& mm : m.materials) {
    EXPECT_EQ(mm.material.sort_key, material_sort_key(mm.material.kind, -1)) << mm.name;
    EXPECT_EQ(mm.alpha_mode, 0u) << mm.name;
  }
  EXPECT_TRUE(m.warnings.empty());
}

TEST_F(MeshLoad, ObjWithoutMaterialsNormalsOrUvsGetsTheDefaultMaterial) {
  const std::string path = write("plain.obj", "v 0 0 0\nv 2 0 0\nv 0 3 0\nf 1 2 3\n");
  TriangleMesh m = load_mesh(path);
  EXPECT_TRUE(m.normals.empty());
  EXPECT_TRUE(m.uvs.empty());
  ASSERT_EQ(m.triangles.size(), 1u);
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "default");
  EXPECT_EQ(m.materials[0].material.kind, MaterialKind::Lambertian);
  expect_vec(m.materials[0].material.albedo, vec3(1.0f));
  EXPECT_EQ(m.triangle_material, std::vector<uint32_t>{0});
}

TEST_F(MeshLoad, ObjDropsAndCountsDegenerateTriangles) {
  // A good triangle, one with a repeated corner, one of collinear corners, a
  // two-corner face.
  const std::string path = write("degenerate.obj",
                                 "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n"
                                 "f 1 2 3\nf 1 2 2\nf 1 2 4\nf 1 2\n");
  TriangleMesh m = load_mesh(path);
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.dropped_degenerate, 3u);
  EXPECT_EQ(m.dropped_nan, 0u);
}

TEST_F(MeshLoad, ObjErrorsNameTheFileAndTheProblem) {
  expect_error((folder_.root() / "missing.obj").string(), "cannot open mesh file (No such file or directory)");
  expect_error(write("mesh.stl", "solid\n"), "unknown mesh format '.stl' (expected .obj, .gltf, .glb, .ply, .serialized)");
  expect_error(write("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"), "malformed OBJ: line 4: ");
  expect_error(write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"), "out of");
  expect_error(write("empty.obj", "# nothing\nv 0 0 0\n"), "has no triangles");
  expect_error(write("flat.obj", "v 0 0 0\nv 1 0 0\nf 1 2 2\n"), "no triangles left (1 degenerate and 0 non-finite dropped)");
  expect_error(write("nomtl.obj", "mtllib absent.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
               "mtllib absent.mtl: " + (folder_.root() / "absent.mtl").string() +
                   ": cannot open material library (No such file or directory)");
  write("one.mtl", "newmtl known\nKd 1 1 1\n");
  expect_error(write("unknown.obj", "mtllib one.mtl\nusemtl nosuch\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
               "malformed OBJ: material [ 'nosuch' ] not found in .mtl");
  write("bright.mtl", "newmtl bright\nKd 1.5 1 1\n");
  expect_error(write("bright.obj", "mtllib bright.mtl\nusemtl bright\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
               "material 'bright': Kd must be 3 numbers in [0, 1]");
}

// ---- MTL materials ----

// The PBR extension's values reach the principled material's fields; Kd is the base
// colour and Ni the index.
TEST_F(MeshLoad, MtlPbrKeysMakeAPrincipledMaterialWithTheirValues) {
  const TriangleMesh m = load_mtl(R"(newmtl brushed
Kd 0.8 0.6 0.4
Ks 0.5 0.5 0.5
Ns 200
Ni 1.6
Pr 0.35
Pm 0.75
Pc 0.5
Pcr 0.125
aniso 0.25
)");
  ASSERT_EQ(m.materials.size(), 2u);  // and the default
  const MeshMaterial& mm = m.materials[0];
  EXPECT_EQ(mm.name, "brushed");
  EXPECT_EQ(mm.material.kind, MaterialKind::Principled);
  expect_vec(mm.material.albedo, vec3(0.8f, 0.6f, 0.4f));
  EXPECT_FLOAT_EQ(mm.material.ior, 1.6f);
  EXPECT_TRUE(mm.material.flags & kMaterialCompensated);
  EXPECT_FALSE(mm.material.flags & kMaterialOneSided);
  EXPECT_EQ(mm.material.sort_key, material_sort_key(MaterialKind::Principled, -1));
  EXPECT_FLOAT_EQ(mm.roughness, 0.35f);
  EXPECT_FLOAT_EQ(mm.metallic, 0.75f);
  EXPECT_FLOAT_EQ(mm.clearcoat, 0.5f);
  EXPECT_FLOAT_EQ(mm.clearcoat_roughness, 0.125f);
  EXPECT_FLOAT_EQ(mm.anisotropy, 0.25f);
  EXPECT_FLOAT_EQ(mm.specular, 1.0f);
  EXPECT_EQ(mm.transmission, 0.0f);
  EXPECT_TRUE(mm.albedo_map.empty());
  EXPECT_TRUE(mm.normal_map.empty());
  EXPECT_EQ(mm.alpha_mode, 0u);
  EXPECT_TRUE(m.warnings.empty());
}

// Whether a material is PBR is whether it writes a PBR key, not whether the value
// differs from tinyobjloader's default: Pr 0 is a smooth principled surface. Where Pr
// is not written the surface is matte (roughness 1).
TEST_F(MeshLoad, MtlPbrKeyWrittenAsZeroStillMakesAPrincipledMaterial) {
  const TriangleMesh m = load_mtl("newmtl smooth\nKd 0.5 0.5 0.5\nPr 0\nnewmtl metal\nKd 0.9 0.9 0.9\nPm 1\n"
                                  "newmtl plain\nKd 0.5 0.5 0.5\n");
  const MeshMaterial* smooth = find(m, "smooth");
  const MeshMaterial* metal = find(m, "metal");
  const MeshMaterial* plain = find(m, "plain");
  ASSERT_TRUE(smooth && metal && plain);
  EXPECT_EQ(smooth->material.kind, MaterialKind::Principled);
  EXPECT_EQ(smooth->roughness, 0.0f);
  EXPECT_EQ(smooth->metallic, 0.0f);
  EXPECT_EQ(metal->material.kind, MaterialKind::Principled);
  EXPECT_EQ(metal->roughness, 1.0f);
  EXPECT_EQ(metal->metallic, 1.0f);
  EXPECT_EQ(plain->material.kind, MaterialKind::Lambertian);
}

// map_Kd (sRGB base colour), map_Pr, map_Pm and norm are files resolved against the
// mesh's folder; a map written without its value scales 1 (the map alone).
TEST_F(MeshLoad, MtlPbrMapsAreFilesBesideTheMesh) {
  const TriangleMesh m = load_mtl(R"(newmtl painted
map_Kd maps/base.png
map_Pr maps/rough.png
map_Pm maps/metal.png
norm -bm 0.5 maps/normal.png
newmtl scaled
Kd 0.5 0.5 0.5
Pr 0.5
Pm 0.25
map_Pr r.png
map_Pm m.png
)");
  const MeshMaterial* painted = find(m, "painted");
  const MeshMaterial* scaled = find(m, "scaled");
  ASSERT_TRUE(painted && scaled);
  EXPECT_EQ(painted->material.kind, MaterialKind::Principled);
  EXPECT_EQ(painted->albedo_map.image, at_root("maps/base.png"));
  EXPECT_EQ(painted->roughness_map.image, at_root("maps/rough.png"));
  EXPECT_EQ(painted->metallic_map.image, at_root("maps/metal.png"));
  EXPECT_EQ(painted->normal_map.image, at_root("maps/normal.png"));
  EXPECT_FLOAT_EQ(painted->normal_scale, 0.5f);
  expect_vec(painted->material.albedo, vec3(1.0f));  // not tinyobjloader's 0.6 under a map_Kd
  EXPECT_EQ(painted->roughness, 1.0f);
  EXPECT_EQ(painted->metallic, 1.0f);
  EXPECT_EQ(painted->material.texture, -1);
  // Written with their maps, the values scale them.
  EXPECT_FLOAT_EQ(scaled->roughness, 0.5f);
  EXPECT_FLOAT_EQ(scaled->metallic, 0.25f);
  EXPECT_EQ(scaled->roughness_map.image, at_root("r.png"));
  EXPECT_EQ(scaled->metallic_map.image, at_root("m.png"));
  EXPECT_TRUE(scaled->albedo_map.empty());
  EXPECT_TRUE(m.warnings.empty());
}

// MTL's bump map, in any material but an emitter: heights times -bm (which may be
// negative), of the channel -imfchan names (luminance by default), which the scene
// reads as a normal map where its texels are one's and no channel is named
// (bump_map_test.cpp); norm wins over a bump map.
TEST_F(MeshLoad, MtlBumpMapIsReadWithBmItsScale) {
  const TriangleMesh m = load_mtl(R"(newmtl pbr
Kd 0.5 0.5 0.5
Pr 0.5
map_Bump -bm 0.3 tex/normal.png
newmtl classic
Kd 0.5 0.5 0.5
bump -bm -2 tex/height.png
newmtl red
Kd 0.5 0.5 0.5
map_bump -imfchan r tex/rgb.png
newmtl both
Pr 0.5
norm tex/n.png
bump tex/h.png
newmtl lamp
Ke 1 1 1
bump tex/h.png
)");
  const MeshMaterial* pbr = find(m, "pbr");
  const MeshMaterial* classic = find(m, "classic");
  const MeshMaterial* red = find(m, "red");
  const MeshMaterial* both = find(m, "both");
  const MeshMaterial* lamp = find(m, "lamp");
  ASSERT_TRUE(pbr && classic && red && both && lamp);
  EXPECT_TRUE(pbr->normal_map.empty());
  EXPECT_EQ(pbr->bump_map.image, at_root("tex/normal.png"));
  EXPECT_FLOAT_EQ(pbr->bump_scale, 0.3f);
  EXPECT_EQ(pbr->bump_channel, 'l');
  EXPECT_TRUE(pbr->bump_may_be_normal_map());
  EXPECT_EQ(classic->material.kind, MaterialKind::Lambertian);
  EXPECT_EQ(classic->bump_map.image, at_root("tex/height.png"));
  EXPECT_FLOAT_EQ(classic->bump_scale, -2.0f);
  EXPECT_EQ(red->bump_channel, 'r');
  EXPECT_FALSE(red->bump_may_be_normal_map());
  EXPECT_EQ(both->normal_map.image, at_root("tex/n.png"));
  EXPECT_FLOAT_EQ(both->normal_scale, 1.0f);
  EXPECT_TRUE(both->bump_map.empty());
  EXPECT_TRUE(lamp->bump_map.empty());
  ASSERT_EQ(m.warnings.size(), 2u);
  EXPECT_NE(m.warnings[0].find("material 'both': its bump map is not read: norm gives its normal map"), std::string::npos)
      << m.warnings[0];
  EXPECT_NE(m.warnings[1].find("material 'lamp': bump is not read: an emitter is not shaded"), std::string::npos)
      << m.warnings[1];
}

// MTL's dissolve is coverage: d (or 1 - Tr) times map_d's A channel, as alpha BLEND,
// whatever the material's kind; d 1 without a map is opaque.
TEST_F(MeshLoad, MtlDissolveAndMapDAreAlphaBlend) {
  const TriangleMesh m = load_mtl(R"(newmtl veil
Kd 0.5 0.5 0.5
d 0.25
newmtl leaf
Kd 0.2 0.6 0.1
d 0.5
map_d leaf_alpha.png
newmtl tr
Kd 0.5 0.5 0.5
Tr 0.75
newmtl solid
Kd 0.5 0.5 0.5
d 1
)");
  const MeshMaterial* veil = find(m, "veil");
  const MeshMaterial* leaf = find(m, "leaf");
  const MeshMaterial* tr = find(m, "tr");
  const MeshMaterial* solid = find(m, "solid");
  ASSERT_TRUE(veil && leaf && tr && solid);
  EXPECT_EQ(veil->material.kind, MaterialKind::Lambertian);  // not a glass
  EXPECT_EQ(veil->alpha_mode, static_cast<uint32_t>(AlphaMode::Blend));
  EXPECT_FLOAT_EQ(veil->alpha_factor, 0.25f);
  EXPECT_TRUE(veil->alpha_map.empty());
  EXPECT_EQ(leaf->alpha_mode, static_cast<uint32_t>(AlphaMode::Blend));
  EXPECT_FLOAT_EQ(leaf->alpha_factor, 0.5f);
  EXPECT_EQ(leaf->alpha_map.image, at_root("leaf_alpha.png"));
  EXPECT_EQ(tr->alpha_mode, static_cast<uint32_t>(AlphaMode::Blend));
  EXPECT_FLOAT_EQ(tr->alpha_factor, 0.25f);
  EXPECT_EQ(solid->alpha_mode, 0u);
  EXPECT_TRUE(m.warnings.empty());
}

// Tf (with no illum written) or an illumination model with refraction (4, 6, 7, 9)
// is a principled glass: transmitting, a volume refracting at Ni, tinted by Tf,
// smooth unless Pr says otherwise. Tf under a model without refraction is not read.
TEST_F(MeshLoad, MtlTransmissionFilterOrRefractingIllumIsAPrincipledGlass) {
  const TriangleMesh m = load_mtl(R"(newmtl tinted
Kd 0.1 0.1 0.1
Tf 0.9 0.8 0.7
Ni 1.33
newmtl clear
illum 7
newmtl frosted
illum 4
Ni 1.45
Pr 0.2
newmtl opaque
Kd 0.5 0.5 0.5
Tf 1 1 1
illum 2
)");
  const MeshMaterial* tinted = find(m, "tinted");
  const MeshMaterial* clear = find(m, "clear");
  const MeshMaterial* frosted = find(m, "frosted");
  const MeshMaterial* opaque = find(m, "opaque");
  ASSERT_TRUE(tinted && clear && frosted && opaque);
  for (const MeshMaterial* glass : {tinted, clear, frosted}) {
    EXPECT_EQ(glass->material.kind, MaterialKind::Principled) << glass->name;
    EXPECT_EQ(glass->transmission, 1.0f) << glass->name;
    EXPECT_FALSE(glass->thin) << glass->name;
    EXPECT_EQ(glass->metallic, 0.0f) << glass->name;
  }
  expect_vec(tinted->material.albedo, vec3(0.9f, 0.8f, 0.7f));
  EXPECT_FLOAT_EQ(tinted->material.ior, 1.33f);
  EXPECT_EQ(tinted->roughness, 0.0f);
  expect_vec(clear->material.albedo, vec3(1.0f));
  EXPECT_FLOAT_EQ(clear->material.ior, 1.5f);  // Ni not written
  EXPECT_FLOAT_EQ(frosted->roughness, 0.2f);
  EXPECT_FLOAT_EQ(frosted->material.ior, 1.45f);
  EXPECT_EQ(opaque->material.kind, MaterialKind::Lambertian);
  EXPECT_EQ(opaque->transmission, 0.0f);
}

// Each key that is read and not rendered gives one warning line naming the
// library, the material and the key.
TEST_F(MeshLoad, MtlSheenAnisotropyRotationAndSpecularMapsAreWarnedOfOnceEach) {
  const TriangleMesh m = load_mtl(R"(newmtl velvet
Kd 0.5 0.1 0.1
Pr 0.8
Ps 0.5
map_Ps sheen.png
anisor 0.25
newmtl phong
Kd 0.5 0.5 0.5
Ks 0.2 0.2 0.2
map_Ks spec.png
map_Ns gloss.png
)");
  const std::vector<std::string> want = {
      "mtllib lib.mtl: material 'velvet': Ps (sheen) is not rendered",
      "mtllib lib.mtl: material 'velvet': map_Ps (sheen) is not rendered",
      "mtllib lib.mtl: material 'velvet': anisor (anisotropy rotation) is not rendered",
      "mtllib lib.mtl: material 'phong': map_Ks is not read",
      "mtllib lib.mtl: material 'phong': map_Ns is not read",
  };
  ASSERT_EQ(m.warnings.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(m.warnings[i].rfind(want[i], 0), 0u) << m.warnings[i];
    EXPECT_EQ(m.warnings[i].find('\n'), std::string::npos) << m.warnings[i];
  }
  // What is read of them still is: velvet is principled, phong keeps its classic kind.
  EXPECT_EQ(m.materials[0].material.kind, MaterialKind::Principled);
  EXPECT_FLOAT_EQ(m.materials[0].roughness, 0.8f);
  EXPECT_EQ(m.materials[1].material.kind, MaterialKind::Coated);
}

// The renderer reads roughness from G, metallic from B and coverage from A: an
// -imfchan that names another channel is warned of (b for metallic is the one read).
TEST_F(MeshLoad, MtlImfchanOtherThanTheChannelReadIsWarnedOf) {
  const TriangleMesh m = load_mtl(R"(newmtl orm
Pr 1
map_Pr -imfchan r orm.png
map_Pm -imfchan b orm.png
map_d -imfchan l mask.png
)");
  ASSERT_EQ(m.warnings.size(), 2u);
  EXPECT_EQ(m.warnings[0],
            "mtllib lib.mtl: material 'orm': map_Pr -imfchan r is not honoured: its roughness is read from the image's "
            "G channel");
  EXPECT_EQ(m.warnings[1],
            "mtllib lib.mtl: material 'orm': map_d -imfchan l is not honoured: its coverage is read from the image's "
            "A channel");
  EXPECT_EQ(m.materials[0].metallic_map.image, at_root("orm.png"));
  EXPECT_EQ(m.materials[0].alpha_map.image, at_root("mask.png"));
}

// Every bad value is one error naming the file, the library, the material and the key.
TEST_F(MeshLoad, MtlValuesOutOfRangeAreRefused) {
  const std::pair<const char*, const char*> cases[] = {
      {"Pr 1.5", "Pr must be a number in [0, 1]"},
      {"Pr rough", "Pr must be a number in [0, 1]"},
      {"Pm -0.1", "Pm must be a number in [0, 1]"},
      {"Pc -1", "Pc must be a number in [0, 1]"},
      {"Pcr 2", "Pcr must be a number in [0, 1]"},
      {"aniso 3", "aniso must be a number in [0, 1]"},
      {"Pr 0.5\nnorm -bm -1 n.png", "norm -bm must be in [0, 1000]"},
      {"Pr 0.5\nmap_Bump -bm 2000 n.png", "map_Bump -bm must be in [-1000, 1000]"},
      {"map_Pr -bm 1", "map_Pr names no image"},
      {"Tf 1.5 1 1", "Tf must be 3 numbers in [0, 1]"},
      {"d -halo 0.5", "d must be a number in [0, 1]"},
      {"Tr 2", "Tr must be a number in [0, 1]"},
      {"Ni 0", "Ni must be a number > 0"},
      {"Ns -1", "Ns must be a number >= 0"},
      {"illum 12", "illum must be a number in [0, 10]"},
  };
  for (const auto& [line, message] : cases) {
    expect_error(mtl_obj(std::string("newmtl bad\nKd 0.5 0.5 0.5\n") + line + "\n"),
                 std::string("mtllib lib.mtl: material 'bad': ") + message);
  }
}

// An emitter's texture is map_Ke (Ke times it); map_Kd stays unread on it, as before.
TEST_F(MeshLoad, MtlEmitterTakesMapKeAsItsTexture) {
  const TriangleMesh m = load_mtl("newmtl screen\nKe 2 2 2\nmap_Kd base.png\nmap_Ke glow.png\n");
  ASSERT_EQ(m.materials[0].material.kind, MaterialKind::Emissive);
  expect_vec(m.materials[0].material.emission, vec3(2.0f));
  EXPECT_EQ(m.materials[0].albedo_map.image, at_root("glow.png"));
  EXPECT_TRUE(m.warnings.empty());
}

// The shipped scenes' materials and the references' (whose golden images and
// converged references were rendered with them) load as they always have.
TEST_F(MeshLoad, MtlShippedMaterialsAreUnchanged) {
  struct Want {
    const char* name;
    MaterialKind kind;
    vec3 albedo, emission;
  };
  const std::vector<Want> cornell = {
      {"white", MaterialKind::Lambertian, vec3(0.73f), vec3(0.0f)},
      {"red", MaterialKind::Lambertian, vec3(0.65f, 0.05f, 0.05f), vec3(0.0f)},
      {"green", MaterialKind::Lambertian, vec3(0.12f, 0.45f, 0.15f), vec3(0.0f)},
      {"light", MaterialKind::Emissive, vec3(0.0f), vec3(17.0f, 12.0f, 4.0f)},
  };
  const std::vector<Want> room = {
      {"white", MaterialKind::Lambertian, vec3(0.75f, 0.75f, 0.72f), vec3(0.0f)},
      {"red", MaterialKind::Lambertian, vec3(0.7f, 0.08f, 0.06f), vec3(0.0f)},
      {"green", MaterialKind::Lambertian, vec3(0.12f, 0.5f, 0.15f), vec3(0.0f)},
      {"lamp", MaterialKind::Emissive, vec3(0.0f), vec3(12.0f, 10.0f, 7.0f)},
  };
  const std::vector<Want> quad = {{"picture", MaterialKind::Lambertian, vec3(1.0f), vec3(0.0f)}};
  const std::pair<const char*, const std::vector<Want>*> files[] = {
      {"scenes/cornell-box.obj", &cornell},
      {"scenes/cornell-materials-room.obj", &cornell},
      {"tests/data/references/room.obj", &room},
      {"tests/data/references/textured-quad.obj", &quad},
  };
  for (const auto& [file, want] : files) {
    const TriangleMesh m = load_mesh(test::repo_path(file));
    EXPECT_TRUE(m.warnings.empty()) << file;
    for (const Want& w : *want) {
      const MeshMaterial* mm = find(m, w.name);
      ASSERT_TRUE(mm) << file;
      const Material& got = mm->material;
      EXPECT_EQ(got.kind, w.kind) << file << " " << w.name;
      expect_vec(got.albedo, w.albedo);
      expect_vec(got.emission, w.emission);
      EXPECT_EQ(got.texture, -1) << file << " " << w.name;
      EXPECT_EQ(got.fuzz, 0.0f) << file << " " << w.name;
      EXPECT_EQ(got.ior, 1.0f) << file << " " << w.name;
      EXPECT_EQ(got.flags, 0u) << file << " " << w.name;
      EXPECT_EQ(got.sort_key, material_sort_key(w.kind, -1)) << file << " " << w.name;
      EXPECT_EQ(mm->alpha_mode, 0u) << file << " " << w.name;
      EXPECT_TRUE(mm->normal_map.empty()) << file << " " << w.name;
      EXPECT_EQ(mm->albedo_map.empty(), std::string(w.name) != "picture") << file << " " << w.name;
    }
  }
}

// ---- glTF ----

// The binary buffer of a test glTF: positions, normals and UVs of `n` vertices, then
// the indices as unsigned shorts.
struct Buffer {
  std::string bytes;
  template <typename T>
  size_t add(const std::vector<T>& values) {
    size_t offset = bytes.size();
    bytes.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
    while (bytes.size() % 4) bytes.push_back('\0');
    return offset;
  }
};

// A glTF document over `buffer` (given as `buffer_json`): vertices with normals and
// UVs, an unsigned-short index list, a node translated by (10, 20, 30), one
// material. `indices` counts the indices.
std::string gltf_json(const std::string& buffer_json, size_t buffer_size, size_t vertices, size_t indices,
                      const std::string& material) {
  const size_t p = 0, n = vertices * 12, t = vertices * 24, i = vertices * 32;
  auto view = [](size_t offset, size_t length) {
    return "{\"buffer\": 0, \"byteOffset\": " + std::to_string(offset) + ", \"byteLength\": " +
           std::to_string(length) + "}";
  };
  auto accessor = [](int view_index, size_t count, int component, const char* type) {
    return "{\"bufferView\": " + std::to_string(view_index) + ", \"componentType\": " + std::to_string(component) +
           ", \"count\": " + std::to_string(count) + ", \"type\": \"" + type + "\"}";
  };
  return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0, "translation": [10, 20, 30]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
  "materials": [)" + material + R"(],
  "buffers": [)" + buffer_json + R"(],
  "bufferViews": [)" + view(p, n - p) + ", " + view(n, t - n) + ", " + view(t, i - t) + ", " +
         view(i, buffer_size - i) + R"(],
  "accessors": [)" + accessor(0, vertices, 5126, "VEC3") + ", " + accessor(1, vertices, 5126, "VEC3") + ", " +
         accessor(2, vertices, 5126, "VEC2") + ", " + accessor(3, indices, 5123, "SCALAR") + "]}";
}

struct TestGltf {
  std::vector<float> positions, normals, uvs;
  std::vector<uint16_t> indices;
  std::string material = R"({"name": "brass", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1, 0.5],
    "metallicFactor": 1, "roughnessFactor": 0.25}})";
  Buffer buffer() const {
    Buffer b;
    b.add(positions);
    b.add(normals);
    b.add(uvs);
    b.add(indices);
    return b;
  }
  std::string embedded() const {
    Buffer b = buffer();
    std::string uri = "data:application/octet-stream;base64," +
                      tinygltf::base64_encode(reinterpret_cast<const unsigned char*>(b.bytes.data()),
                                              static_cast<unsigned>(b.bytes.size()));
    std::string buffer_json = "{\"byteLength\": " + std::to_string(b.bytes.size()) + ", \"uri\": \"" + uri + "\"}";
    return gltf_json(buffer_json, b.bytes.size(), positions.size() / 3, indices.size(), material);
  }
  // The GLB container: a 12-byte header, the JSON chunk (padded with spaces), the BIN chunk.
  std::string binary() const {
    Buffer b = buffer();
    std::string json = gltf_json("{\"byteLength\": " + std::to_string(b.bytes.size()) + "}", b.bytes.size(),
                                 positions.size() / 3, indices.size(), material);
    while (json.size() % 4) json.push_back(' ');
    auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    std::string out = "glTF" + u32(2) + u32(static_cast<uint32_t>(12 + 8 + json.size() + 8 + b.bytes.size()));
    out += u32(static_cast<uint32_t>(json.size())) + "JSON" + json;
    out += u32(static_cast<uint32_t>(b.bytes.size())) + "BIN" + std::string(1, '\0') + b.bytes;
    return out;
  }
};

// A unit quad in z = 0 as two indexed triangles, normals along +z (given scaled).
TestGltf quad() {
  TestGltf g;
  g.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  g.normals = {0, 0, 3, 0, 0, 3, 0, 0, 3, 0, 0, 3};
  g.uvs = {0, 0, 1, 0, 1, 1, 0, 0.25f};
  g.indices = {0, 1, 2, 0, 2, 3};
  return g;
}

void expect_quad(const TriangleMesh& m) {
  ASSERT_EQ(m.positions.size(), 4u);
  ASSERT_EQ(m.normals.size(), 4u);
  ASSERT_EQ(m.uvs.size(), 4u);
  const vec3 corners[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const float v[4] = {0, 0, 1, 0.25f};  // glTF's v as the file has it
  for (size_t i = 0; i < 4; ++i) {
    expect_vec(m.positions[i], corners[i] + vec3(10, 20, 30));  // the node's translation
    expect_vec(m.normals[i], vec3(0, 0, 1));
    EXPECT_FLOAT_EQ(m.uvs[i].x, corners[i].x);
    EXPECT_FLOAT_EQ(m.uvs[i].y, v[i]);
  }
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.triangles[0], (std::array<uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(m.triangles[1], (std::array<uint32_t, 3>{0, 2, 3}));
  EXPECT_EQ(m.triangle_material, (std::vector<uint32_t>{0, 0}));
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "brass");
  EXPECT_EQ(m.materials[0].material.kind, MaterialKind::Principled);
  expect_vec(m.materials[0].material.albedo, vec3(0.5f, 0.25f, 1.0f));
  EXPECT_FLOAT_EQ(m.materials[0].roughness, 0.25f);
}

TEST_F(MeshLoad, GltfWithAnEmbeddedBuffer) { expect_quad(load_mesh(write("quad.gltf", quad().embedded()))); }

TEST_F(MeshLoad, Glb) { expect_quad(load_mesh(write("quad.glb", quad().binary()))); }

// Every non-emissive glTF material is `principled` with the file's factors; an
// emissive one an emitter of emissiveFactor times KHR_materials_emissive_strength.
TEST_F(MeshLoad, GltfMaterialsAreThePrincipledKindWithTheirFactors) {
  struct Case {
    std::string material;
    MaterialKind kind;
    vec3 albedo, emission;
    float ior, metallic, roughness;
    bool one_sided;
  };
  const Case cases[] = {
      {R"({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0, "roughnessFactor": 0.9}})",
       MaterialKind::Principled, vec3(0.5f), vec3(0.0f), 1.5f, 0.0f, 0.9f, true},
      {R"({"pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.2, 0.3, 1], "metallicFactor": 0.2, "roughnessFactor": 0.1},
           "doubleSided": true, "extensions": {"KHR_materials_ior": {"ior": 1.7}}})",
       MaterialKind::Principled, vec3(0.1f, 0.2f, 0.3f), vec3(0.0f), 1.7f, 0.2f, 0.1f, false},
      {R"({"emissiveFactor": [1, 0.5, 0], "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}})",
       MaterialKind::Emissive, vec3(0.0f), vec3(1.0f, 0.5f, 0.0f), 1.0f, 0.0f, 1.0f, false},
      {R"({"emissiveFactor": [1, 0.5, 0], "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]},
           "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}}})",
       MaterialKind::Emissive, vec3(0.0f), vec3(4.0f, 2.0f, 0.0f), 1.0f, 0.0f, 1.0f, false},
      // A base that reflects: principled, and it emits too.
      {R"({"emissiveFactor": [1, 0.5, 0], "pbrMetallicRoughness": {"metallicFactor": 0}})", MaterialKind::Principled,
       vec3(1.0f), vec3(1.0f, 0.5f, 0.0f), 1.5f, 0.0f, 1.0f, true},
      // glTF's default: metallic 1, roughness 1, single-sided.
      {R"({})", MaterialKind::Principled, vec3(1.0f), vec3(0.0f), 1.5f, 1.0f, 1.0f, true},
  };
  for (const Case& c : cases) {
    TestGltf g = quad();
    g.material = c.material;
    TriangleMesh m = load_mesh(write("material.gltf", g.embedded()));
    ASSERT_EQ(m.materials.size(), 1u) << c.material;
    const MeshMaterial& mm = m.materials[0];
    const Material& got = mm.material;
    EXPECT_EQ(mm.name, "material 0");
    EXPECT_EQ(got.kind, c.kind) << c.material;
    expect_vec(got.albedo, c.albedo);
    expect_vec(got.emission, c.emission);
    EXPECT_FLOAT_EQ(got.ior, c.ior) << c.material;
    if (c.kind != MaterialKind::Principled) continue;
    EXPECT_FLOAT_EQ(mm.metallic, c.metallic) << c.material;
    EXPECT_FLOAT_EQ(mm.roughness, c.roughness) << c.material;
    EXPECT_EQ((got.flags & kMaterialOneSided) != 0, c.one_sided) << c.material;
    EXPECT_TRUE(got.flags & kMaterialCompensated);
    EXPECT_EQ((got.flags & kMaterialEmits) != 0, c.emission.x > 0.0f) << c.material;
  }
}

// KHR_materials_clearcoat, _transmission and _volume reach the material's layers;
// a texture of each is read with its texCoord and KHR_texture_transform.
TEST_F(MeshLoad, GltfCoatTransmissionAndVolumeReachTheMaterial) {
  TestGltf g = quad();
  g.material = R"({"extensions": {
      "KHR_materials_clearcoat": {"clearcoatFactor": 0.8, "clearcoatRoughnessFactor": 0.3,
        "clearcoatTexture": {"index": 0}, "clearcoatRoughnessTexture": {"index": 0},
        "clearcoatNormalTexture": {"index": 1, "scale": 0.5}},
      "KHR_materials_transmission": {"transmissionFactor": 0.9,
        "transmissionTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [2, 2]}}}},
      "KHR_materials_volume": {"thicknessFactor": 0.2, "attenuationDistance": 0.5, "attenuationColor": [0.9, 0.5, 0.1]},
      "KHR_materials_ior": {"ior": 1.4}}}],
    "textures": [{"source": 0}, {"source": 1}], "images": [{"uri": "coat.png"}, {"uri": "n.png"}], "samplers": [{})";
  const MeshMaterial mm = load_mesh(write("layers.gltf", g.embedded())).materials.at(0);
  EXPECT_EQ(mm.material.kind, MaterialKind::Principled);
  EXPECT_FLOAT_EQ(mm.clearcoat, 0.8f);
  EXPECT_FLOAT_EQ(mm.clearcoat_roughness, 0.3f);
  EXPECT_EQ(mm.clearcoat_map.image, (folder_.root() / "coat.png").string());
  EXPECT_EQ(mm.clearcoat_roughness_map.image, mm.clearcoat_map.image);
  EXPECT_EQ(mm.clearcoat_normal_map.image, (folder_.root() / "n.png").string());
  EXPECT_FLOAT_EQ(mm.clearcoat_normal_scale, 0.5f);
  EXPECT_FLOAT_EQ(mm.transmission, 0.9f);
  EXPECT_EQ(mm.transmission_map.image, mm.clearcoat_map.image);
  EXPECT_FLOAT_EQ(mm.transmission_map.uv_scale.x, 2.0f);
  EXPECT_FALSE(mm.thin);
  EXPECT_FLOAT_EQ(mm.attenuation_distance, 0.5f);
  expect_vec(mm.attenuation_color, vec3(0.9f, 0.5f, 0.1f));
  EXPECT_FLOAT_EQ(mm.material.ior, 1.4f);
  // No volume (thickness 0, the default): a thin wall.
  g.material = R"({"extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}}})";
  const MeshMaterial thin = load_mesh(write("thin.gltf", g.embedded())).materials.at(0);
  EXPECT_TRUE(thin.thin);
  EXPECT_FLOAT_EQ(thin.transmission, 1.0f);
  EXPECT_FLOAT_EQ(thin.clearcoat, 0.0f);
}

TEST_F(MeshLoad, GltfSpecularColourAndTexturesReachTheMaterial) {
  TestGltf g = quad();
  g.material = R"({"extensions": {"KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [1, 0.8, 2],
      "specularTexture": {"index": 0}, "specularColorTexture": {"index": 1}}}}],
    "textures": [{"source": 0}, {"source": 1}], "images": [{"uri": "s.png"}, {"uri": "c.png"}], "samplers": [{})";
  TriangleMesh m = load_mesh(write("specular.gltf", g.embedded()));
  const MeshMaterial& mm = m.materials.at(0);
  EXPECT_FLOAT_EQ(mm.specular, 0.5f);
  expect_vec(mm.specular_color, vec3(1.0f, 0.8f, 2.0f));
  EXPECT_EQ(mm.specular_map.image, (folder_.root() / "s.png").string());
  EXPECT_EQ(mm.specular_color_map.image, (folder_.root() / "c.png").string());
  EXPECT_TRUE(m.warnings.empty()) << m.warnings.front();
}

TEST_F(MeshLoad, GltfLayerFieldsOutOfRangeAreRefused) {
  const std::pair<const char*, const char*> cases[] = {
      {R"({"extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1.5}}})",
       "KHR_materials_clearcoat clearcoatFactor must be in [0, 1]"},
      {R"({"extensions": {"KHR_materials_clearcoat": {"clearcoatRoughnessFactor": -0.1}}})",
       "KHR_materials_clearcoat clearcoatRoughnessFactor must be in [0, 1]"},
      {R"({"extensions": {"KHR_materials_clearcoat": {"clearcoatTexture": {"index": -2}}}})",
       "KHR_materials_clearcoat clearcoatTexture index must be a whole number >= 0"},
      {R"({"extensions": {"KHR_materials_transmission": {"transmissionFactor": "all"}}})",
       "KHR_materials_transmission transmissionFactor must be in [0, 1]"},
      {R"({"extensions": {"KHR_materials_volume": {"thicknessFactor": -1}}})",
       "KHR_materials_volume thicknessFactor must be a number >= 0"},
      {R"({"extensions": {"KHR_materials_volume": {"attenuationDistance": 0}}})",
       "KHR_materials_volume attenuationDistance must be a number > 0"},
      {R"({"extensions": {"KHR_materials_volume": {"attenuationColor": [1, 2, 0]}}})",
       "KHR_materials_volume attenuationColor must be 3 numbers in [0, 1]"},
      {R"({"extensions": {"KHR_materials_specular": {"specularColorFactor": [1, -1, 0]}}})",
       "KHR_materials_specular specularColorFactor must be 3 numbers in [0, 1000]"},
  };
  for (const auto& [material, message] : cases) {
    TestGltf g = quad();
    g.material = material;
    expect_error(write("bad.gltf", g.embedded()), std::string("material 'material 0': ") + message);
  }
}

// The base colour, metallic-roughness and normal textures are files beside the
// mesh (the normal map with its scale); the occlusion texture is read, not used.
TEST_F(MeshLoad, GltfTexturesAreFilesBesideTheMesh) {
  TestGltf g = quad();
  g.material = R"({"pbrMetallicRoughness": {"metallicFactor": 0, "baseColorTexture": {"index": 0},
      "metallicRoughnessTexture": {"index": 1}}, "normalTexture": {"index": 2, "scale": 0.8},
      "occlusionTexture": {"index": 1}}],
    "textures": [{"source": 0}, {"source": 1}, {"source": 2}],
    "images": [{"uri": "maps/base.png"}, {"uri": "maps/mr.png"}, {"uri": "maps/normal.png"}], "samplers": [{})";
  TriangleMesh m = load_mesh(write("textured.gltf", g.embedded()));
  ASSERT_EQ(m.materials.size(), 1u);
  const MeshMaterial& mm = m.materials[0];
  EXPECT_EQ(mm.material.kind, MaterialKind::Principled);
  EXPECT_EQ(mm.albedo_map.image, (folder_.root() / "maps/base.png").string());
  EXPECT_EQ(mm.roughness_map.image, (folder_.root() / "maps/mr.png").string());
  EXPECT_EQ(mm.metallic_map.image, mm.roughness_map.image);
  EXPECT_EQ(mm.normal_map.image, (folder_.root() / "maps/normal.png").string());
  EXPECT_FLOAT_EQ(mm.normal_scale, 0.8f);
}

// What the materials' new fields refuse, each naming the material and the field.
TEST_F(MeshLoad, GltfMaterialFieldsOutOfRangeAreRefused) {
  const std::pair<const char*, const char*> cases[] = {
      {R"({"extensions": {"KHR_materials_ior": {"ior": 0.5}}})", "KHR_materials_ior ior must be 0 or in [1, 10]"},
      {R"({"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": -1}}})",
       "KHR_materials_emissive_strength emissiveStrength must be a number in [0, 1e9]"},
      {R"({"normalTexture": {"index": 0, "scale": -1}}], "textures": [{"source": 0}], "images": [{"uri": "n.png"}],
          "samplers": [{})", "normalTexture scale must be in [0, 1000]"},
      {R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 2}}}], "textures": [{"source": 0}],
          "images": [{"uri": "b.png"}], "samplers": [{})", "base colour texture: texCoord 2 is not supported"},
  };
  for (const auto& [material, message] : cases) {
    TestGltf g = quad();
    g.material = material;
    expect_error(write("bad.gltf", g.embedded()), std::string("material 'material 0': ") + message);
  }
}

TEST_F(MeshLoad, GltfDropsAndCountsNanAndDegenerateTriangles) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  TestGltf g = quad();
  g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, nan, 0, 0, 2, 0, 0};
  g.normals.assign(15, 0.0f);
  for (size_t i = 2; i < 15; i += 3) g.normals[i] = 1.0f;
  g.uvs.assign(10, 0.0f);
  g.indices = {0, 1, 2, 0, 1, 3, 0, 1, 4, 2, 2, 1};  // good, NaN, collinear, repeated
  TriangleMesh m = load_mesh(write("dropped.gltf", g.embedded()));
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.triangles[0], (std::array<uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(m.dropped_nan, 1u);
  EXPECT_EQ(m.dropped_degenerate, 2u);
}

TEST_F(MeshLoad, GltfErrorsNameTheFileAndTheProblem) {
  expect_error(write("bad.gltf", "{\"asset\": "), "malformed glTF: ");
  expect_error(write("bad.glb", "glTF...."), "malformed glTF: ");
  TestGltf range = quad();
  range.indices = {0, 1, 7, 0, 2, 3};
  expect_error(write("range.gltf", range.embedded()), "mesh 0 primitive 0: index 7 out of range (4 vertices)");
  TestGltf odd = quad();
  odd.indices = {0, 1, 2, 3};
  expect_error(write("odd.gltf", odd.embedded()), "mesh 0 primitive 0: 4 corners is not a multiple of 3");
  TestGltf flat = quad();
  flat.indices = {0, 0, 1};
  expect_error(write("flat.gltf", flat.embedded()), "no triangles left (1 degenerate and 0 non-finite dropped)");
  // An accessor that claims more vertices than its buffer view holds.
  std::string overrun = quad().embedded();
  std::string from = "\"count\": 4, \"type\": \"VEC3\"";
  overrun.replace(overrun.find(from), from.size(), "\"count\": 5, \"type\": \"VEC3\"");
  expect_error(write("overrun.gltf", overrun), "POSITION (accessor 0): elements run past the end of the buffer view");
  TestGltf embedded_image = quad();
  embedded_image.material = R"({"pbrMetallicRoughness": {"metallicFactor": 0, "baseColorTexture": {"index": 0}}}],
    "textures": [{"source": 0}], "images": [{"bufferView": 0, "mimeType": "image/ktx2"}], "samplers": [{})";
  expect_error(write("image.gltf", embedded_image.embedded()),
               "material 'material 0': base colour texture: image 0: KTX2 / Basis Universal textures are not supported");
}

// ---- OBJ numbers ----

// tinyobjloader would take 'abc' for 0, keep NaN and the infinities, and wrap an index
// past 2^31 to another vertex; each is refused with the file and the line.
TEST_F(MeshLoad, ObjVertexNumbersMustBeFinite) {
  expect_error(write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"),
               "malformed OBJ: line 2: v: 'nan' is not a finite number");
  expect_error(write("words.obj", "v abc def ghi\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
               "malformed OBJ: line 1: v: 'abc' is not a finite number");
  expect_error(write("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 1 -inf\nf 1 2 3\n"),
               "malformed OBJ: line 3: v: '-inf' is not a finite number");
  // Finite as a double, not as a float.
  expect_error(write("huge.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n"),
               "malformed OBJ: line 2: v: '1e39' is not a finite number");
}

TEST_F(MeshLoad, ObjNormalsAndTextureCoordinatesMustBeFinite) {
  expect_error(write("vn.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn nan 0 1\nf 1//1 2//1 3//1\n"),
               "malformed OBJ: line 4: vn: 'nan' is not a finite number");
  expect_error(write("vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt inf 0\nf 1/1 2/1 3/1\n"),
               "malformed OBJ: line 4: vt: 'inf' is not a finite number");
}

TEST_F(MeshLoad, ObjIndexPastTheVerticesIsRefusedNotWrapped) {
  // 2^32 + 1 would wrap to 1 in 32 bits.
  const std::string path = write("wrap.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4294967297\n");
  expect_error(path, "malformed OBJ: line 4: index 4294967297 is out of range: the file has 3 vertex positions");
  expect_error(write("normal.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n"),
               "malformed OBJ: line 5: index 2 is out of range: the file has 1 normal");
}

TEST_F(MeshLoad, ObjNegativeIndexBeforeTheFirstVertexIsRefused) {
  expect_error(write("negative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n"),
               "malformed OBJ: line 4: f: index -4 reaches before the first vertex position (3 given so far)");
  // Relative indices count the vertices given before the face, not the file's.
  expect_error(write("early.obj", "v 0 0 0\nf -1 -2 -3\nv 1 0 0\nv 0 1 0\n"),
               "malformed OBJ: line 2: f: index -2 reaches before the first vertex position (1 given so far)");
  // Within range they work.
  EXPECT_EQ(load_mesh(write("relative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n")).triangles.size(), 1u);
}

TEST_F(MeshLoad, ObjIndexZeroOrNotWholeIsRefused) {
  expect_error(write("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
               "malformed OBJ: line 4: f: '0' is not a corner of whole, non-zero indices");
  expect_error(write("half.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2.5\n"),
               "malformed OBJ: line 4: f: '2.5' is not a corner of whole, non-zero indices");
}

// A mesh's emission is bounded as a scene file's is (at most 1e9).
TEST_F(MeshLoad, MeshEmissionIsAtMostABillion) {
  write("hot.mtl", "newmtl hot\nKe 2e9 0 0\n");
  expect_error(write("hot.obj", "mtllib hot.mtl\nusemtl hot\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
               "material 'hot': Ke must be 3 numbers in [0, 1e9] (the most radiance a scene may hold)");
  TestGltf g = quad();
  g.material = R"({"name": "sun", "emissiveFactor": [0, 2e9, 0]})";
  expect_error(write("hot.gltf", g.embedded()),
               "material 'sun': emissiveFactor must be 3 numbers in [0, 1e9] (the most radiance a scene may hold)");
  g.material = R"({"name": "sun", "emissiveFactor": [0, 1e9, 0]})";  // the limit itself
  EXPECT_EQ(load_mesh(write("bright.gltf", g.embedded())).materials[0].material.emission.y, 1e9f);
}

// ---- The glTF node graph ----

// The quad's document with its scene's roots and its nodes replaced.
std::string with_nodes(const std::string& gltf, const std::string& roots, const std::string& nodes) {
  std::string out = gltf;
  const std::string scenes = R"("scenes": [{"nodes": [0]}])", old_nodes = R"("nodes": [{"mesh": 0, "translation": [10, 20, 30]}])";
  EXPECT_NE(out.find(scenes), std::string::npos);
  EXPECT_NE(out.find(old_nodes), std::string::npos);
  out.replace(out.find(scenes), scenes.size(), R"("scenes": [{"nodes": )" + roots + "}]");
  out.replace(out.find(old_nodes), old_nodes.size(), R"("nodes": )" + nodes);
  return out;
}

// The walk keeps its own stack: a chain far deeper than the call stack could hold loads.
TEST_F(MeshLoad, GltfChainOfAHundredThousandNodesLoads) {
  const int depth = 100001;
  std::string nodes = "[";
  for (int i = 0; i + 1 < depth; ++i) nodes += "{\"children\": [" + std::to_string(i + 1) + "]},";
  nodes += R"({"mesh": 0, "translation": [10, 20, 30]}])";  // the deepest node holds the mesh
  expect_quad(load_mesh(write("chain.gltf", with_nodes(quad().embedded(), "[0]", nodes))));
}

TEST_F(MeshLoad, GltfNodeWithTwoParentsIsRefused) {
  const std::string path = write("shared.gltf", with_nodes(quad().embedded(), "[0, 1]",
                                                           R"([{"children": [2]}, {"children": [2]}, {"mesh": 0}])"));
  expect_error(path, "node 2 has two parents (nodes 0 and 1); glTF nodes form a forest, each node with one parent at most");
}

TEST_F(MeshLoad, GltfChildListedTwiceByOneParentIsRefused) {
  const std::string path = write("twice.gltf", with_nodes(quad().embedded(), "[0]", R"([{"children": [1, 1]}, {"mesh": 0}])"));
  expect_error(path, "node 1 is listed twice as a child of node 0; glTF nodes form a forest");
}

// 40 levels of two nodes, each the parent of both nodes below: walked as a tree it
// would reach the mesh 2^40 times. Refused at once instead.
TEST_F(MeshLoad, GltfDiamondOfFortyLevelsIsRefusedQuickly) {
  test::Watchdog watchdog(std::chrono::seconds(30), "a glTF diamond of 40 levels");
  const int levels = 40;
  std::string nodes = "[";
  for (int level = 0; level < levels; ++level) {
    const std::string below = std::to_string(2 * level + 2) + ", " + std::to_string(2 * level + 3);
    nodes += "{\"children\": [" + below + "]}, {\"children\": [" + below + "]}, ";
  }
  nodes += R"({"mesh": 0}, {"mesh": 0}])";
  const auto start = std::chrono::steady_clock::now();
  expect_error(write("diamond.gltf", with_nodes(quad().embedded(), "[0, 1]", nodes)),
               "node 2 has two parents (nodes 0 and 1)");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

TEST_F(MeshLoad, GltfCycleIsRefused) {
  // A loop apart from the scene's root (no node in it has two parents).
  expect_error(write("loop.gltf", with_nodes(quad().embedded(), "[0]", R"([{"mesh": 0}, {"children": [2]}, {"children": [1]}])")),
               "the node hierarchy has a cycle through node 1");
  expect_error(write("self.gltf", with_nodes(quad().embedded(), "[0]", R"([{"mesh": 0, "children": [0]}])")),
               "the node hierarchy has a cycle through node 0");
}

TEST_F(MeshLoad, GltfSceneRootsMustBeRootsListedOnce) {
  expect_error(write("root.gltf", with_nodes(quad().embedded(), "[0, 1]", R"([{"children": [1]}, {"mesh": 0}])")),
               "node 1 is a root of the scene but a child of node 0");
  expect_error(write("roots.gltf", with_nodes(quad().embedded(), "[0, 0]", R"([{"mesh": 0}])")),
               "node 0 is listed twice among the scene's nodes");
}

// A primitive without "material" takes the specification's default: metallic 1,
// roughness 1, base colour 1.
TEST_F(MeshLoad, GltfPrimitiveWithoutAMaterialGetsTheDefaultMaterial) {
  TestGltf g = quad();
  g.material = "";  // "materials": []
  std::string text = g.embedded();
  const std::string from = R"(, "material": 0})";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), "}");
  const TriangleMesh m = load_mesh(write("nomaterial.gltf", text));
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "default");
  EXPECT_EQ(m.materials[0].material.kind, MaterialKind::Principled);
  expect_vec(m.materials[0].material.albedo, vec3(1.0f));
  EXPECT_FLOAT_EQ(m.materials[0].metallic, 1.0f);
  EXPECT_FLOAT_EQ(m.materials[0].roughness, 1.0f);
  expect_vec(m.materials[0].material.emission, vec3(0.0f));
  EXPECT_EQ(m.triangle_material, (std::vector<uint32_t>{0, 0}));
}

// ---- The real models of ../shared/models ----

std::filesystem::path models() { return test::models_dir(); }

void expect_model(const char* file, size_t triangles, bool uvs) {
  std::filesystem::path path = models() / file;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "no " << path.string() << " (the shared models are optional)";
  TriangleMesh m = load_mesh(path.string());
  EXPECT_EQ(m.triangles.size() + m.dropped_degenerate + m.dropped_nan, triangles) << file;
  EXPECT_EQ(m.triangles.size(), triangles) << file << ": " << m.dropped_degenerate << " degenerate, " << m.dropped_nan
                                           << " non-finite dropped";
  EXPECT_EQ(!m.uvs.empty(), uvs) << file;
  EXPECT_EQ(m.triangle_material.size(), m.triangles.size());
  for (const auto& t : m.triangles) {
    for (uint32_t v : t) ASSERT_LT(v, m.positions.size());
  }
}

TEST(SharedModels, Teapot) { expect_model("teapot.obj", 6320, false); }
TEST(SharedModels, Spot) { expect_model("spot.obj", 5856, true); }
TEST(SharedModels, StanfordBunny) { expect_model("stanford-bunny.obj", 69451, false); }
TEST(SharedModels, Nefertiti) { expect_model("nefertiti.obj", 99938, false); }

}  // namespace
}  // namespace wt

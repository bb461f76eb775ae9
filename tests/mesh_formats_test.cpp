// The mesh formats of Mitsuba 3 scenes (src/scene/mesh_ply.cpp, mesh_serialized.cpp):
// PLY files (ASCII, binary little- and big-endian) and .serialized files (versions 3
// and 4, compressed here with zlib) written byte by byte, loaded, and compared exactly;
// and each malformed file's error, which names the file.
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "errors/errors.hpp"
#include "scene/mesh_load.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

using Tri = std::array<uint32_t, 3>;

// Numbers appended as bytes, little- or big-endian.
class Bytes {
 public:
  explicit Bytes(bool big_endian = false) : big_(big_endian) {}
  template <class T>
  Bytes& put(T v) {
    char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof v);
    if (big_) std::reverse(raw, raw + sizeof raw);
    s.append(raw, sizeof raw);
    return *this;
  }
  Bytes& text(const std::string& t) {
    s += t;
    return *this;
  }
  std::string s;

 private:
  bool big_;
};

class MeshFormats : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& bytes) {
    const std::string path = (folder_.root() / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  // load_mesh must throw one line that starts with the file and contains `what`.
  void expect_error(const std::string& path, const std::string& what, uint32_t shape_index = 0) {
    try {
      load_mesh(path, shape_index);
      ADD_FAILURE() << path << " loaded; expected: " << what;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
      EXPECT_NE(message.find(what), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }

  test::TestFolder folder_;
};

// Every triangle takes the one material "default", white lambertian.
void expect_default_material(const TriangleMesh& m) {
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "default");
  EXPECT_EQ(m.materials[0].material.kind, MaterialKind::Lambertian);
  EXPECT_EQ(m.materials[0].material.albedo, vec3(1.0f));
  EXPECT_EQ(m.materials[0].material.texture, -1);
  EXPECT_EQ(m.triangle_material, std::vector<uint32_t>(m.triangles.size(), 0u));
}

// ---- PLY ----

// The triangles, each turned (keeping its winding) to start at its smallest index:
// Assimp's triangulation may turn a triangle so (its n-gon encoding turns one that
// starts where the polygon before it was fanned from).
std::vector<Tri> turned(std::vector<Tri> t) {
  for (Tri& c : t) std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
  return t;
}

const std::vector<vec3> kQuad = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5f, 0.5f, 1}};

TEST_F(MeshFormats, PlyAsciiPositionsAndAQuadTriangulated) {
  const std::string path = write("quad.ply",
                                 "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 5\n"
                                 "property float x\nproperty float y\nproperty float z\n"
                                 "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
                                 "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n4 0 1 2 3\n3 0 1 4\n");
  const TriangleMesh m = load_mesh(path);
  EXPECT_EQ(m.source, path);
  EXPECT_EQ(m.positions, kQuad);
  EXPECT_EQ(turned(m.triangles), (std::vector<Tri>{{0, 1, 2}, {0, 2, 3}, {0, 1, 4}}));
  EXPECT_TRUE(m.normals.empty());
  EXPECT_TRUE(m.uvs.empty());
  EXPECT_TRUE(m.tangents.empty());
  EXPECT_EQ(m.dropped_degenerate, 0u);
  EXPECT_EQ(m.dropped_nan, 0u);
  expect_default_material(m);
}

TEST_F(MeshFormats, PlyAsciiNormalsNormalizedAndUvsAsTheyAre) {
  const std::string path = write("uv.PLY",
                                 "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\n"
                                 "property float x\r\nproperty float y\r\nproperty float z\r\n"
                                 "property float nx\r\nproperty float ny\r\nproperty float nz\r\n"
                                 "property float u\r\nproperty float v\r\n"
                                 "element face 1\r\nproperty list uchar uint vertex_index\r\nend_header\r\n"
                                 "0 0 0 0 0 2 0 0.25\r\n1 0 0 0 0 1 1 0.25\r\n0 1 0 0 3 4 0 1\r\n3 0 1 2\r\n");
  const TriangleMesh m = load_mesh(path);
  EXPECT_EQ(m.positions, (std::vector<vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  EXPECT_EQ(m.normals, (std::vector<vec3>{{0, 0, 1}, {0, 0, 1}, {0, 0.6f, 0.8f}}));
  // Mitsuba 3 reads a PLY's v as it is (its ply plugin's flip_tex_coords: false).
  EXPECT_EQ(m.uvs, (std::vector<vec2>{{0, 0.25f}, {1, 0.25f}, {0, 1}}));
  EXPECT_EQ(m.triangles, (std::vector<Tri>{{0, 1, 2}}));
  expect_default_material(m);
}

// A binary PLY: positions and, where asked, normals and (s, t) UVs, the faces given.
std::string binary_ply(bool big_endian, bool normals, bool uvs, const std::vector<vec3>& positions,
                       const std::vector<std::vector<int32_t>>& faces) {
  Bytes b(big_endian);
  b.text(std::string("ply\nformat ") + (big_endian ? "binary_big_endian" : "binary_little_endian") + " 1.0\n");
  b.text("element vertex " + std::to_string(positions.size()) +
         "\nproperty float x\nproperty float y\nproperty float z\n");
  if (normals) b.text("property float nx\nproperty float ny\nproperty float nz\n");
  if (uvs) b.text("property double s\nproperty double t\n");
  b.text("element face " + std::to_string(faces.size()) + "\nproperty list uchar int vertex_indices\nend_header\n");
  for (size_t i = 0; i < positions.size(); ++i) {
    b.put(positions[i].x).put(positions[i].y).put(positions[i].z);
    if (normals) b.put(0.0f).put(0.0f).put(-1.0f);
    if (uvs) b.put(0.125 * static_cast<double>(i)).put(1.0 - 0.125 * static_cast<double>(i));
  }
  for (const auto& f : faces) {
    b.put(static_cast<uint8_t>(f.size()));
    for (int32_t i : f) b.put(i);
  }
  return b.s;
}

TEST_F(MeshFormats, PlyBinaryLittleAndBigEndianWithAndWithoutNormalsAndUvs) {
  for (bool big : {false, true}) {
    for (bool attributes : {false, true}) {
      SCOPED_TRACE(std::string(big ? "big" : "little") + (attributes ? " with" : " without") + " normals, uvs");
      const TriangleMesh m =
          load_mesh(write("bin.ply", binary_ply(big, attributes, attributes, kQuad, {{0, 1, 2, 3}, {0, 1, 4}})));
      EXPECT_EQ(m.positions, kQuad);
      EXPECT_EQ(turned(m.triangles), (std::vector<Tri>{{0, 1, 2}, {0, 2, 3}, {0, 1, 4}}));
      if (attributes) {
        EXPECT_EQ(m.normals, std::vector<vec3>(5, vec3(0, 0, -1)));
        EXPECT_EQ(m.uvs, (std::vector<vec2>{{0, 1}, {0.125f, 0.875f}, {0.25f, 0.75f}, {0.375f, 0.625f}, {0.5f, 0.5f}}));
      } else {
        EXPECT_TRUE(m.normals.empty());
        EXPECT_TRUE(m.uvs.empty());
      }
      expect_default_material(m);
    }
  }
}

TEST_F(MeshFormats, PlyDropsAndCountsDegenerateAndNonFiniteTriangles) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<vec3> p = kQuad;
  p.push_back(vec3(nan, 0, 0));  // vertex 5: only its triangle uses it, and is dropped
  const std::string path = write("drop.ply", binary_ply(false, true, false, p,
                                                        {{0, 1, 2}, {0, 1, 1}, {0, 1, 5}, {0, 2, 4}, {3, 4}}));
  const TriangleMesh m = load_mesh(path);
  EXPECT_EQ(m.dropped_degenerate, 2u);  // a repeated corner; a face of two corners
  EXPECT_EQ(m.dropped_nan, 1u);
  // Vertex 5 is dropped with its triangle; vertex 3 (used only by the edge) too.
  EXPECT_EQ(m.positions, (std::vector<vec3>{kQuad[0], kQuad[1], kQuad[2], kQuad[4]}));
  EXPECT_EQ(m.normals.size(), 4u);
  EXPECT_EQ(turned(m.triangles), (std::vector<Tri>{{0, 1, 2}, {0, 2, 3}}));
}

TEST_F(MeshFormats, PlyErrorsNameTheFile) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string face = "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  expect_error(write("empty.ply", ""), "malformed PLY: the file is empty");
  expect_error(write("obj.ply", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "does not start with the line 'ply'");
  expect_error(write("points.ply", header + "end_header\n0 0 0\n1 0 0\n0 1 0\n"), "malformed PLY: no faces");
  expect_error(write("range.ply", header + face + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"), "malformed PLY: ");
  expect_error(write("noend.ply", header), "malformed PLY: no end_header line");
  expect_error(write("normal.ply",
                     "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                     "property float nx\nproperty float ny\nproperty float nz\n" +
                         face + "0 0 0 0 0 1\n1 0 0 0 0 0\n0 1 0 0 0 1\n3 0 1 2\n"),
               "vertex 1 has a zero or non-finite normal");
  expect_error(write("flat.ply", header + face + "0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n"),
               "no triangles left (1 degenerate and 0 non-finite dropped)");
  // A count the file cannot hold is refused before Assimp allocates for it.
  std::string huge = binary_ply(false, false, false, kQuad, {{0, 1, 2}});
  huge.replace(huge.find("element vertex 5"), 16, "element vertex 4000000000");
  expect_error(write("huge.ply", huge), "malformed PLY: the file ends inside element 'vertex' 6 (of 4000000000");
  // A body cut short (Assimp would read what is missing as zeros).
  const std::string cut = binary_ply(false, false, false, kQuad, {{0, 1, 2}, {0, 2, 3}});
  expect_error(write("cut.ply", cut.substr(0, cut.size() - 6)), "malformed PLY: the file ends inside element 'face' 1");
  expect_error(write("cut-ascii.ply", header + face + "0 0 0\n1 0 0\n0 1 0\n3 0 1"),
               "malformed PLY: the file ends inside element 'face' 0");
  expect_error(write("count.ply", header + face + "0 0 0\n1 0 0\n0 1 0\nx 0 1 2\n"),
               "element 'face' 0: a list's length 'x' is not a whole number");
}

// ---- Mitsuba's serialized ----

constexpr uint32_t kNormals = 0x0001, kUvs = 0x0002, kColours = 0x0008, kFaceNormals = 0x0010, kSingle = 0x1000,
                   kDouble = 0x2000;

struct Shape {
  uint32_t flags = kSingle;
  std::string name = "shape";
  std::vector<double> positions, normals, uvs, colours;  // written as the flags say
  std::vector<uint32_t> indices;
  uint64_t vertex_count() const { return positions.size() / 3; }
};

std::string deflate(const std::string& raw) {
  uLongf size = compressBound(raw.size());
  std::string out(size, '\0');
  EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(&out[0]), &size, reinterpret_cast<const Bytef*>(raw.data()),
                      raw.size(), 9),
            Z_OK);
  out.resize(size);
  return out;
}

// The shape's inflated stream (the counts as given, or as the arrays say).
std::string shape_stream(const Shape& s, uint16_t version, uint64_t vertices, uint64_t triangles) {
  Bytes b;
  b.put(s.flags);
  if (version == 4) b.text(s.name).put('\0');
  b.put(vertices).put(triangles);
  auto reals = [&](const std::vector<double>& v) {
    for (double x : v) {
      if (s.flags & kDouble) {
        b.put(x);
      } else {
        b.put(static_cast<float>(x));
      }
    }
  };
  reals(s.positions);
  if (s.flags & kNormals) reals(s.normals);
  if (s.flags & kUvs) reals(s.uvs);
  if (s.flags & kColours) reals(s.colours);
  for (uint32_t i : s.indices) b.put(i);
  return b.s;
}

std::string shape_bytes(const Shape& s, uint16_t version) {
  return Bytes().put(uint16_t{0x041C}).put(version).s +
         deflate(shape_stream(s, version, s.vertex_count(), s.indices.size() / 3));
}

// The shapes one after another, then the table of their offsets and their count.
std::string serialized(const std::vector<std::string>& shapes, uint16_t version) {
  std::string file;
  Bytes table;
  for (const std::string& s : shapes) {
    if (version == 4) {
      table.put(uint64_t{file.size()});
    } else {
      table.put(static_cast<uint32_t>(file.size()));
    }
    file += s;
  }
  table.put(static_cast<uint32_t>(shapes.size()));
  return file + table.s;
}

Shape textured_quad() {
  Shape s;
  s.flags = kSingle | kNormals | kUvs;
  s.name = "quad";
  s.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  s.normals = {0, 0, 2, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  s.uvs = {0, 0, 1, 0, 1, 0.75, 0, 0.75};
  s.indices = {0, 1, 2, 0, 2, 3};
  return s;
}

Shape double_triangle() {
  Shape s;
  s.flags = kDouble;
  s.name = "tri";
  s.positions = {0.5, 0.25, -1, 2, 0.25, -1, 0.5, 3, -1.5};
  s.indices = {0, 1, 2};
  return s;
}

TEST_F(MeshFormats, SerializedTwoShapesSingleAndDoublePrecision) {
  const std::string path =
      write("two.serialized", serialized({shape_bytes(textured_quad(), 4), shape_bytes(double_triangle(), 4)}, 4));
  const TriangleMesh a = load_mesh(path, 0);
  EXPECT_EQ(a.positions, (std::vector<vec3>{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}));
  EXPECT_EQ(a.normals, std::vector<vec3>(4, vec3(0, 0, 1)));
  // As Mitsuba reads them: v as it is.
  EXPECT_EQ(a.uvs, (std::vector<vec2>{{0, 0}, {1, 0}, {1, 0.75f}, {0, 0.75f}}));
  EXPECT_EQ(a.triangles, (std::vector<Tri>{{0, 1, 2}, {0, 2, 3}}));
  expect_default_material(a);
  EXPECT_EQ(load_mesh(path).positions, a.positions);  // shape 0 by default

  const TriangleMesh b = load_mesh(path, 1);
  EXPECT_EQ(b.positions, (std::vector<vec3>{{0.5f, 0.25f, -1}, {2, 0.25f, -1}, {0.5f, 3, -1.5f}}));
  EXPECT_TRUE(b.normals.empty());
  EXPECT_TRUE(b.uvs.empty());
  EXPECT_EQ(b.triangles, (std::vector<Tri>{{0, 1, 2}}));
  expect_default_material(b);
}

TEST_F(MeshFormats, SerializedVersion3AndItsTableOfU32Offsets) {
  Shape first = double_triangle(), second = textured_quad();
  second.flags = kDouble | kUvs;  // doubles, UVs, no normals
  const std::string path =
      write("v3.serialized", serialized({shape_bytes(first, 3), shape_bytes(second, 3)}, 3));
  EXPECT_EQ(load_mesh(path, 0).triangles.size(), 1u);
  const TriangleMesh m = load_mesh(path, 1);
  EXPECT_EQ(m.positions.size(), 4u);
  EXPECT_TRUE(m.normals.empty());
  EXPECT_EQ(m.uvs, (std::vector<vec2>{{0, 0}, {1, 0}, {1, 0.75f}, {0, 0.75f}}));
}

TEST_F(MeshFormats, SerializedFaceNormalsFlagDropsTheNormalsAndColoursAreSkipped) {
  Shape s = textured_quad();
  s.flags |= kFaceNormals | kColours;
  s.colours = std::vector<double>(12, 0.5);
  const TriangleMesh m = load_mesh(write("faceted.serialized", serialized({shape_bytes(s, 4)}, 4)));
  EXPECT_TRUE(m.normals.empty());
  EXPECT_EQ(m.uvs.size(), 4u);  // read after the normals and before the colours
  EXPECT_EQ(m.triangles, (std::vector<Tri>{{0, 1, 2}, {0, 2, 3}}));
}

TEST_F(MeshFormats, SerializedDropsNonFinitePositionsAndDegenerateTriangles) {
  Shape s = double_triangle();
  s.positions.insert(s.positions.end(), {std::nan(""), 0, 0});
  s.indices = {0, 1, 2, 0, 1, 3, 0, 0, 2};
  const TriangleMesh m = load_mesh(write("drop.serialized", serialized({shape_bytes(s, 4)}, 4)));
  EXPECT_EQ(m.triangles, (std::vector<Tri>{{0, 1, 2}}));
  EXPECT_EQ(m.positions.size(), 3u);
  EXPECT_EQ(m.dropped_nan, 1u);
  EXPECT_EQ(m.dropped_degenerate, 1u);
}

TEST_F(MeshFormats, SerializedErrorsNameTheFile) {
  const std::string good = shape_bytes(double_triangle(), 4);
  expect_error(write("empty.serialized", ""), "malformed serialized mesh: the file is empty");
  expect_error(write("magic.serialized", "PK" + good.substr(2)), "not a Mitsuba serialized mesh (format identifier 0x4B50");
  std::string v5 = good;
  v5[2] = 5;
  expect_error(write("v5.serialized", serialized({v5}, 4)), "version 5 is not supported");
  expect_error(write("cut.serialized", good.substr(0, good.size() - 5)), "zlib stream is cut short");
  std::string corrupt = good;
  corrupt[4] = static_cast<char>(0xFF);  // zlib's header
  expect_error(write("corrupt.serialized", corrupt), "corrupt zlib stream");

  const Shape t = double_triangle();
  auto with_counts = [&](uint64_t vertices, uint64_t triangles) {
    return serialized({Bytes().put(uint16_t{0x041C}).put(uint16_t{4}).s + deflate(shape_stream(t, 4, vertices, triangles))}, 4);
  };
  expect_error(write("more.serialized", with_counts(4, 1)), "need 132 inflated bytes, but it holds 108");
  expect_error(write("fewer.serialized", with_counts(3, 0)), "it holds more than the 96 inflated bytes");
  expect_error(write("huge.serialized", with_counts(3, uint64_t{1} << 40)), "compressed bytes can hold");
  expect_error(write("wide.serialized", with_counts(uint64_t{1} << 33, 1)), "more than 2^32 - 1");

  Shape range = double_triangle();
  range.indices = {0, 1, 3};
  expect_error(write("range.serialized", serialized({shape_bytes(range, 4)}, 4)),
               "shape 0: triangle 0: vertex index 3 is out of range (3 vertices)");
  const std::string two = write("two.serialized", serialized({good, good}, 4));
  expect_error(two, "shape_index 2 is past the file's 2 shapes", 2);
  expect_error(write("one.serialized", serialized({good}, 4)), "shape_index 7 is past the file's 1 shape", 7);
  std::string offset = serialized({good, good}, 4);
  offset.replace(offset.size() - 12, 8, Bytes().put(uint64_t{good.size() + 1}).s);  // shape 1's offset, one byte on
  expect_error(write("offset.serialized", offset), "does not point at a shape's header", 1);
  Shape both = double_triangle();
  both.flags |= kSingle;
  expect_error(write("both.serialized", serialized({shape_bytes(both, 4)}, 4)), "give both single and double precision");
  Shape none = double_triangle();
  none.indices.clear();
  expect_error(write("none.serialized", serialized({shape_bytes(none, 4)}, 4)), "has no triangles");
}

TEST_F(MeshFormats, ExtensionsInAnyCase) {
  EXPECT_EQ(load_mesh(write("A.SERIALIZED", serialized({shape_bytes(double_triangle(), 4)}, 4))).triangles.size(), 1u);
  EXPECT_EQ(load_mesh(write("b.Ply", binary_ply(false, false, false, kQuad, {{0, 1, 2}}))).triangles.size(), 1u);
}

}  // namespace
}  // namespace wt

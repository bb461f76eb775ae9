// Stanford PLY (.ply: ASCII, binary little- and big-endian) through Assimp's PLY
// importer (Debian's libassimp-dev), from the bytes read_input_file read. Assimp
// triangulates; this file checks what it returns and builds the mesh as the other
// formats' are built (add_indexed_mesh).
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "errors/errors.hpp"
#include "scene/mesh_formats.hpp"

namespace wt {

namespace {

// The size in bytes of a PLY scalar type in a binary file; 0 for a name PLY does not have.
uint64_t type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

bool integer_type(const std::string& t) {
  return type_size(t) != 0 && t != "float" && t != "float32" && t != "float64" && t != "double";
}
bool signed_type(const std::string& t) { return t == "char" || t == "short" || t == "int" || t.rfind("int", 0) == 0; }

struct Property {
  bool list = false;
  std::string type, count_type;  // a list's items' type, and its length's
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
};

// Checks that the bytes after a PLY's header hold every instance its header
// declares, before Assimp reads them: Assimp reads the bytes of a binary file that
// are not there as zeros (or as an earlier block's), and the numbers missing from an
// ASCII one as zeros, and allocates for the counts the header gives before it reads.
// Only the layout is walked here (each list's length read, no other number); the
// numbers are Assimp's to parse. A header this cannot follow (a type PLY does not
// have, an unknown format) is left to Assimp to judge.
void check_layout(const std::string& bytes, const std::string& path) {
  auto fail = [&](const std::string& what) { throw InputError(path + ": malformed PLY: " + what); };
  std::vector<Element> elements;
  std::string format;
  size_t line_start = 0, body = std::string::npos;
  while (line_start < bytes.size()) {
    size_t line_end = bytes.find('\n', line_start);
    if (line_end == std::string::npos) line_end = bytes.size();
    std::istringstream line(bytes.substr(line_start, line_end - line_start));
    line_start = line_end + 1;
    std::string word;
    line >> word;
    if (word == "end_header") {
      body = std::min(line_start, bytes.size());
      break;
    }
    if (word == "format") {
      line >> format;
    } else if (word == "element") {
      Element e;
      std::string count;
      line >> e.name >> count;
      char* end = nullptr;
      e.count = std::strtoull(count.c_str(), &end, 10);
      if (count.empty() || *end != '\0' || count[0] == '-') return;
      elements.push_back(e);
    } else if (word == "property") {
      if (elements.empty()) return;
      Property p;
      line >> p.type;
      if (p.type == "list") {
        p.list = true;
        line >> p.count_type >> p.type;
        if (!integer_type(p.count_type)) return;
      }
      if (type_size(p.type) == 0) return;
      elements.back().properties.push_back(p);
    }
  }
  if (body == std::string::npos) fail("no end_header line");
  if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian") return;
  bool faces = false;
  for (const Element& e : elements) faces = faces || ((e.name == "face" || e.name == "tristrips") && e.count > 0);
  if (!faces) fail("no faces (no element 'face' or 'tristrips' with instances): a point cloud is not a mesh");

  auto ends_inside = [&](const Element& e, uint64_t i) {
    fail("the file ends inside element '" + e.name + "' " + std::to_string(i) + " (of " + std::to_string(e.count) +
         " its header declares)");
  };
  const uint64_t size = bytes.size();
  if (format == "ascii") {
    // Whitespace-separated numbers: one per scalar property, a list's length and its items.
    size_t at = body;
    auto token = [&]() -> std::string {
      at = bytes.find_first_not_of(" \t\r\n", at);
      if (at == std::string::npos) {
        at = size;
        return std::string();
      }
      const size_t end = std::min(bytes.find_first_of(" \t\r\n", at), bytes.size());
      std::string t = bytes.substr(at, end - at);
      at = end;
      return t;
    };
    for (const Element& e : elements) {
      for (uint64_t i = 0; i < e.count; ++i) {
        for (const Property& p : e.properties) {
          const std::string t = token();
          if (t.empty()) ends_inside(e, i);
          if (!p.list) continue;
          char* end = nullptr;
          const uint64_t n = std::strtoull(t.c_str(), &end, 10);
          if (*end != '\0' || !std::isdigit(static_cast<unsigned char>(t[0]))) {
            fail("element '" + e.name + "' " + std::to_string(i) + ": a list's length '" + t + "' is not a whole number");
          }
          for (uint64_t k = 0; k < n; ++k) {
            if (token().empty()) ends_inside(e, i);
          }
        }
      }
    }
    return;
  }
  const bool big = format == "binary_big_endian";
  uint64_t at = body;
  for (const Element& e : elements) {
    uint64_t record = 0;
    bool lists = false;
    for (const Property& p : e.properties) {
      lists = lists || p.list;
      record += type_size(p.type);
    }
    if (!lists) {  // every instance the same size
      if (record > 0 && e.count > (size - at) / record) ends_inside(e, (size - at) / record);
      at += record * e.count;
      continue;
    }
    for (uint64_t i = 0; i < e.count; ++i) {
      for (const Property& p : e.properties) {
        const uint64_t s = type_size(p.list ? p.count_type : p.type);
        if (size - at < s) ends_inside(e, i);
        if (!p.list) {
          at += s;
          continue;
        }
        // The list's length: an integer of s bytes, in the file's byte order.
        uint64_t n = 0;
        for (uint64_t k = 0; k < s; ++k) {
          n = n << 8 | static_cast<unsigned char>(bytes[at + (big ? k : s - 1 - k)]);
        }
        if (signed_type(p.count_type) && (n >> (8 * s - 1)) != 0) {
          fail("element '" + e.name + "' " + std::to_string(i) + ": a list of negative length");
        }
        at += s;
        const uint64_t item = type_size(p.type);
        if (n > (size - at) / item) ends_inside(e, i);
        at += n * item;
      }
    }
  }
}

std::string one_line(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) text.pop_back();
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text.empty() ? std::string("Assimp gives no reason") : text;
}

}  // namespace

void load_ply(const std::string& bytes, TriangleMesh& mesh) {
  const std::string& path = mesh.source;
  auto fail = [&](const std::string& what) { throw InputError(path + ": " + what); };
  if (bytes.empty()) fail("malformed PLY: the file is empty");
  // The magic line itself, so that Assimp, given a file of another format named
  // .ply, cannot pass it to another importer that recognizes it.
  if (bytes.compare(0, 4, "ply\n") != 0 && bytes.compare(0, 5, "ply\r\n") != 0) {
    fail("malformed PLY: it does not start with the line 'ply'");
  }
  check_layout(bytes, path);

  Assimp::Importer importer;
  // Validation first (it runs before any other step: every face index within the
  // vertices, before triangulation reads them), then triangulation only: no normals
  // are generated (a file without normals has none) and no vertices joined (the
  // file's indexing is kept).
  const aiScene* scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(),
                                                     aiProcess_ValidateDataStructure | aiProcess_Triangulate, "ply");
  if (!scene) fail("malformed PLY: " + one_line(importer.GetErrorString()));

  IndexedMesh m;
  bool normals = true, uvs = true;
  for (unsigned int i = 0; i < scene->mNumMeshes; ++i) {
    const aiMesh* a = scene->mMeshes[i];
    const size_t base = m.positions.size();
    normals = normals && a->HasNormals();
    uvs = uvs && a->HasTextureCoords(0);
    for (unsigned int v = 0; v < a->mNumVertices; ++v) {
      const aiVector3D& p = a->mVertices[v];
      m.positions.push_back(vec3(p.x, p.y, p.z));
      if (normals) m.normals.push_back(vec3(a->mNormals[v].x, a->mNormals[v].y, a->mNormals[v].z));
      // Mitsuba 3 reads a PLY's v as it is (its ply plugin's flip_tex_coords is false
      // by default): v = 0 is the image's top row there, as in a mesh here. Assimp
      // gives the file's u, v (or s, t; texture_u, texture_v) unchanged.
      if (uvs) m.uvs.push_back(vec2(a->mTextureCoords[0][v].x, a->mTextureCoords[0][v].y));
    }
    for (unsigned int f = 0; f < a->mNumFaces; ++f) {
      const aiFace& face = a->mFaces[f];
      if (face.mNumIndices < 3) {  // a point or an edge: no area
        ++mesh.dropped_degenerate;
        continue;
      }
      if (face.mNumIndices > 3) fail("malformed PLY: face " + std::to_string(f) + " was not triangulated");
      std::array<uint32_t, 3> t;
      for (int k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= a->mNumVertices) {
          fail("malformed PLY: face " + std::to_string(f) + ": vertex index " + std::to_string(face.mIndices[k]) +
               " is out of range (" + std::to_string(a->mNumVertices) + " vertices)");
        }
        t[k] = static_cast<uint32_t>(base + face.mIndices[k]);
      }
      m.triangles.push_back(t);
    }
  }
  if (!normals) m.normals.clear();
  if (!uvs) m.uvs.clear();
  add_indexed_mesh(m, mesh);
}

}  // namespace wt

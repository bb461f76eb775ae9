// The mesh formats read beside OBJ and glTF, for Mitsuba 3 scenes: Stanford PLY
// through Assimp (mesh_ply.cpp) and Mitsuba's own serialized meshes (read here by
// hand, mesh_serialized.cpp), and what they share with mesh_load.cpp, which
// dispatches to them by extension (docs/scene-format.md, "Reading mesh files").
// Internal to src/scene: load_mesh (mesh_load.hpp) is the interface.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "scene/mesh_load.hpp"

namespace wt {

// A mesh as an indexed format holds it: an array per vertex attribute and
// triangles over them, every index below positions.size() (the reader checks).
struct IndexedMesh {
  std::vector<vec3> positions;
  std::vector<vec3> normals;  // none, or one per position (as the file gives them)
  std::vector<vec2> uvs;      // none, or one per position; v = 0 the image's top row
  std::vector<std::array<uint32_t, 3>> triangles;
};

// Puts an indexed mesh into `mesh` (its source set, nothing else yet) as the OBJ and
// glTF readers build theirs (mesh_load.cpp's MeshBuilder): a triangle with a
// non-finite corner or of zero area is dropped and counted; the vertices that the
// kept triangles use are kept, in the file's order (all of them, where every vertex
// is used: then the indices are the file's); normals are normalized, and a zero or
// non-finite one (or a non-finite UV) of a used vertex is an error naming the vertex
// by its index in the file; every triangle takes the one material "default",
// lambertian white (as OBJ faces without usemtl). No triangle left is an error.
void add_indexed_mesh(const IndexedMesh& in, TriangleMesh& mesh);

// A .ply file's bytes (read by read_input_file) into `mesh`, through Assimp.
// Throws InputError "<mesh.source>: <what>".
void load_ply(const std::string& bytes, TriangleMesh& mesh);

// A .serialized file's bytes into `mesh`: its shape `shape_index` (0 the first).
// Throws InputError "<mesh.source>: <what>".
void load_serialized(const std::string& bytes, uint32_t shape_index, TriangleMesh& mesh);

}  // namespace wt

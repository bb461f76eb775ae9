// The built-in shapes a scene's mesh entry may name instead of a file (`"shape"`),
// as Mitsuba 3 defines them in their own space, as triangle meshes with normals
// and UVs (docs/scene-format.md, "Meshes and instances"):
// - rectangle: z = 0, x and y in [-1, 1], facing +z; uv = ((x + 1) / 2, (y + 1) / 2);
// - cube: [-1, 1]^3, each face two triangles facing out, its own four corners with
//   the face's normal and uv (0, 0) to (1, 1);
// - disk: z = 0, radius 1, facing +z, a fan of kDiskSegments triangles about the
//   centre; uv = (r, phi / 2 pi), as Mitsuba's disk maps it;
// - cylinder: radius 1 about the z axis from z = 0 to z = 1, open at both ends,
//   facing out, kCylinderSegments quads around; uv = (phi / 2 pi, z).
// Each takes one material, "default" (white Lambertian), which a scene's material
// replaces.
#pragma once

#include <string>
#include <vector>

#include "scene/mesh_load.hpp"

namespace wt {

// 1024 segments leave the polygon's area 6.3e-6 short of the circle's
// (1 - sin(2 pi / n) n / 2 pi): an emitter's power, and an outline's pixels, within
// that of the round shape.
constexpr int kDiskSegments = 1024;
constexpr int kCylinderSegments = 1024;

// The built-in shapes' names.
const std::vector<std::string>& shape_names();

// The shape `name` (one of shape_names()); its source is "<shape name>".
TriangleMesh shape_mesh(const std::string& name);

}  // namespace wt

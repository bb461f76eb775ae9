// Per-vertex tangents for normal maps, as MikkTSpace defines them, so that a normal
// map baked by another tool against MikkTSpace tangents shades as it was baked.
#pragma once

#include <vector>

#include "scene/scene.hpp"

namespace wt {

// Fills scene.tangents (two per vertex of the normal and UV arrays: triangle.hpp)
// and marks the triangles that have normals and UVs kTriangleHasTangents, with
// kTriangleTangentFlipped where their handedness is negative. A vertex's tangent is
// the file's where `file_tangents` gives one (w != 0: its sign is the handedness of
// the triangles at vertex 0's), else built as MikkTSpace builds it:
// - each triangle's dp/du from its corners and UVs, and its handedness from
//   dp/du, dp/dv and the corners' mean normal (the UV map's orientation);
// - at each corner, dp/du projected onto the plane normal to the vertex normal and
//   normalised, weighted by the corner's angle, summed over the triangles of the
//   same handedness that share the vertex, and normalised.
// The shading code interpolates the three corners' tangents and forms the
// bitangent as sign * cross(n, t), MikkTSpace's per-pixel rule. Triangles whose UVs
// are degenerate add nothing; a vertex that gets nothing keeps a zero tangent, and
// the shading falls back to the triangle's own dp/du.
void build_tangents(Scene& scene, const std::vector<vec4>& file_tangents);

}  // namespace wt

#include "scene/mesh_shapes.hpp"

#include <cmath>

#include "errors/errors.hpp"
#include "scene/mesh_formats.hpp"

namespace wt {

namespace {

constexpr double kTwoPi = 6.28318530717958647692;

uint32_t add_vertex(IndexedMesh& m, const vec3& p, const vec3& n, const vec2& uv) {
  m.positions.push_back(p);
  m.normals.push_back(n);
  m.uvs.push_back(uv);
  return static_cast<uint32_t>(m.positions.size() - 1);
}

void add_triangle(IndexedMesh& m, uint32_t a, uint32_t b, uint32_t c) { m.triangles.push_back({a, b, c}); }

// A quad of corners a, b, c, d (counter-clockwise seen from the side n faces).
void add_quad(IndexedMesh& m, const vec3 (&p)[4], const vec3& n, const vec2 (&uv)[4]) {
  uint32_t v[4];
  for (int i = 0; i < 4; ++i) v[i] = add_vertex(m, p[i], n, uv[i]);
  add_triangle(m, v[0], v[1], v[2]);
  add_triangle(m, v[0], v[2], v[3]);
}

void rectangle(IndexedMesh& m) {
  add_quad(m, {vec3(-1, -1, 0), vec3(1, -1, 0), vec3(1, 1, 0), vec3(-1, 1, 0)}, vec3(0, 0, 1),
           {vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 1)});
}

void cube(IndexedMesh& m) {
  // Each face by its normal n and two axes s, t with s x t = n: corners c +- s +- t.
  const vec3 normals[6] = {vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1)};
  for (const vec3& n : normals) {
    const vec3 s = std::fabs(n.y) > 0.5f ? vec3(0, 0, n.y) : vec3(-n.z, 0, n.x);  // about +y, then the poles
    const vec3 t = glm::cross(n, s);
    add_quad(m, {n - s - t, n + s - t, n + s + t, n - s + t}, n, {vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 1)});
  }
}

void disk(IndexedMesh& m) {
  const vec3 n(0, 0, 1);
  for (int i = 0; i < kDiskSegments; ++i) {
    const double a0 = kTwoPi * i / kDiskSegments, a1 = kTwoPi * (i + 1) / kDiskSegments;
    const float u0 = static_cast<float>(i) / kDiskSegments, u1 = static_cast<float>(i + 1) / kDiskSegments;
    const uint32_t c = add_vertex(m, vec3(0), n, vec2(0, 0.5f * (u0 + u1)));
    const uint32_t p0 = add_vertex(m, vec3(std::cos(a0), std::sin(a0), 0), n, vec2(1, u0));
    const uint32_t p1 = add_vertex(m, vec3(std::cos(a1), std::sin(a1), 0), n, vec2(1, u1));
    add_triangle(m, c, p0, p1);
  }
}

void cylinder(IndexedMesh& m) {
  for (int i = 0; i < kCylinderSegments; ++i) {
    const double a0 = kTwoPi * i / kCylinderSegments, a1 = kTwoPi * (i + 1) / kCylinderSegments;
    const float u0 = static_cast<float>(i) / kCylinderSegments, u1 = static_cast<float>(i + 1) / kCylinderSegments;
    const vec3 n0(std::cos(a0), std::sin(a0), 0), n1(std::cos(a1), std::sin(a1), 0);
    const uint32_t b0 = add_vertex(m, n0, n0, vec2(u0, 0)), b1 = add_vertex(m, n1, n1, vec2(u1, 0));
    const uint32_t t1 = add_vertex(m, n1 + vec3(0, 0, 1), n1, vec2(u1, 1));
    const uint32_t t0 = add_vertex(m, n0 + vec3(0, 0, 1), n0, vec2(u0, 1));
    add_triangle(m, b0, b1, t1);
    add_triangle(m, b0, t1, t0);
  }
}

}  // namespace

const std::vector<std::string>& shape_names() {
  static const std::vector<std::string> names = {"rectangle", "cube", "disk", "cylinder"};
  return names;
}

TriangleMesh shape_mesh(const std::string& name) {
  IndexedMesh m;
  if (name == "rectangle") {
    rectangle(m);
  } else if (name == "cube") {
    cube(m);
  } else if (name == "disk") {
    disk(m);
  } else if (name == "cylinder") {
    cylinder(m);
  } else {
    throw InputError("unknown shape '" + name + "'");
  }
  TriangleMesh mesh;
  mesh.source = "<" + name + ">";
  add_indexed_mesh(m, mesh);
  return mesh;
}

}  // namespace wt

// Meshes built in the tests (icosphere, cube, torus, random soups), written as OBJ
// files or put into an in-memory Scene with placements, and the scene file's
// transform (T * Rz * Ry * Rx * S) in double, for the mesh and instance tests.
#pragma once

#include <glm/gtc/matrix_transform.hpp>

#include <array>
#include <cstdint>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "scene/scene.hpp"

namespace wt::test {

struct MeshData {
  std::vector<vec3> v;
  std::vector<std::array<uint32_t, 3>> f;

  vec3 corner(size_t tri, int c) const { return v[f[tri][c]]; }
};

// Turns every face so that its corners run counter-clockwise seen from `outside`
// (the direction from `inside_point` to the face's centroid, or a per-face rule).
template <class Outward>
void orient(MeshData& m, Outward outward) {
  for (auto& t : m.f) {
    const glm::dvec3 a(m.v[t[0]]), b(m.v[t[1]]), c(m.v[t[2]]);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    if (glm::dot(n, outward((a + b + c) / 3.0)) < 0.0) std::swap(t[1], t[2]);
  }
}

// A unit icosphere: an icosahedron whose faces are split in four `levels` times,
// new vertices pushed out to the sphere. Vertices are shared by index, so a shared
// edge is the same two floats in both of its triangles.
inline MeshData icosphere(int levels) {
  MeshData m;
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  const double raw[12][3] = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                             {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  for (const auto& r : raw) m.v.push_back(vec3(glm::normalize(glm::dvec3(r[0], r[1], r[2]))));
  m.f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
         {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
         {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      const uint32_t i = static_cast<uint32_t>(m.v.size());
      m.v.push_back(vec3(glm::normalize(glm::dvec3(m.v[a]) + glm::dvec3(m.v[b]))));
      mid[key] = i;
      return i;
    };
    std::vector<std::array<uint32_t, 3>> next;
    for (const auto& t : m.f) {
      const uint32_t a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]), c = midpoint(t[2], t[0]);
      next.push_back({t[0], a, c});
      next.push_back({t[1], b, a});
      next.push_back({t[2], c, b});
      next.push_back({a, b, c});
    }
    m.f = std::move(next);
  }
  orient(m, [](const glm::dvec3& centroid) { return centroid; });
  return m;
}

// The cube [-1, 1]^3, two triangles a face, split along a diagonal.
inline MeshData cube() {
  MeshData m;
  for (int i = 0; i < 8; ++i) m.v.push_back(vec3((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1));
  const uint32_t quads[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.f.push_back({q[0], q[1], q[2]});
    m.f.push_back({q[0], q[2], q[3]});
  }
  orient(m, [](const glm::dvec3& centroid) { return centroid; });
  return m;
}

// A torus about the y axis (radii R > r), nu x nv quads split in two.
inline MeshData torus(float R, float r, int nu, int nv) {
  MeshData m;
  const double two_pi = 6.283185307179586;
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const double u = two_pi * i / nu, w = two_pi * j / nv;
      m.v.push_back(vec3((R + r * std::cos(w)) * std::cos(u), r * std::sin(w), (R + r * std::cos(w)) * std::sin(u)));
    }
  }
  auto at = [&](int i, int j) { return static_cast<uint32_t>((i % nu) * nv + (j % nv)); };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      m.f.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.f.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  // Outward: away from the tube's centre circle.
  orient(m, [R](const glm::dvec3& c) {
    const glm::dvec3 ring = double(R) * glm::normalize(glm::dvec3(c.x, 0.0, c.z));
    return c - ring;
  });
  return m;
}

// `count` random triangles in [-extent, extent]^3, each of size up to `size`.
inline MeshData triangle_soup(uint32_t seed, int count, float extent, float size) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-extent, extent), off(-size, size);
  MeshData m;
  for (int i = 0; i < count; ++i) {
    const vec3 c(pos(rng), pos(rng), pos(rng));
    const uint32_t base = static_cast<uint32_t>(m.v.size());
    for (int k = 0; k < 3; ++k) m.v.push_back(c + vec3(off(rng), off(rng), off(rng)));
    m.f.push_back({base, base + 1, base + 2});
  }
  return m;
}

// The scene file's transform: T * Rz * Ry * Rx * S (angles in degrees).
inline glm::dmat4 trs(const glm::dvec3& translate, const glm::dvec3& degrees, const glm::dvec3& scale) {
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), translate);
  m = glm::rotate(m, glm::radians(degrees.z), glm::dvec3(0, 0, 1));
  m = glm::rotate(m, glm::radians(degrees.y), glm::dvec3(0, 1, 0));
  m = glm::rotate(m, glm::radians(degrees.x), glm::dvec3(1, 0, 0));
  return glm::scale(m, scale);
}

inline Affine affine_of(const glm::dmat4& m) {
  Affine a;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) a.m[4 * r + c] = static_cast<float>(m[c][r]);
  }
  return a;
}

// A point through a transform in double, rounded once to float.
inline vec3 transformed(const glm::dmat4& m, const vec3& p) { return vec3(m * glm::dvec4(glm::dvec3(p), 1.0)); }

// Writes the mesh as OBJ, its vertices through `m` (in double; printed exactly
// enough to read back the same floats), optionally naming an MTL and a material.
inline void write_obj(const std::string& path, const MeshData& mesh, const glm::dmat4& m = glm::dmat4(1.0),
                      const std::string& mtllib = "", const std::string& usemtl = "") {
  std::ofstream out(path);
  out.precision(9);
  if (!mtllib.empty()) out << "mtllib " << mtllib << "\n";
  for (const vec3& v : mesh.v) {
    const vec3 p = transformed(m, v);
    out << "v " << p.x << " " << p.y << " " << p.z << "\n";
  }
  if (!usemtl.empty()) out << "usemtl " << usemtl << "\n";
  for (const auto& t : mesh.f) out << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
}

// Appends a mesh to an in-memory scene; each triangle's material is its index in
// the scene's triangle arrays before build_bvh, so a test can tell where a
// reordered triangle came from. Returns the mesh's index.
inline int32_t add_mesh(Scene& s, const MeshData& mesh, const std::string& name) {
  SceneMesh sm;
  sm.name = name;
  sm.file = name + ".obj";
  sm.first_triangle = static_cast<uint32_t>(s.triangles.size());
  sm.triangle_count = static_cast<uint32_t>(mesh.f.size());
  for (size_t t = 0; t < mesh.f.size(); ++t) {
    TriangleGeom g{};
    for (int c = 0; c < 3; ++c) {
      const vec3 p = mesh.corner(t, c);
      float* dst = c == 0 ? g.p0 : (c == 1 ? g.p1 : g.p2);
      dst[0] = p.x;
      dst[1] = p.y;
      dst[2] = p.z;
    }
    s.triangle_materials.push_back(static_cast<uint32_t>(s.triangles.size()));
    s.triangles.push_back(g);
    s.triangle_shadings.push_back(TriangleShading{{0, 0, 0}, 0u});
  }
  s.meshes.push_back(sm);
  return static_cast<int32_t>(s.meshes.size() - 1);
}

// Places mesh (or kSpheres) by m; `tag` goes into the material override, which the
// traversal does not read, so that a test can tell which placement a hit is in.
inline void place(Scene& s, int32_t mesh, const glm::dmat4& m, int32_t tag = -1) {
  Placement p;
  p.mesh = mesh;
  p.identity = m == glm::dmat4(1.0);
  p.world_from_object = affine_of(m);
  p.object_from_world = affine_of(glm::inverse(m));
  p.material = tag;
  s.placements.push_back(p);
}

inline vec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<float> n;
  for (;;) {
    const vec3 d(n(rng), n(rng), n(rng));
    if (glm::dot(d, d) > 1e-6f) return glm::normalize(d);
  }
}

}  // namespace wt::test

#include "scene/mesh_tangents.hpp"

#include <cmath>

namespace wt {

namespace {

// The angle at corner a of the triangle (a, b, c).
float corner_angle(const vec3& a, const vec3& b, const vec3& c) {
  const vec3 e1 = b - a, e2 = c - a;
  const float l = glm::length(e1) * glm::length(e2);
  if (!(l > 0.0f)) return 0.0f;
  return std::acos(std::fmin(std::fmax(glm::dot(e1, e2) / l, -1.0f), 1.0f));
}

}  // namespace

void build_tangents(Scene& scene, const std::vector<vec4>& file_tangents) {
  constexpr uint32_t kBoth = kTriangleHasNormals | kTriangleHasUvs;
  scene.tangents.assign(2 * scene.normals.size(), vec3(0.0f));
  std::vector<bool> given(scene.normals.size(), false);
  for (size_t v = 0; v < scene.normals.size() && v < file_tangents.size(); ++v) {
    if (file_tangents[v].w != 0.0f) {
      given[v] = true;
      scene.tangents[2 * v] = scene.tangents[2 * v + 1] = vec3(file_tangents[v]);
    }
  }
  for (size_t i = 0; i < scene.triangles.size(); ++i) {
    TriangleShading& sh = scene.triangle_shadings[i];
    if ((sh.flags & kBoth) != kBoth) continue;
    const TriangleGeom& tri = scene.triangles[i];
    const uint32_t* v = sh.vertex;
    const vec3 p[3] = {tri.corner(0), tri.corner(1), tri.corner(2)};
    const vec2 t0 = scene.uvs[v[0]], t1 = scene.uvs[v[1]], t2 = scene.uvs[v[2]];
    const vec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    const vec2 d1 = t1 - t0, d2 = t2 - t0;
    const float det = d1.x * d2.y - d1.y * d2.x;
    float sign;
    vec3 dpdu(0.0f);
    if (det != 0.0f) {
      vec3 dpdv;
      uv_derivatives(e1, e2, d1, d2, det, dpdu, dpdv);
      // The shading code's rule, about the corners' mean normal.
      sign = uv_handedness(scene.normals[v[0]] + scene.normals[v[1]] + scene.normals[v[2]], dpdu, dpdv);
    } else {
      sign = 1.0f;
    }
    if (given[v[0]]) sign = file_tangents[v[0]].w;
    const uint32_t slot = sign < 0.0f ? 1u : 0u;
    sh.flags |= kTriangleHasTangents | (slot ? kTriangleTangentFlipped : 0u);
    if (det == 0.0f) continue;
    for (int c = 0; c < 3; ++c) {
      if (given[v[c]]) continue;
      const vec3& n = scene.normals[v[c]];
      const vec3 t = dpdu - n * glm::dot(n, dpdu);
      const float len = glm::length(t);
      if (!(len > 0.0f) || !std::isfinite(len)) continue;
      scene.tangents[2 * v[c] + slot] += corner_angle(p[c], p[(c + 1) % 3], p[(c + 2) % 3]) * (t / len);
    }
  }
  for (size_t v = 0; v < scene.normals.size(); ++v) {
    if (given[v]) continue;
    for (size_t s = 0; s < 2; ++s) {
      vec3& t = scene.tangents[2 * v + s];
      const float len = glm::length(t);
      t = len > 0.0f && std::isfinite(len) ? t / len : vec3(0.0f);
    }
  }
}

}  // namespace wt

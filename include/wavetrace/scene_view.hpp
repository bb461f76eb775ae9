// A scene as the tracing code sees it: flat arrays in one memory (host or device).
#pragma once

#include "wavetrace/camera.hpp"
#include "wavetrace/distribution.hpp"
#include "wavetrace/geometry/geometry.hpp"
#include "wavetrace/lights.hpp"
#include "wavetrace/material.hpp"
#include "wavetrace/sky.hpp"

namespace wt {

// The settings of one render that the per-path code needs.
struct RenderParams {
  int32_t width;
  int32_t height;
  int32_t spp;
  int32_t depth;           // the most rays a path may trace
  int32_t roulette_depth;  // Russian roulette from this many bounces on
  uint32_t seed;
  int32_t nee = 1;         // 1: sample the emitters at every diffuse hit (next-event estimation); 0: not
};

// Scene access through plain pointers (global memory on the GPU, host memory on
// the CPU). The constant-memory megakernel has an accessor of the same shape.
// The accessor functions are the ones geometry/geometry.hpp names.
struct SceneView {
  const BvhNode* nodes;  // the top level over instances first, then each instance's
  const Instance* instances;
  const SphereGeom* spheres;
  const uint32_t* sphere_materials;
  const TriangleGeom* triangles;
  const TriangleShading* triangle_shadings;
  const uint32_t* triangle_materials;
  const vec3* normals;
  const vec2* uvs;
  const Material* materials;
  const Texture* textures;
  const ImageView* images;
  const LightRef* lights;   // every emitter, for next-event estimation
  const float* light_cdf;   // light_cdf[i]: the probability of picking lights 0..i (the last is 1)
  int32_t light_total;
  float light_power;        // the emitters' summed power (light_power_of), which picks them
  // The sky as a light (lights.hpp's kSkyLight): the probability of picking it (0:
  // the sky is not sampled), and the environment's table (rows 0: none).
  float sky_pick;
  PiecewiseConstant2D environment;
  int32_t node_total;
  uint32_t kinds;  // the primitive kinds present (geometry.hpp), for choosing a kernel
  Sky sky;
  Camera camera;

  WT_HD int node_count() const { return node_total; }
  WT_HD BvhNode node(int i) const { return nodes[i]; }
  WT_HD const Instance& instance(int i) const { return instances[i]; }
  WT_HD SphereGeom sphere(int i) const { return spheres[i]; }
  WT_HD uint32_t sphere_material(int i) const { return sphere_materials[i]; }
  WT_HD TriangleGeom triangle(int i) const { return triangles[i]; }
  WT_HD TriangleShading triangle_shading(int i) const { return triangle_shadings[i]; }
  WT_HD uint32_t triangle_material(int i) const { return triangle_materials[i]; }
  WT_HD vec3 normal(uint32_t i) const { return normals[i]; }
  WT_HD vec2 uv(uint32_t i) const { return uvs[i]; }
  WT_HD const Material& material(uint32_t i) const { return materials[i]; }
  WT_HD const Texture* texture_array() const { return textures; }
  WT_HD const ImageView* image_array() const { return images; }
  WT_HD int light_count() const { return light_total; }
  WT_HD LightRef light(int i) const { return lights[i]; }
  WT_HD float light_cdf_at(int i) const { return light_cdf[i]; }
  WT_HD float total_light_power() const { return light_power; }
  WT_HD float sky_light_pick() const { return sky_pick; }
  WT_HD const PiecewiseConstant2D& environment_table() const { return environment; }
};

}  // namespace wt

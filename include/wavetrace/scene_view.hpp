// A scene as the tracing code sees it: flat arrays in one memory (host or device).
#pragma once

#include "wavetrace/bvh.hpp"
#include "wavetrace/camera.hpp"
#include "wavetrace/material.hpp"
#include "wavetrace/sky.hpp"

namespace wt {

struct alignas(16) SphereGeom {
  float x, y, z, w;  // centre and radius
};

// The settings of one render that the per-path code needs.
struct RenderParams {
  int32_t width;
  int32_t height;
  int32_t spp;
  int32_t depth;           // the most rays a path may trace
  int32_t roulette_depth;  // Russian roulette from this many bounces on
  uint32_t seed;
};

// Scene access through plain pointers (global memory on the GPU, host memory on
// the CPU). The constant-memory megakernel has an accessor of the same shape.
struct SceneView {
  const SphereGeom* spheres;
  const uint32_t* sphere_material;
  const BvhNode* nodes;
  const Material* materials;
  const Texture* textures;
  const ImageView* images;
  int32_t sphere_count;
  int32_t node_total;
  Sky sky;
  Camera camera;

  WT_HD int node_count() const { return node_total; }
  WT_HD BvhNode node(int i) const { return nodes[i]; }
  WT_HD SphereGeom sphere(int i) const { return spheres[i]; }
  WT_HD const Material& material_of(int sphere) const { return materials[sphere_material[sphere]]; }
  WT_HD const Texture* texture_array() const { return textures; }
  WT_HD const ImageView* image_array() const { return images; }
};

}  // namespace wt

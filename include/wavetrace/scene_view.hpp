// A scene as the tracing code sees it: flat arrays in one memory (host or device).
#pragma once

#include "wavetrace/camera.hpp"
#include "wavetrace/distribution.hpp"
#include "wavetrace/geometry/geometry.hpp"
#include "wavetrace/lights.hpp"
#include "wavetrace/bsdf.hpp"
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

}  // namespace wt

// The scene's arrays, declared once. Each line names the element type, the array
// (a std::vector in the host Scene, a pointer in SceneView, a device buffer in the
// uploaded scene, an offset in the constant-memory pool), the accessor through
// which the tracing code reads one element, what that accessor returns and the
// index it takes. The return and the index are the kernels' own, kept as they were
// before the list: an element read by value is loaded whole and at once, and a
// signed index lets the compiler fold `i + 1` into the address (references and
// unsigned indices everywhere cost each intersect kernel 8 PTX instructions). The
// host scene's members, the host and device views, the upload, the constant-memory
// layout and its size check, and the device byte count all follow from this list
// (docs/architecture.md, "Where a new thing goes"). Two things of the scene are not
// plain arrays and are named where they are used: its images (decoded texels on the
// host, texture objects on the device) and the environment's sampling table (a
// struct with a view of its own, kept in global memory by every kernel).
//
// The top-level nodes come first, then each tree's; the instances are in top-level
// order; spheres and triangles are in BVH order, every mesh's triangles one range;
// normals and uvs are per vertex, of the meshes that have them, and tangents two per
// such vertex (triangle.hpp), where the scene has a normal map; material_params
// hold the microfacet kinds' parameters and bsdf_tables their energy tables
// (bsdfs/energy.hpp); the lights are every
// emitter, for next-event estimation, and light_cdf[i] the probability of picking
// lights 0..i; punctual_lights are the lights of no extent (lights.hpp), among the
// lights as kPunctualLight; alpha_tests are the alpha-tested materials' (a
// triangle's `alpha` names its own).
#define WT_SCENE_ARRAYS(X)                                                        \
  X(BvhNode, nodes, node, BvhNode, int)                                           \
  X(Instance, instances, instance, const Instance&, int)                          \
  X(SphereGeom, spheres, sphere, SphereGeom, int)                                 \
  X(uint32_t, sphere_materials, sphere_material, uint32_t, int)                   \
  X(TriangleGeom, triangles, triangle, TriangleGeom, int)                         \
  X(TriangleShading, triangle_shadings, triangle_shading, TriangleShading, int)   \
  X(uint32_t, triangle_materials, triangle_material, uint32_t, int)               \
  X(vec3, normals, normal, vec3, uint32_t)                                        \
  X(vec2, uvs, uv, vec2, uint32_t)                                                \
  X(vec3, tangents, tangent, vec3, uint32_t)                                      \
  X(Material, materials, material, const Material&, uint32_t)                     \
  X(MaterialParams, material_params, material_param, const MaterialParams&, int)  \
  X(float, bsdf_tables, bsdf_table, float, int)                                   \
  X(Texture, textures, texture, const Texture&, uint32_t)                         \
  X(LightRef, lights, light, LightRef, int)                                       \
  X(float, light_cdf, light_cdf_at, float, int)                                   \
  X(PunctualLight, punctual_lights, punctual_light, PunctualLight, int)           \
  X(AlphaTest, alpha_tests, alpha_test, AlphaTest, int)

namespace wt {

// What every view of a scene holds besides its arrays, and its accessors.
struct SceneScalars {
  int32_t node_total;
  int32_t light_total;
  int32_t punctual_total;  // punctual_lights' count
  float light_power;  // the emitters' summed power (light_power_of), which picks them
  // The sky as a light (lights.hpp's kSkyLight): the probability of picking it (0:
  // the sky is not sampled), and the environment's table (rows 0: none).
  float sky_pick;
  PiecewiseConstant2D environment;
  uint32_t kinds;  // the primitive kinds present (geometry.hpp), for choosing a kernel
  Sky sky;
  Camera camera;

  WT_HD int node_count() const { return node_total; }
  WT_HD int light_count() const { return light_total; }
  WT_HD int punctual_count() const { return punctual_total; }
  // Whether paths sample lights (the kernels' kLightSampling): where next-event
  // estimation is on and there are lights, and wherever there are punctual lights,
  // which nothing else reaches.
  WT_HD bool samples_lights(const RenderParams& rp) const {
    return (rp.nee != 0 && light_total > 0) || punctual_total > 0;
  }
  WT_HD float total_light_power() const { return light_power; }
  WT_HD float sky_light_pick() const { return sky_pick; }
  WT_HD const PiecewiseConstant2D& environment_table() const { return environment; }
};

#define WT_SCENE_VIEW_POINTER(T, array, at, Return, Index) const T* array;
#define WT_SCENE_VIEW_AT(T, array, at, Return, Index) \
  WT_HD Return at(Index i) const { return array[i]; }

// Scene access through plain pointers (global memory on the GPU, host memory on
// the CPU). The constant-memory megakernel has an accessor of the same shape.
// The accessor functions are the ones geometry/geometry.hpp names.
struct SceneView : SceneScalars {
  WT_SCENE_ARRAYS(WT_SCENE_VIEW_POINTER)
  const ImageView* images;

  WT_SCENE_ARRAYS(WT_SCENE_VIEW_AT)
  // The texture and BSDF code take these arrays whole.
  WT_HD const Texture* texture_array() const { return textures; }
  WT_HD const MaterialParams* material_param_array() const { return material_params; }
  WT_HD const float* bsdf_table_array() const { return bsdf_tables; }
  WT_HD const ImageView* image_array() const { return images; }
};

#undef WT_SCENE_VIEW_POINTER
#undef WT_SCENE_VIEW_AT

}  // namespace wt

// The host-side scene: what a scene file describes, validated and ready to upload.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "render/settings.hpp"
#include "scene/bvh_build.hpp"
#include "scene/environment_distribution.hpp"
#include "wavetrace/scene_view.hpp"

namespace wt {


struct Image {
  std::string path;  // as resolved from the scene file
  int width = 0, height = 0;
  std::vector<float> texels;  // RGBA, linear, row 0 = top
  bool srgb_decoded = false;  // its 8-bit colours went through the sRGB decoding curve
  // Mip levels 1, 2, ... (image_mips.hpp), one below the other, max(width / 2, 1)
  // texels wide (texture.hpp's ImageView says how they are laid out); `levels`
  // counts level 0 too (1: none built).
  int levels = 1;
  std::vector<float> mip_texels;
};

// The bounds of a scene's numbers, refused at load beyond them, so that no product the
// renderer forms of them leaves float's range (3.4e38): a radiance (an emission, a
// sky's colour, an environment texel times its intensity) of at most 1e9, so that a
// film's sum over the most samples (1e6) with the estimators' weights stays finite;
// a position's coordinates and a radius of at most 1e15 in magnitude, so that squared
// distances and cross products (1e30) do.
constexpr float kMaxRadiance = 1e9f;
constexpr float kMaxCoordinate = 1e15f;

// How long each host-side phase of loading a scene took, in seconds (wall clock).
// Uploading to the device is timed by the backend (RenderResult::upload_seconds).
struct LoadTimes {
  double parse = 0;         // reading the file and parsing the JSON
  double validate = 0;      // checking every field and building the scene's arrays
  double texture_load = 0;  // decoding image textures (not part of validate)
  double mesh_load = 0;  // reading mesh files (not part of validate)
  double bvh_build = 0;
};

// One mesh file as the scene holds it: a range of the scene's triangle arrays,
// with its own BVH, however many instances place it.
struct SceneMesh {
  std::string name;
  std::string file;
  uint32_t first_triangle = 0;
  uint32_t triangle_count = 0;
  size_t dropped_degenerate = 0;  // triangles the loader dropped (mesh_load.hpp)
  size_t dropped_nan = 0;
  std::vector<std::string> warnings;  // what the file holds that is not rendered (mesh_load.hpp)
  std::vector<PunctualLight> lights;  // the file's punctual lights, in its space: each instance places them
  BvhStats bvh;
};

// Where a group of primitives stands in the world: one entry of the scene file's
// `instances` (or the spheres, which stand untransformed).
struct Placement {
  int32_t mesh;  // index into Scene::meshes; kSpheres: the scene's spheres
  Affine world_from_object;
  Affine object_from_world;
  bool identity;
  int32_t material;  // an override; < 0: the primitives' own
};
constexpr int32_t kSpheres = -1;

struct Scene {
  std::string source;  // the scene file
  CameraSpec camera;
  Sky sky{SkyKind::Gradient, vec3(1.0f), vec3(0.5f, 0.7f, 1.0f)};
  RenderDefaults render;
  std::vector<Image> images;
  std::vector<std::string> material_names;  // per material
  std::vector<SceneMesh> meshes;
  std::vector<Placement> placements;
  // The scene file's own `lights` (punctual, in world space), beside those its mesh
  // files place.
  std::vector<PunctualLight> file_lights;
  // What the scene file says is not rendered as its source meant (a Mitsuba scene's
  // mapping: mitsuba_scene.hpp), one line each.
  std::vector<std::string> warnings;
  // The arrays that the renderer reads (scene_view.hpp's list; the comments there
  // say what each holds). The scene file fills the materials, textures, spheres and
  // the meshes' triangle arrays, one contiguous range per mesh; build_bvh puts the
  // primitives in BVH order and fills the nodes (the top level first, then the
  // spheres' and each mesh's tree) and the instances in top-level order. The lights
  // are every emissive primitive of every instance, with the material it shades
  // with, and light_cdf the table that picks them by power (lights.hpp).
#define WT_SCENE_VECTOR(T, array, at, Return, Index) std::vector<T> array;
  WT_SCENE_ARRAYS(WT_SCENE_VECTOR)
#undef WT_SCENE_VECTOR
  // The sky is one of the lights (kSkyLight) where it is sampled: sky_pick is then
  // the probability of picking it, and `environment` its table where it has one.
  float light_power = 0.0f;
  float sky_pick = 0.0f;
  EnvironmentDistribution environment;
  BvhStats top_level_bvh;
  BvhStats sphere_bvh;
  LoadTimes load_times;

  // Triangles placed, counting each instance's: what the scene renders.
  size_t instanced_triangles() const;
  // What the scene holds, for --stats and the benchmark.
  struct Summary;
  Summary summary() const;
  // The primitive kinds the scene places (geometry.hpp's bits).
  uint32_t primitive_kinds() const;
  // The primitive kinds, kMicrofacet where a material has parameters beyond the
  // study's (the microfacet kinds, normal maps), and kLayersAndAlpha where a
  // triangle is alpha-tested or a principled material has a coat, transmission or a
  // volume: the kernel the scene needs (geometry.hpp's with_kinds).
  uint32_t kernel_kinds() const;
  // What the scene's arrays and images take on the device.
  size_t device_bytes() const;

  // Number of low bits that hold every sort key the scene's materials use (at least 1).
  int sort_key_bits() const;
};

// The scene's geometry in numbers: counts, what the loader dropped, and each BVH's
// shape and SAH cost.
struct Scene::Summary {
  size_t spheres = 0;
  size_t triangles = 0;            // stored: each mesh once
  size_t instanced_triangles = 0;  // placed: each instance's
  size_t instances = 0;            // top-level entries (the spheres count as one)
  size_t dropped_degenerate = 0;
  size_t dropped_nan = 0;
  size_t bvh_nodes = 0;  // all levels
  size_t device_bytes = 0;
  BvhStats top_level_bvh;
  BvhStats sphere_bvh;
  std::vector<SceneMesh> meshes;
};

// Reads, validates and prepares (BVH built, sort keys set) a scene file.
// Throws InputError naming the file and the field.
Scene load_scene(const std::string& path);

// The same from JSON text; `source` names the file in messages and anchors
// relative texture paths.
Scene parse_scene(const std::string& json_text, const std::string& source);

// Builds the bottom-level BVHs (over the spheres, and over each mesh's triangles,
// reordering their arrays), the instances and the top-level BVH over them.
void build_bvh(Scene& scene);

// What every view of the scene holds besides its arrays, for a render of
// width x height, with the environment's table as the view's memory holds it.
SceneScalars scene_scalars(const Scene& scene, int width, int height, const PiecewiseConstant2D& environment);

// A host view of the scene (pointers into `scene`) for a render of width x height,
// for the CPU backend.
SceneView host_view(const Scene& scene, int width, int height, std::vector<ImageView>& image_views);

}  // namespace wt

// The scene-file reader (docs/scene-format.md), one source file per section:
// scene_json.cpp (the document, shared field readers, loading), scene_camera.cpp
// (camera, sky, render), scene_textures.cpp, scene_materials.cpp, scene_geometry.cpp
// (spheres), scene_meshes.cpp (meshes and instances); scene_bvh.cpp builds the BVHs.
// Internal to src/scene; the rest of the project calls load_scene / parse_scene.
#pragma once

#include <chrono>
#include <filesystem>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "scene/bsdf_tables.hpp"
#include "scene/height_maps.hpp"
#include "scene/json_reader.hpp"
#include "scene/mesh_formats.hpp"
#include "scene/mesh_load.hpp"
#include "scene/scene.hpp"

namespace wt {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Reads one scene document; holds what later sections look up in earlier ones.
class SceneReader : JsonReader {
 public:
  SceneReader(const std::string& source, Scene& scene) : JsonReader(source), scene_(scene) {
    base_dir_ = std::filesystem::path(source).parent_path();
  }

  void read(const json& root);

  double texture_seconds() const { return texture_seconds_; }
  double mesh_seconds() const { return mesh_seconds_; }

 private:
  // Field readers shared by the sections (scene_json.cpp).
  const std::string& name(const json& obj, const JsonPath& path) const;
  vec3 triple(const json& j, const JsonPath& path) const;
  vec2 pair(const json& j, const JsonPath& path) const;
  vec3 colour(const json& j, const JsonPath& path) const;
  // Each component in [0, kMaxRadiance].
  vec3 radiance(const json& j, const JsonPath& path) const;
  // Each coordinate within +-kMaxCoordinate.
  vec3 position(const json& j, const JsonPath& path) const;
  // Reads obj["type"] and returns its index in `types`.
  size_t type_of(const json& obj, const JsonPath& path, const std::string& what,
                 const std::vector<std::string>& types) const;

  // scene_camera.cpp
  void read_camera(const json& j, const JsonPath& path);
  // A camera that a mesh file holds (`"camera": {"gltf": MESH, "index": N}`), placed
  // once the meshes and instances are read.
  void place_mesh_camera();
  void read_sky(const json& j, const JsonPath& path);
  void read_render(const json& j, const JsonPath& path);

  // scene_textures.cpp
  void read_texture(const json& j, const JsonPath& path);
  // Textures that name the same file in the same colorspace share one image.
  // `file` relative to the scene file; an error names the field.
  int32_t image(const std::string& file, bool srgb, const JsonPath& path);
  // `resolved` as it is; an error names `referrer` (a mesh file whose material uses
  // it). `embedded`: the encoded bytes of an image held in that file, `resolved` its key.
  int32_t image_file(const std::string& resolved, bool srgb, const std::string& referrer,
                     const std::string* embedded = nullptr);
  // The image's index, or -1 with the reason in `why`.
  int32_t image_at(const std::string& resolved, bool srgb, std::string& why, const std::string* embedded = nullptr);
  // A bump map's texture: `heights` (an image texture, linear) with its image
  // replaced by the image of its heights' derivatives (height_gradient; one per
  // image, channel and wrap), its transform and filters kept.
  int32_t bump_texture(const Texture& heights, HeightChannel channel);

  // scene_materials.cpp
  void read_material(const json& j, const JsonPath& path);
  void read_params(const json& j, const JsonPath& path, Material& m);
  void read_blend(const json& j, const JsonPath& path, Material& m);
  // How many blends deep m is (0: not a blend).
  int blend_depth(const Material& m) const;
  // A texture by name (the field's value); an error names the field.
  int32_t texture_named(const json& j, const JsonPath& path) const;

  // scene_lights.cpp
  void read_light(const json& j, const JsonPath& path);

  // scene_geometry.cpp
  void read_sphere(const json& j, const JsonPath& path);

  // scene_meshes.cpp
  void read_meshes(const json& list, const JsonPath& path);
  // `alpha`: the mesh entry's own (with its material), or null.
  void add_mesh(const TriangleMesh& mesh, const std::string& name, int32_t material_override,
                const AlphaTest* alpha = nullptr);
  // A mesh entry's own arrays (positions, indices, normals, uvs).
  IndexedMesh read_mesh_arrays(const json& j, const JsonPath& path) const;
  // A mesh entry's `alpha`: the test, its luminance image made where it reads that.
  AlphaTest read_alpha(const json& j, const JsonPath& path);
  void read_instance(const json& j, const JsonPath& path);
  // A material's index by its name in the scene file.
  int32_t material_named(const json& j, const JsonPath& path) const;

  // Name -> (index, JSON path of the definition).
  using Names = std::map<std::string, std::pair<size_t, std::string>>;

  void remember(Names& names, const std::string& n, size_t index, const char* what, const JsonPath& path) const;

  Scene& scene_;
  std::filesystem::path base_dir_;
  Names texture_names_;
  Names material_names_;
  // Where the tables that materials share (the conductors', the principled layers')
  // are in bsdf_tables.
  SharedTables shared_tables_;
  Names mesh_names_;
  std::vector<std::vector<MeshCamera>> mesh_cameras_;  // each mesh file's, by mesh index
  struct MeshCameraChoice {
    std::string mesh;
    size_t index = 0;
    bool chosen = false;
  } mesh_camera_;
  std::map<std::pair<std::string, bool>, int32_t> images_;
  // height_gradient's images by (height image, channel, wrap u, wrap v).
  std::map<std::tuple<int32_t, HeightChannel, Wrap, Wrap>, int32_t> gradients_;
  double texture_seconds_ = 0;
  double mesh_seconds_ = 0;
  // The mesh files' own tangents, per vertex of the scene's normal and UV arrays
  // (w = 0 where a file gives none), for build_tangents.
  std::vector<vec4> file_tangents_;
};

}  // namespace wt

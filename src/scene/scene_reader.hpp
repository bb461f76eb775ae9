// The scene-file reader (docs/scene-format.md), one source file per section:
// scene_json.cpp (the document, shared field readers, loading), scene_camera.cpp
// (camera, sky, render), scene_textures.cpp, scene_materials.cpp, scene_geometry.cpp.
// Internal to src/scene; the rest of the project calls load_scene / parse_scene.
#pragma once

#include <chrono>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "scene/json_reader.hpp"
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

 private:
  // Field readers shared by the sections (scene_json.cpp).
  const std::string& name(const json& obj, const JsonPath& path) const;
  vec3 triple(const json& j, const JsonPath& path) const;
  vec3 colour(const json& j, const JsonPath& path) const;
  vec3 radiance(const json& j, const JsonPath& path) const;
  // Reads obj["type"] and returns its index in `types`.
  size_t type_of(const json& obj, const JsonPath& path, const std::string& what,
                 const std::vector<std::string>& types) const;

  // scene_camera.cpp
  void read_camera(const json& j, const JsonPath& path);
  void read_sky(const json& j, const JsonPath& path);
  void read_render(const json& j, const JsonPath& path);

  // scene_textures.cpp
  void read_texture(const json& j, const JsonPath& path);
  // Textures that name the same file in the same colorspace share one image.
  int32_t image(const std::string& file, bool srgb, const JsonPath& path);

  // scene_materials.cpp
  void read_material(const json& j, const JsonPath& path);

  // scene_geometry.cpp
  void read_sphere(const json& j, const JsonPath& path);

  // Name -> (index, JSON path of the definition).
  using Names = std::map<std::string, std::pair<size_t, std::string>>;

  void remember(Names& names, const std::string& n, size_t index, const char* what, const JsonPath& path) const;

  Scene& scene_;
  std::filesystem::path base_dir_;
  Names texture_names_;
  Names material_names_;
  std::map<std::pair<std::string, bool>, int32_t> images_;
  double texture_seconds_ = 0;
};

}  // namespace wt

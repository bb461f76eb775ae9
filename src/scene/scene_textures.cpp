// Scene files: textures, and the images that image textures read.
#include <stb/stb_image.h>

#include <utility>

#include "scene/scene_reader.hpp"
#include "wavetrace/film.hpp"

namespace wt {

void SceneReader::read_texture(const json& j, const JsonPath& path) {
  object(j, path);
  remember(texture_names_, name(j, path), scene_.textures.size(), "texture", path);
  size_t type = type_of(j, path, "texture", {"checker", "noise", "image"});
  Texture t{};
  t.image = -1;
  if (type == 0) {
    check_keys(j, path, {"name", "type", "size", "even", "odd"}, "checker");
    t.kind = TextureKind::Checker;
    t.scale = positive(required(j, path, "size"), path / "size");
    t.a = colour(required(j, path, "even"), path / "even");
    t.b = colour(required(j, path, "odd"), path / "odd");
  } else if (type == 1) {
    check_keys(j, path, {"name", "type", "scale", "octaves", "high", "low"}, "noise");
    t.kind = TextureKind::Noise;
    t.scale = positive(required(j, path, "scale"), path / "scale");
    t.octaves = j.contains("octaves") ? static_cast<int32_t>(integer(j["octaves"], path / "octaves", 1, 16)) : 7;
    t.a = colour(required(j, path, "high"), path / "high");
    t.b = colour(required(j, path, "low"), path / "low");
  } else {
    check_keys(j, path, {"name", "type", "file", "colorspace"}, "image");
    t.kind = TextureKind::Image;
    bool srgb = true;
    if (j.contains("colorspace")) {
      std::string cs = string(j["colorspace"], path / "colorspace");
      if (cs != "srgb" && cs != "linear") {
        fail_at(path / "colorspace", "unknown colorspace '" + cs + "' (expected srgb, linear)");
      }
      srgb = cs == "srgb";
    }
    t.image = image(string(required(j, path, "file"), path / "file"), srgb, path / "file");
  }
  scene_.textures.push_back(t);
}

int32_t SceneReader::image(const std::string& file, bool srgb, const JsonPath& path) {
  std::string resolved = (base_dir_ / file).lexically_normal().string();
  std::string why;
  int32_t index = image_at(resolved, srgb, why);
  if (index < 0) fail_at(path, "cannot read image '" + resolved + "' (" + why + ")");
  return index;
}

int32_t SceneReader::image_file(const std::string& resolved, bool srgb, const std::string& referrer) {
  std::string why;
  int32_t index = image_at(resolved, srgb, why);
  if (index < 0) throw SceneError(referrer + ": cannot read texture image '" + resolved + "' (" + why + ")");
  return index;
}

int32_t SceneReader::image_at(const std::string& resolved, bool srgb, std::string& why) {
  auto known = images_.find({resolved, srgb});
  if (known != images_.end()) return known->second;

  const auto start = Clock::now();
  // Read in the file's own channels and widened to RGBA here: stb 2.27 (Debian
  // bookworm) reads past its buffer when it converts a 16-bit PNM to 4 channels.
  int w = 0, h = 0, channels = 0;
  stbi_uc* data = stbi_load(resolved.c_str(), &w, &h, &channels, 0);
  if (!data) {
    why = stbi_failure_reason();
    return -1;
  }
  Image im;
  im.path = resolved;
  im.width = w;
  im.height = h;
  im.texels.resize(static_cast<size_t>(w) * h * 4);
  for (size_t i = 0; i < im.texels.size(); ++i) {
    const stbi_uc* texel = data + i / 4 * channels;
    bool alpha = i % 4 == 3;
    // grey: g g g 1; grey + alpha: g g g a; RGB: r g b 1; RGBA.
    float v = alpha ? (channels % 2 == 0 ? texel[channels - 1] / 255.0f : 1.0f)
                    : texel[channels >= 3 ? i % 4 : 0] / 255.0f;
    im.texels[i] = srgb && !alpha ? decode_srgb(v) : v;
  }
  stbi_image_free(data);
  texture_seconds_ += seconds_since(start);

  int32_t index = static_cast<int32_t>(scene_.images.size());
  scene_.images.push_back(std::move(im));
  images_.emplace(std::make_pair(resolved, srgb), index);
  return index;
}

}  // namespace wt

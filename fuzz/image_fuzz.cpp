// The image loading path as a scene file drives it: the input becomes the file of
// an image texture, read by the scene reader (stb, then the conversion to linear
// floats). A InputError (an unreadable image) is a clean rejection.
#include <stb/stb_image.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "errors/errors.hpp"
#include "scene/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // A few bytes can claim a huge image that stb then fills in (a truncated RLE TGA
  // of 13757 x 13066 takes seconds and gigabytes): the scene reader sets no size
  // limit, so such inputs would only time out. Stay at 1 Mi texels.
  int w = 0, h = 0, channels = 0;
  if (stbi_info_from_memory(data, static_cast<int>(size), &w, &h, &channels) &&
      static_cast<int64_t>(w) * h > (int64_t{1} << 20)) {
    return 0;
  }
  wt::fuzz::write_input("texture.img", data, size);
  static const std::string scene = R"({
    "camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
    "textures": [{"name": "t", "type": "image", "file": "texture.img"}],
    "materials": [{"name": "m", "type": "lambertian", "texture": "t"}],
    "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})";
  try {
    wt::parse_scene(scene, wt::fuzz::temp_dir() + "/scene.json");
  } catch (const wt::InputError&) {
  }
  return 0;
}

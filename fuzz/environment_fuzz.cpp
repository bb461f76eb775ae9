// The environment image's loading path as a scene file drives it: the first byte
// picks the format (even: Radiance .hdr through stb; odd: OpenEXR through
// OpenEXR), the rest becomes the file a scene's environment sky names, read by the
// scene reader (the format's loader, then the check that every value is finite
// radiance). A InputError is a clean rejection.
#include <ImathBox.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <stb/stb_image.h>

#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>

#include "fuzz_support.hpp"
#include "errors/errors.hpp"
#include "scene/scene.hpp"

namespace {

// Images over 1 Mi texels are skipped, as by the image target: a few bytes can claim
// a picture of gigabytes that the loader then allocates.
constexpr int64_t kMaxTexels = int64_t{1} << 20;

bool too_large_exr(const std::string& path) {
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i w = file.header().dataWindow();
    return (static_cast<int64_t>(w.max.x) - w.min.x + 1) * (static_cast<int64_t>(w.max.y) - w.min.y + 1) >
           kMaxTexels;
  } catch (const std::exception&) {
    return false;  // the loader refuses it the same way
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const bool exr = data[0] % 2 == 1;
  const std::string file = exr ? "sky.exr" : "sky.hdr";
  const std::string path = wt::fuzz::write_input(file.c_str(), data + 1, size - 1);
  if (exr) {
    if (too_large_exr(path)) return 0;
  } else {
    int w = 0, h = 0, channels = 0;
    if (stbi_info_from_memory(data + 1, static_cast<int>(size - 1), &w, &h, &channels) &&
        static_cast<int64_t>(w) * h > kMaxTexels) {
      return 0;
    }
  }
  const std::string scene = R"({
    "camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0]},
    "sky": {"type": "environment", "file": ")" + file + R"(", "mapping": "latlong"},
    "materials": [{"name": "m", "type": "lambertian", "albedo": [0.5, 0.5, 0.5]}],
    "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "m"}]})";
  try {
    wt::parse_scene(scene, wt::fuzz::temp_dir() + "/scene.json");
  } catch (const wt::InputError&) {
  }
  return 0;
}

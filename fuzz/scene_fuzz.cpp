// The scene parser over arbitrary bytes. A InputError is a clean rejection; any
// other exception, a crash, a leak or a sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "errors/errors.hpp"
#include "scene/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    // A folder that does not exist: relative texture files are not found, so this
    // target stays on the parser (the image target covers the loading path).
    wt::parse_scene(std::string(reinterpret_cast<const char*>(data), size), "/nonexistent/wavetrace-fuzz/scene.json");
  } catch (const wt::InputError&) {
  }
  return 0;
}

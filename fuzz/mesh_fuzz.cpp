// The mesh loaders (src/scene/mesh_load.*) as a scene will drive them: the input
// becomes a mesh file, read through tinyobjloader (OBJ, with an MTL beside it) or
// tinygltf (.gltf, .glb) and checked by the project's own code. The first byte picks
// the format; for OBJ, the bytes after a "\0MTL\0" marker become the file m.mtl. A
// InputError is a clean rejection.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "errors/errors.hpp"
#include "scene/mesh_load.hpp"
#include "scene/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  static const char* const kNames[] = {"mesh.obj", "mesh.gltf", "mesh.glb"};
  const char* name = kNames[data[0] % 3];
  const std::string body(reinterpret_cast<const char*>(data + 1), size - 1);
  std::string mesh = body;
  if (data[0] % 3 == 0) {
    static const std::string kMarker("\0MTL\0", 5);
    const size_t at = body.find(kMarker);
    const std::string mtl = at == std::string::npos ? std::string() : body.substr(at + kMarker.size());
    if (at != std::string::npos) mesh = body.substr(0, at);
    wt::fuzz::write_input("m.mtl", reinterpret_cast<const uint8_t*>(mtl.data()), mtl.size());
  }
  const std::string path = wt::fuzz::write_input(name, reinterpret_cast<const uint8_t*>(mesh.data()), mesh.size());
  try {
    wt::load_mesh(path);
  } catch (const wt::InputError&) {
  }
  return 0;
}

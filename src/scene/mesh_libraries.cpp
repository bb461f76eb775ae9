// The code of the two header-only mesh libraries, compiled once here from the headers
// that their Debian packages ship, so that the binaries need neither package's
// shared library.
#define TINYOBJLOADER_IMPLEMENTATION
#define TINYGLTF_IMPLEMENTATION
#include "scene/mesh_libraries.hpp"

namespace wt {
std::string gltf_uri_decode(const std::string& uri) { return tinygltf::dlib::urldecode(uri); }
}  // namespace wt

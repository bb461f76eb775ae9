// The code of the two header-only mesh libraries, compiled once here from the headers
// that their Debian packages ship, so that the binaries need neither package's
// shared library.
#define TINYOBJLOADER_IMPLEMENTATION
#define TINYGLTF_IMPLEMENTATION
#include "scene/mesh_libraries.hpp"

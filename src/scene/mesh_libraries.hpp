// The mesh libraries of the Debian packages libtinyobjloader-dev and libtinygltf-dev,
// configured alike in every file that includes them (their inline code depends on
// the configuration). tinygltf: no image decoding or writing and no reading of image
// files (mesh_load.cpp keeps image file names only); it parses JSON with
// nlohmann-json, as wavetrace does.
#pragma once

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>
#include <tiny_obj_loader.h>

#include <string>

namespace wt {
// A glTF URI's percent-escapes decoded, by tinygltf's own decoder (as it decodes the
// URIs of buffers): "my%20map.png" names "my map.png".
std::string gltf_uri_decode(const std::string& uri);
}  // namespace wt

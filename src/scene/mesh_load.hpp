// Triangle meshes from Wavefront OBJ (+ MTL, through tinyobjloader), glTF 2.0
// (.gltf, .glb, through tinygltf), Stanford PLY (.ply, through Assimp) and Mitsuba's
// serialized meshes (.serialized), read into host arrays with their materials mapped
// onto wavetrace's (docs/scene-format.md, "Meshes"). A scene file's `meshes` name the
// files and its `instances` place them (scene_meshes.cpp).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "wavetrace/geometry/alpha.hpp"
#include "wavetrace/lights.hpp"
#include "wavetrace/material.hpp"
#include "wavetrace/texture.hpp"

namespace wt {

// A material's texture as the file gives it: its image, how it is sampled (glTF's
// sampler) and its UV transform (KHR_texture_transform, as Texture holds it).
struct MeshTexture {
  // The image's file, resolved against the mesh file's folder; or, for an image
  // embedded in the mesh file (a .glb buffer view, a data URI), a key
  // "<mesh file>#images[N]" of TriangleMesh::embedded. "" for none.
  std::string image;
  Wrap wrap_u = Wrap::Repeat, wrap_v = Wrap::Repeat;
  Filter filter = Filter::Trilinear;   // minified
  Filter magnify = Filter::Bilinear;   // magnified (Bilinear or Nearest)
  vec2 uv_offset{0.0f}, uv_scale{1.0f};
  float uv_rotation = 0.0f;  // radians
  bool empty() const { return image.empty(); }
  // The same image read the same way (wrap, filters, transform).
  bool same_lookup(const MeshTexture& o) const {
    return image == o.image && wrap_u == o.wrap_u && wrap_v == o.wrap_v && filter == o.filter &&
           magnify == o.magnify && uv_offset == o.uv_offset && uv_scale == o.uv_scale && uv_rotation == o.uv_rotation;
  }
};

// One of the file's materials, mapped onto a wavetrace Material.
struct MeshMaterial {
  std::string name;        // as the file names it ("default" for faces without one)
  Material material{};     // texture < 0; sort_key set as for an untextured material
  // The albedo texture (an emitter's: its emission's), sRGB.
  MeshTexture albedo_map;
  // `principled` (glTF's metallic-roughness): its factors, and its
  // metallic-roughness texture (G roughness, B metallic) and tangent-space normal
  // map (both linear), the normal map's x and y scaled by normal_scale.
  float roughness = 1.0f, metallic = 0.0f;
  float anisotropy = 0.0f;  // in [0, 1] (MTL's aniso)
  // KHR_materials_specular: specularFactor (times specular_map's A channel) and
  // specularColorFactor (times specular_color_map, sRGB).
  float specular = 1.0f;
  vec3 specular_color{1.0f};
  MeshTexture specular_map, specular_color_map;
  // The roughness (its G channel) and metallic (its B channel) textures: glTF's
  // metallicRoughnessTexture is both (one texture), MTL's map_Pr and map_Pm each one.
  MeshTexture roughness_map, metallic_map, normal_map;
  float normal_scale = 1.0f;
  // MTL's bump map (map_Bump, bump), any kind but an emitter: a height map, its
  // bump_channel ('l' luminance, 'r', 'g', 'b', or 'm': alpha) times bump_scale (-bm)
  // displacing the surface along its normal in the scene's units; but where no
  // -imfchan is written and its image reads as a tangent-space normal map (the
  // scene decides, by the image's texels: height_maps.hpp), that normal map, of
  // strength bump_scale. Empty where norm gives the normal map.
  MeshTexture bump_map;
  float bump_scale = 1.0f;
  char bump_channel = 'l';
  bool bump_may_be_normal_map() const { return bump_channel == 'l'; }
  // KHR_materials_clearcoat (MTL's Pc, Pcr): the coat's weight and roughness, times
  // clearcoat_map's R and clearcoat_roughness_map's G; the coat's own normal map
  // (none: the coat follows the surface, not the base's normal map).
  float clearcoat = 0.0f, clearcoat_roughness = 0.0f;
  MeshTexture clearcoat_map, clearcoat_roughness_map, clearcoat_normal_map;
  float clearcoat_normal_scale = 1.0f;
  // KHR_materials_transmission (MTL's Tf): the share of the dielectric base that
  // transmits (tinted by the base colour), times transmission_map's R. Thin-walled
  // unless `thin` is false (KHR_materials_volume: the surface bounds a volume that
  // refracts at `material.ior` and absorbs, Beer-Lambert, to attenuation_color over
  // attenuation_distance; infinite: clear).
  float transmission = 0.0f;
  MeshTexture transmission_map;
  bool thin = true;
  vec3 attenuation_color{1.0f};
  float attenuation_distance = 0.0f;  // 0: infinite
  // A reflecting material's emission (material.emission) is textured by emission_map
  // (sRGB); an emitter's (material.kind Emissive) by albedo_map, as above.
  MeshTexture emission_map;
  // Alpha (glTF's alphaMode): none (0, opaque), or MASK (alpha below alpha_cutoff is
  // not there) or BLEND (alpha is the chance of being there), of alpha_factor times
  // alpha_map's A channel (the base colour texture).
  uint32_t alpha_mode = 0;  // 0, or an AlphaMode
  float alpha_factor = 1.0f, alpha_cutoff = 0.5f;
  MeshTexture alpha_map;
  // The texture coordinates its textures read (glTF: 0 for TEXCOORD_0, 1 for
  // TEXCOORD_1); the mesh's uvs hold that set for this material's triangles.
  int uv_set = 0;
};

// An image held inside a mesh file: its key (MeshTexture::image) and its encoded
// bytes (PNG, JPEG, ...: decoded as image files are).
struct EmbeddedImage {
  std::string key;
  std::string bytes;
};

// A camera of the file (glTF's cameras), where the first node that names it places
// it: looking down the node's -z with +y up, in the file's space.
struct MeshCamera {
  std::string name;
  bool perspective = true;  // false: orthographic (which wavetrace does not render)
  vec3 position{0.0f}, forward{0.0f, 0.0f, -1.0f}, up{0.0f, 1.0f, 0.0f};
  float yfov = 0.0f;  // radians
  bool placed = false;  // a node names it
};

struct TriangleMesh {
  std::string source;  // the mesh file
  std::vector<vec3> positions;
  std::vector<vec3> normals;  // shading normals, one per vertex; empty where the file lacks any
  std::vector<vec2> uvs;      // one per vertex, v = 0 the image's top row; empty where the file lacks any
  // One per vertex where the file gives them (glTF's TANGENT, with normals and UVs):
  // xyz the unit tangent, w = +-1 the handedness (bitangent = w cross(normal, tangent)).
  std::vector<vec4> tangents;
  std::vector<std::array<uint32_t, 3>> triangles;  // vertex indices
  std::vector<uint32_t> triangle_material;         // per triangle, an index into materials
  std::vector<MeshMaterial> materials;
  std::vector<EmbeddedImage> embedded;  // the images its textures name by key
  // What the file holds that is not rendered (an extension it uses that wavetrace
  // does not read), one line each; the scene counts and prints them.
  std::vector<std::string> warnings;
  // Its punctual lights (glTF's KHR_lights_punctual), in the file's space (its
  // nodes' transforms applied).
  std::vector<PunctualLight> lights;
  std::vector<MeshCamera> cameras;  // by the file's camera index
  size_t dropped_degenerate = 0;  // zero-area triangles (and faces of fewer than 3 corners)
  size_t dropped_nan = 0;         // triangles with a non-finite position
};

// A spot light's falloff between its inner and outer cones (radians, 0 <= inner <
// outer <= pi / 2), as KHR_lights_punctual gives it (PunctualLight's spot_scale and
// spot_offset).
void set_spot_cones(PunctualLight& l, double inner, double outer);

// Reads a mesh file, its format chosen by extension (.obj, .gltf, .glb, .ply,
// .serialized; any case). A glTF file's default scene (or its first; or, with none,
// every mesh) is read with its node transforms applied. shape_index picks the shape
// of a .serialized file (0 the first; one past the file's shapes is an error); the
// other formats hold one mesh and ignore it (the caller accepts only 0 for them).
// Throws InputError "<path>: <what is wrong>".
TriangleMesh load_mesh(const std::string& path, uint32_t shape_index = 0);

}  // namespace wt

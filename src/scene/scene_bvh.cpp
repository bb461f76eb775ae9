// The scene's acceleration structure: a BVH per group of primitives (the spheres,
// each mesh), the instances that place them, and the top-level BVH over those.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "scene/scene.hpp"
#include "errors/errors.hpp"
#include "wavetrace/scene_lights.hpp"

namespace wt {

namespace {

// Spheres: a box a little larger than the sphere, because the slab test and the
// sphere test round differently, and a grazing hit must not be culled by its box.
BuildPrimitive sphere_primitive(const SphereGeom& s) {
  const vec3 c(s.x, s.y, s.z);
  const float pad = 1e-5f * (std::max({std::fabs(s.x), std::fabs(s.y), std::fabs(s.z)}) + s.w);
  BuildPrimitive p;
  p.box.lo = c - vec3(s.w + pad);
  p.box.hi = c + vec3(s.w + pad);
  p.centroid = c;
  return p;
}

// Triangles: the corners' box, an ulp wider on every side, so that no triangle lies
// in the plane of a box face (geometry/bvh.hpp, slab_inverse); the slab test rounds
// its far side up for the rest.
BuildPrimitive triangle_primitive(const TriangleGeom& t) {
  BuildPrimitive p;
  for (int i = 0; i < 3; ++i) p.box.grow(t.corner(i));
  p.centroid = p.box.centre();
  for (int k = 0; k < 3; ++k) {
    p.box.lo[k] = std::nextafter(p.box.lo[k], -FLT_MAX);
    p.box.hi[k] = std::nextafter(p.box.hi[k], FLT_MAX);
  }
  return p;
}

template <class T>
void permute_range(std::vector<T>& v, size_t first, const std::vector<uint32_t>& order) {
  std::vector<T> out(order.size());
  for (size_t i = 0; i < order.size(); ++i) out[i] = v[first + order[i]];
  std::copy(out.begin(), out.end(), v.begin() + first);
}

// Appends a bottom-level tree to the node array; its leaves' primitive indices move
// by `first_prim`. Returns the root's index.
int32_t append_tree(std::vector<BvhNode>& nodes, const std::vector<BvhNode>& tree, uint32_t first_prim) {
  const int32_t base = static_cast<int32_t>(nodes.size());
  for (BvhNode n : tree) {
    n.left_or_first += n.count > 0 ? static_cast<int32_t>(first_prim) : base;
    nodes.push_back(n);
  }
  return base;
}

// The world box of an instance: its tree's root box through the transform, widened
// by the rounding of the transform (rays are carried the other way, into object
// space, and must not be culled here where they hit there).
Aabb world_box(const Aabb& object, const Placement& p) {
  if (p.identity) return object;
  Aabb w;
  for (int corner = 0; corner < 8; ++corner) {
    vec3 c((corner & 1) ? object.hi.x : object.lo.x, (corner & 2) ? object.hi.y : object.lo.y,
           (corner & 4) ? object.hi.z : object.lo.z);
    w.grow(p.world_from_object.point(c));
  }
  const vec3 pad = 1e-5f * glm::max(glm::abs(w.lo), glm::abs(w.hi));
  w.lo -= pad;
  w.hi += pad;
  return w;
}

}  // namespace

void build_lights(Scene& scene, const std::vector<int32_t>& instance_mesh);

void build_bvh(Scene& scene) {
  scene.nodes.clear();
  scene.instances.clear();
  build_lights(scene, {});
  if (scene.placements.empty()) return;
  const BvhBuildOptions blas_options;
  BvhBuildOptions tlas_options;
  tlas_options.max_leaf_size = 1;  // traversal enters one instance per top-level leaf

  // Bottom levels, built and permuted first; appended after the top level below.
  std::vector<BvhNode> sphere_tree;
  if (!scene.spheres.empty()) {
    std::vector<BuildPrimitive> prims(scene.spheres.size());
    for (size_t i = 0; i < prims.size(); ++i) prims[i] = sphere_primitive(scene.spheres[i]);
    BvhTree tree;
    try {
      tree = build_bvh(prims, blas_options);
    } catch (const std::length_error& e) {
      throw InputError(scene.source + ": /spheres: " + e.what());
    }
    permute_range(scene.spheres, 0, tree.order);
    permute_range(scene.sphere_materials, 0, tree.order);
    scene.sphere_bvh = bvh_stats(tree.nodes, blas_options);
    sphere_tree = std::move(tree.nodes);
  }
  std::vector<std::vector<BvhNode>> mesh_trees(scene.meshes.size());
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    SceneMesh& mesh = scene.meshes[m];
    std::vector<BuildPrimitive> prims(mesh.triangle_count);
    for (uint32_t i = 0; i < mesh.triangle_count; ++i) {
      prims[i] = triangle_primitive(scene.triangles[mesh.first_triangle + i]);
    }
    BvhTree tree;
    try {
      tree = build_bvh(prims, blas_options);
    } catch (const std::length_error& e) {
      throw InputError(mesh.file + ": " + e.what());
    }
    permute_range(scene.triangles, mesh.first_triangle, tree.order);
    permute_range(scene.triangle_shadings, mesh.first_triangle, tree.order);
    permute_range(scene.triangle_materials, mesh.first_triangle, tree.order);
    mesh.bvh = bvh_stats(tree.nodes, blas_options);
    mesh_trees[m] = std::move(tree.nodes);
  }

  // The top level over the placements' world boxes.
  std::vector<BuildPrimitive> boxes(scene.placements.size());
  for (size_t i = 0; i < boxes.size(); ++i) {
    const Placement& p = scene.placements[i];
    const auto& tree = p.mesh == kSpheres ? sphere_tree : mesh_trees[p.mesh];
    boxes[i].box = world_box(node_bounds(tree[0]), p);
    boxes[i].centroid = boxes[i].box.centre();
    if (p.mesh != kSpheres) {
      const vec3 far = glm::max(glm::abs(boxes[i].box.lo), glm::abs(boxes[i].box.hi));
      const float reach = std::max(far.x, std::max(far.y, far.z));
      if (!(reach <= kMaxCoordinate)) {
        const size_t instance = i - (scene.spheres.empty() ? 0 : 1);  // the spheres' placement comes first
        char value[32];
        std::snprintf(value, sizeof value, "%g", static_cast<double>(reach));
        throw InputError(scene.source + ": /instances/" + std::to_string(instance) + ": the placed mesh '" +
                         scene.meshes[p.mesh].name + "' reaches a coordinate of " + value +
                         ", beyond +-1e15, the largest a scene may hold");
      }
    }
  }
  BvhTree top;
  try {
    top = build_bvh(boxes, tlas_options);
  } catch (const std::length_error& e) {
    throw InputError(scene.source + ": /instances: " + e.what());
  }
  scene.top_level_bvh = bvh_stats(top.nodes, tlas_options);
  scene.nodes = std::move(top.nodes);
  const int32_t sphere_root = sphere_tree.empty() ? -1 : append_tree(scene.nodes, sphere_tree, 0);
  std::vector<int32_t> mesh_roots(scene.meshes.size());
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    mesh_roots[m] = append_tree(scene.nodes, mesh_trees[m], scene.meshes[m].first_triangle);
  }
  if (scene.nodes.size() > static_cast<size_t>(INT32_MAX)) {
    throw InputError(scene.source + ": too many BVH nodes for 32-bit indices");
  }
  scene.instances.resize(top.order.size());
  for (size_t i = 0; i < top.order.size(); ++i) {
    const Placement& p = scene.placements[top.order[i]];
    Instance& in = scene.instances[i];
    in.object_from_world = p.object_from_world;
    in.world_from_object = p.world_from_object;
    in.root = p.mesh == kSpheres ? sphere_root : mesh_roots[p.mesh];
    in.kind = p.mesh == kSpheres ? PrimitiveKind::Sphere : PrimitiveKind::Triangle;
    in.material = p.material;
    in.identity = p.identity ? 1u : 0u;
  }
  std::vector<int32_t> instance_mesh(top.order.size());
  for (size_t i = 0; i < top.order.size(); ++i) instance_mesh[i] = scene.placements[top.order[i]].mesh;
  build_lights(scene, instance_mesh);
}

// The radius of the scene's bounding sphere (about its top-level box); 0 for an
// empty scene.
static float scene_radius(const Scene& scene) {
  if (scene.nodes.empty()) return 0.0f;
  const Aabb box = node_bounds(scene.nodes[0]);
  return 0.5f * glm::length(box.hi - box.lo);
}

// The sky's power as a light, in light_power_of's units (power / pi): the radiance
// that enters the scene's bounding sphere (radius r) from every direction, mean
// radiance x 4 pi x pi r^2, over pi. 0 where the sky is not sampled: the gradient
// (the study's skies, which stay as they were rendered) and black skies.
float sky_light_power(const Scene& scene) {
  if (scene.nodes.empty()) return 0.0f;
  const Sky& sky = scene.sky;
  double mean = 0.0;  // the channels' mean radiance, averaged over the sphere of directions
  if (sky.kind == SkyKind::Uniform) {
    mean = (sky.horizon.x + sky.horizon.y + sky.horizon.z) / 3.0;
  } else if (sky.kind == SkyKind::Environment && sky.image >= 0 &&
             static_cast<size_t>(sky.image) < scene.images.size()) {
    const Image& im = scene.images[static_cast<size_t>(sky.image)];
    // A LatLong row covers solid angle in proportion to sin theta; the other
    // mappings are averaged over their texels (a guide to the power, not a measure).
    double weighted = 0.0, weights = 0.0;
    for (int y = 0; y < im.height; ++y) {
      const double w = sky.mapping == EnvironmentMapping::LatLong ? std::sin(kPi * (y + 0.5) / im.height) : 1.0;
      for (int x = 0; x < im.width; ++x) {
        const float* t = &im.texels[4 * (static_cast<size_t>(y) * im.width + x)];
        const double v = (static_cast<double>(t[0]) + t[1] + t[2]) / 3.0;
        weighted += w * (std::isfinite(v) && v > 0.0 ? v : 0.0);
        weights += w;
      }
    }
    mean = weights > 0.0 ? sky.intensity * weighted / weights : 0.0;
  }
  const double r = scene_radius(scene);
  const double power = mean * 4.0 * kPi * r * r;
  return std::isfinite(power) && power > 0.0 && power < 3.0e38 ? static_cast<float>(power) : 0.0f;
}

// The lights of the built instances (instance_mesh[i]: instance i's mesh, or
// kSpheres) and the sky, with the table that picks them by power. An emitter's
// power is computed in float from its world-space shape as the shading code
// computes it (scene_lights.hpp, light_density), so that both see the same probabilities.
void build_lights(Scene& scene, const std::vector<int32_t>& instance_mesh) {
  scene.lights.clear();
  scene.light_cdf.clear();
  scene.light_power = 0.0f;
  scene.sky_pick = 0.0f;
  scene.environment = EnvironmentDistribution{};
  std::vector<float> power;
  auto add = [&](int32_t instance, uint32_t prim, uint32_t material, const EmitterShape& shape) {
    // (Scenes built by hand in the tests may leave out materials they never shade.)
    if (material >= scene.materials.size()) return;
    const Material& m = scene.materials[material];
    if (m.kind != MaterialKind::Emissive && !(m.flags & kMaterialEmits)) return;
    const float p = light_power_of(m.emission, shape.area());
    if (!(p > 0.0f)) return;
    scene.lights.push_back(LightRef{instance, static_cast<int32_t>(prim)});
    power.push_back(p);
  };
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& in = scene.instances[i];
    const int32_t index = static_cast<int32_t>(i);
    if (in.kind == PrimitiveKind::Sphere) {
      for (size_t p = 0; p < scene.spheres.size(); ++p) {
        const SphereGeom& sg = scene.spheres[p];
        add(index, static_cast<uint32_t>(p), in.material >= 0 ? static_cast<uint32_t>(in.material) : scene.sphere_materials[p],
            EmitterShape::of_sphere(vec3(sg.x, sg.y, sg.z), sg.w));
      }
      continue;
    }
    const SceneMesh& mesh = scene.meshes.at(static_cast<size_t>(instance_mesh.at(i)));
    for (uint32_t t = mesh.first_triangle; t < mesh.first_triangle + mesh.triangle_count; ++t) {
      vec3 a, b, c;
      world_triangle(scene.triangles[t], in, a, b, c);
      add(index, t, in.material >= 0 ? static_cast<uint32_t>(in.material) : scene.triangle_materials[t],
          EmitterShape::of_triangle(a, b, c));
    }
  }
  // Each placed mesh's punctual lights, in world space.
  scene.punctual_lights.clear();
  const float radius = scene_radius(scene);
  auto add_punctual = [&](const PunctualLight& l) {
    const float p = l.power(radius);
    if (!(p > 0.0f)) return;
    scene.lights.push_back(LightRef{kPunctualLight, static_cast<int32_t>(scene.punctual_lights.size())});
    scene.punctual_lights.push_back(l);
    power.push_back(p);
  };
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& in = scene.instances[i];
    if (in.kind == PrimitiveKind::Sphere) continue;
    for (PunctualLight l : scene.meshes.at(static_cast<size_t>(instance_mesh.at(i))).lights) {
      l.position = in.world_from_object.point(l.position);
      const vec3 d = in.world_from_object.vector(l.direction);
      l.direction = glm::length(d) > 0.0f ? glm::normalize(d) : l.direction;
      add_punctual(l);
    }
  }
  for (const PunctualLight& l : scene.file_lights) add_punctual(l);
  const float sky = sky_light_power(scene);
  if (sky > 0.0f) {
    scene.lights.push_back(LightRef{kSkyLight, 0});
    power.push_back(sky);
    scene.environment = build_environment_distribution(scene);
  }
  double total = 0.0;
  for (float p : power) total += p;
  scene.light_power = static_cast<float>(total);
  double running = 0.0;
  for (float p : power) {
    running += p;
    scene.light_cdf.push_back(static_cast<float>(running / total));
  }
  if (!scene.light_cdf.empty()) scene.light_cdf.back() = 1.0f;
  if (sky > 0.0f) {
    // As pick_light reads it from the table.
    const size_t last = scene.light_cdf.size() - 1;
    scene.sky_pick = scene.light_cdf[last] - (last > 0 ? scene.light_cdf[last - 1] : 0.0f);
  }
}

size_t Scene::instanced_triangles() const {
  size_t total = 0;
  for (const Placement& p : placements) {
    if (p.mesh != kSpheres) total += meshes[p.mesh].triangle_count;
  }
  return total;
}

namespace {
template <class T>
size_t bytes_of(const std::vector<T>& v) {
  return v.size() * sizeof(T);
}
}  // namespace

size_t Scene::device_bytes() const {
#define WT_ARRAY_BYTES(T, array, at, Return, Index) +bytes_of(array)
  size_t total = 0 WT_SCENE_ARRAYS(WT_ARRAY_BYTES);
#undef WT_ARRAY_BYTES
  total += bytes_of(environment.marginal_cdf) + bytes_of(environment.conditional_cdf);
  for (const Image& im : images) total += bytes_of(im.texels) + bytes_of(im.mip_texels);
  return total;
}

uint32_t Scene::primitive_kinds() const {
  uint32_t kinds = 0;
  for (const Placement& p : placements) {
    kinds |= kind_bit(p.mesh == kSpheres ? PrimitiveKind::Sphere : PrimitiveKind::Triangle);
  }
  return kinds;
}

uint32_t Scene::kernel_kinds() const {
  uint32_t kinds = primitive_kinds();
  // The microfacet kinds, any material with parameters beyond the study's (a
  // normal map), a mip-mapped image texture and a textured emitter need the kernels
  // that read them.
  // Alpha-tested triangles, principled's coat, transmission and volume need the
  // kernels with the layers and alpha, which come with the microfacet ones.
  if (!alpha_tests.empty()) kinds |= kLayersAndAlpha | kMicrofacet;
  for (const Material& m : materials) {
    if (m.params >= 0) kinds |= kMicrofacet;
    if (m.params >= 0 && static_cast<size_t>(m.params) < material_params.size()) {
      const MaterialParams& p = material_params[static_cast<size_t>(m.params)];
      const bool absorbs = p.attenuation.x > 0.0f || p.attenuation.y > 0.0f || p.attenuation.z > 0.0f;
      if (p.clearcoat > 0.0f || p.transmission > 0.0f || absorbs) kinds |= kLayersAndAlpha;
    }
    if (m.texture >= 0 && static_cast<size_t>(m.texture) < textures.size()) {
      const Texture& t = textures[static_cast<size_t>(m.texture)];
      if (m.kind == MaterialKind::Emissive || (t.kind == TextureKind::Image && t.filter == Filter::Trilinear)) {
        kinds |= kMicrofacet;
      }
    }
  }
  return kinds;
}

Scene::Summary Scene::summary() const {
  Summary s;
  s.spheres = spheres.size();
  s.triangles = triangles.size();
  s.instanced_triangles = instanced_triangles();
  s.instances = instances.size();
  s.bvh_nodes = nodes.size();
  s.device_bytes = device_bytes();
  s.top_level_bvh = top_level_bvh;
  s.sphere_bvh = sphere_bvh;
  s.meshes = meshes;
  for (const SceneMesh& m : meshes) {
    s.dropped_degenerate += m.dropped_degenerate;
    s.dropped_nan += m.dropped_nan;
  }
  return s;
}

}  // namespace wt

// The megakernel over a scene in __constant__ memory. Constant memory broadcasts
// a value when a warp's threads read the same address and serialises otherwise,
// so this variant shows what divergent scene access costs.
#include <cstring>
#include <string>

#include "device/device.hpp"
#include "errors/errors.hpp"
#include "megakernel/megakernel.hpp"
#include "megakernel/megakernel_body.cuh"

namespace wt::cuda {

namespace {

// The 64 KiB of constant memory, less headroom for what the toolchain places there.
constexpr size_t kPoolBytes = 63 * 1024;
__constant__ __align__(16) unsigned char c_pool[kPoolBytes];

// Where each array starts in the pool.
struct ConstantLayout {
  uint32_t nodes, instances, spheres, sphere_materials, triangles, triangle_shadings, triangle_materials, normals, uvs,
      materials, textures, images, lights, light_cdf;
  int32_t node_total, light_total;
  float light_power, sky_pick;
  // The environment's table stays in global memory, as the images do (it can be
  // megabytes): the device view's pointers.
  PiecewiseConstant2D environment;
};

struct ConstantScene {
  ConstantLayout layout;
  Sky sky;
  Camera camera;

  template <class T>
  __device__ const T* array(uint32_t offset) const {
    return reinterpret_cast<const T*>(c_pool + offset);
  }
  __device__ int node_count() const { return layout.node_total; }
  __device__ BvhNode node(int i) const { return array<BvhNode>(layout.nodes)[i]; }
  __device__ const Instance& instance(int i) const { return array<Instance>(layout.instances)[i]; }
  __device__ SphereGeom sphere(int i) const { return array<SphereGeom>(layout.spheres)[i]; }
  __device__ uint32_t sphere_material(int i) const { return array<uint32_t>(layout.sphere_materials)[i]; }
  __device__ TriangleGeom triangle(int i) const { return array<TriangleGeom>(layout.triangles)[i]; }
  __device__ TriangleShading triangle_shading(int i) const {
    return array<TriangleShading>(layout.triangle_shadings)[i];
  }
  __device__ uint32_t triangle_material(int i) const { return array<uint32_t>(layout.triangle_materials)[i]; }
  __device__ vec3 normal(uint32_t i) const { return array<vec3>(layout.normals)[i]; }
  __device__ vec2 uv(uint32_t i) const { return array<vec2>(layout.uvs)[i]; }
  __device__ const Material& material(uint32_t i) const { return array<Material>(layout.materials)[i]; }
  __device__ const Texture* texture_array() const { return array<Texture>(layout.textures); }
  __device__ const ImageView* image_array() const { return array<ImageView>(layout.images); }
  __device__ int light_count() const { return layout.light_total; }
  __device__ LightRef light(int i) const { return array<LightRef>(layout.lights)[i]; }
  __device__ float light_cdf_at(int i) const { return array<float>(layout.light_cdf)[i]; }
  __device__ float total_light_power() const { return layout.light_power; }
  __device__ float sky_light_pick() const { return layout.sky_pick; }
  __device__ const PiecewiseConstant2D& environment_table() const { return layout.environment; }
};

// The host copy of the accessor, filled by upload_constant_scene, and the uploaded
// scene's primitive kinds: per host thread, as the current device is (a render split
// over devices uploads and launches on each device from its own thread, and the
// accessor holds that device's pointers).
thread_local ConstantScene g_scene{};
thread_local uint32_t g_kinds = kAllKinds;

size_t align16(size_t n) { return (n + 15) & ~size_t(15); }

template <uint32_t Kinds>
__global__ void __launch_bounds__(kMegakernelBlockX * kMegakernelBlockY)
    megakernel_constant(ConstantScene scene, RenderParams rp, int first_sample, int samples, float* film,
                        unsigned long long* rays) {
  megakernel_pixel<Kinds>(scene, rp, first_sample, samples, film, rays);
}

}  // namespace

size_t constant_scene_capacity() { return kPoolBytes; }

void upload_constant_scene(const Scene& scene, const SceneView& device_view, const std::vector<ImageView>& images) {
  std::vector<unsigned char> pool;
  auto place = [&pool](const auto& array) {
    const size_t bytes = array.size() * sizeof(array[0]);
    size_t offset = align16(pool.size());
    pool.resize(offset + bytes);
    if (bytes) std::memcpy(pool.data() + offset, array.data(), bytes);
    return static_cast<uint32_t>(offset);
  };
  ConstantScene cs{};
  cs.layout.nodes = place(scene.nodes);
  cs.layout.instances = place(scene.instances);
  cs.layout.spheres = place(scene.spheres);
  cs.layout.sphere_materials = place(scene.sphere_material);
  cs.layout.triangles = place(scene.triangles);
  cs.layout.triangle_shadings = place(scene.triangle_shading);
  cs.layout.triangle_materials = place(scene.triangle_material);
  cs.layout.normals = place(scene.normals);
  cs.layout.uvs = place(scene.uvs);
  cs.layout.materials = place(scene.materials);
  cs.layout.textures = place(scene.textures);
  cs.layout.images = place(images);
  cs.layout.lights = place(scene.lights);
  cs.layout.light_cdf = place(scene.light_cdf);
  if (pool.size() > kPoolBytes) {
    throw InputError(scene.source + ": the scene needs " + std::to_string(pool.size()) +
                     " bytes of constant memory; megakernel-constant holds at most " + std::to_string(kPoolBytes) +
                     " (use --kernel megakernel)");
  }
  cs.layout.node_total = device_view.node_total;
  cs.layout.light_total = device_view.light_total;
  cs.layout.light_power = device_view.light_power;
  cs.layout.sky_pick = device_view.sky_pick;
  cs.layout.environment = device_view.environment;
  cs.sky = device_view.sky;
  cs.camera = device_view.camera;
  WT_CUDA(cudaMemcpyToSymbol(c_pool, pool.data(), pool.size()), "constant upload");
  g_scene = cs;
  g_kinds = device_view.kinds;
}

void launch_megakernel_constant(const RenderParams& rp, int first_sample, int samples, float* film,
                                unsigned long long* rays, cudaStream_t stream) {
  const dim3 grid = megakernel_grid(rp), block(kMegakernelBlockX, kMegakernelBlockY);
  const uint32_t kinds_and_lights = g_kinds | (rp.nee != 0 && g_scene.layout.light_total > 0 ? kLightSampling : 0u);
  with_kinds(kinds_and_lights, [&](auto kinds) {
    megakernel_constant<decltype(kinds)::value>
        <<<grid, block, 0, stream>>>(g_scene, rp, first_sample, samples, film, rays);
  });
  WT_CUDA_LAUNCHED("megakernel_constant", "megakernel-constant");
}

}  // namespace wt::cuda

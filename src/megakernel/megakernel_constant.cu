// The megakernel over a scene in __constant__ memory. Constant memory broadcasts
// a value when a warp's threads read the same address and serialises otherwise,
// so this variant shows what divergent scene access costs.
#include <cstring>
#include <string>

#include "device/device.hpp"
#include "device/kernel_bodies.hpp"
#include "errors/errors.hpp"
#include "megakernel/megakernel.hpp"
#include "megakernel/megakernel_body.cuh"

namespace wt::cuda {

namespace {

// The 64 KiB of constant memory, less headroom for what the toolchain places there.
constexpr size_t kPoolBytes = 63 * 1024;
__constant__ __align__(16) unsigned char c_pool[kPoolBytes];

// Where each array starts in the pool: one offset per array of the scene's list
// (scene_view.hpp), and the images' views.
#define WT_CONSTANT_OFFSET(T, array, at, Return, Index) uint32_t array;
struct ConstantLayout {
  WT_SCENE_ARRAYS(WT_CONSTANT_OFFSET)
  uint32_t images;
};
#undef WT_CONSTANT_OFFSET

// The accessor over the pool. Its scalars (the environment's table among them, which
// stays in global memory as the images do: it can be megabytes) are the device view's.
// (The list gives every array an accessor; an unused one is no defect here.)
#pragma nv_diag_suppress declared_but_not_referenced
#define WT_CONSTANT_AT(T, array, at, Return, Index) \
  __device__ Return at(Index i) const { return pool_array<T>(layout.array)[i]; }
struct ConstantScene : SceneScalars {
  ConstantLayout layout;

  template <class T>
  __device__ static const T* pool_array(uint32_t offset) {
    return reinterpret_cast<const T*>(c_pool + offset);
  }
  WT_SCENE_ARRAYS(WT_CONSTANT_AT)
  __device__ const Texture* texture_array() const { return pool_array<Texture>(layout.textures); }
  __device__ const MaterialParams* material_param_array() const {
    return pool_array<MaterialParams>(layout.material_params);
  }
  __device__ const float* bsdf_table_array() const { return pool_array<float>(layout.bsdf_tables); }
  __device__ const ImageView* image_array() const { return pool_array<ImageView>(layout.images); }
};
#undef WT_CONSTANT_AT
#pragma nv_diag_default declared_but_not_referenced

// The host copy of the accessor, filled by upload_constant_scene, and the uploaded
// scene's primitive kinds: per host thread, as the current device is (a render split
// over devices uploads and launches on each device from its own thread, and the
// accessor holds that device's pointers).
thread_local ConstantScene g_scene{};
thread_local uint32_t g_kinds = kAllKinds;

size_t align16(size_t n) { return (n + 15) & ~size_t(15); }

template <uint32_t Kinds>
__global__ void __launch_bounds__(kMegakernelBlockX * kMegakernelBlockY)
    megakernel_constant(ConstantScene scene, RenderParams rp, int first_sample, int samples, MegakernelWork out,
                        unsigned long long* rays) {
#if WT_KERNEL_BODIES
  megakernel_pixel<Kinds>(scene, rp, first_sample, samples, out, rays);
#endif
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
#define WT_CONSTANT_PLACE(T, array, at, Return, Index) cs.layout.array = place(scene.array);
  WT_SCENE_ARRAYS(WT_CONSTANT_PLACE)
#undef WT_CONSTANT_PLACE
  cs.layout.images = place(images);
  if (pool.size() > kPoolBytes) {
    throw InputError(scene.source + ": the scene needs " + std::to_string(pool.size()) +
                     " bytes of constant memory; megakernel-constant holds at most " + std::to_string(kPoolBytes) +
                     " (use --kernel megakernel)");
  }
  static_cast<SceneScalars&>(cs) = device_view;
  WT_CUDA(cudaMemcpyToSymbol(c_pool, pool.data(), pool.size()), "constant upload");
  g_scene = cs;
  g_kinds = device_view.kinds;
}

namespace {

// Hands f the constant-memory megakernel compiled for the uploaded scene's kinds
// (light sampling's code only where it has emitters to sample).
template <class F>
void with_constant_megakernel(const RenderParams& rp, F&& f) {
  const uint32_t kinds_and_lights = g_kinds | (g_scene.samples_lights(rp) ? kLightSampling : 0u);
  with_kinds(kinds_and_lights, [&](auto kinds) { f(megakernel_constant<decltype(kinds)::value>); });
}

}  // namespace

void launch_megakernel_constant(const RenderParams& rp, int first_sample, int samples, MegakernelWork out,
                                unsigned long long* rays, cudaStream_t stream) {
  const dim3 grid = megakernel_grid(rp, out.radiance ? samples : 1, out), block(kMegakernelBlockX, kMegakernelBlockY);
  with_constant_megakernel(rp, [&](auto kernel) {
    kernel<<<grid, block, 0, stream>>>(g_scene, rp, first_sample, samples, out, rays);
  });
  WT_CUDA_LAUNCHED("megakernel_constant", "megakernel-constant");
}

void load_megakernel_constant(const RenderParams& rp) {
  with_constant_megakernel(
      rp, [](auto kernel) { load_kernel(reinterpret_cast<const void*>(kernel), "megakernel-constant"); });
}

}  // namespace wt::cuda

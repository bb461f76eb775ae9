#include "cuda/device_scene.hpp"

namespace wt::cuda {

namespace {
constexpr const char* kStage = "scene upload";
}

DeviceScene::DeviceScene(const Scene& scene, int width, int height) {
  nodes_.upload(scene.nodes, kStage);
  instances_.upload(scene.instances, kStage);
  spheres_.upload(scene.spheres, kStage);
  sphere_material_.upload(scene.sphere_material, kStage);
  triangles_.upload(scene.triangles, kStage);
  triangle_shading_.upload(scene.triangle_shading, kStage);
  triangle_material_.upload(scene.triangle_material, kStage);
  normals_.upload(scene.normals, kStage);
  uvs_.upload(scene.uvs, kStage);
  materials_.upload(scene.materials, kStage);
  textures_.upload(scene.textures, kStage);
  lights_.upload(scene.lights, kStage);
  light_cdf_.upload(scene.light_cdf, kStage);
  environment_marginal_.upload(scene.environment.marginal_cdf, kStage);
  environment_conditional_.upload(scene.environment.conditional_cdf, kStage);

  // Texels are fetched one by one (point sampling) and filtered by the shared
  // bilinear code, so the GPU computes exactly what the CPU computes.
  for (const Image& im : scene.images) {
    cudaChannelFormatDesc desc = cudaCreateChannelDesc<float4>();
    cudaArray_t array = nullptr;
    WT_CUDA(cudaMallocArray(&array, &desc, im.width, im.height), kStage);
    arrays_.push_back(array);
    const size_t row = static_cast<size_t>(im.width) * 4 * sizeof(float);
    WT_CUDA(cudaMemcpy2DToArray(array, 0, 0, im.texels.data(), row, row, im.height, cudaMemcpyHostToDevice), kStage);

    cudaResourceDesc res{};
    res.resType = cudaResourceTypeArray;
    res.res.array.array = array;
    cudaTextureDesc tex{};
    tex.addressMode[0] = cudaAddressModeClamp;
    tex.addressMode[1] = cudaAddressModeClamp;
    tex.filterMode = cudaFilterModePoint;
    tex.readMode = cudaReadModeElementType;
    tex.normalizedCoords = 0;
    cudaTextureObject_t object = 0;
    WT_CUDA(cudaCreateTextureObject(&object, &res, &tex, nullptr), kStage);
    objects_.push_back(object);
    image_views_.push_back(ImageView{object, nullptr, im.width, im.height});
  }
  images_.upload(image_views_, kStage);

  view_.nodes = nodes_.get();
  view_.instances = instances_.get();
  view_.spheres = spheres_.get();
  view_.sphere_materials = sphere_material_.get();
  view_.triangles = triangles_.get();
  view_.triangle_shadings = triangle_shading_.get();
  view_.triangle_materials = triangle_material_.get();
  view_.normals = normals_.get();
  view_.uvs = uvs_.get();
  view_.materials = materials_.get();
  view_.textures = textures_.get();
  view_.images = images_.get();
  view_.lights = lights_.get();
  view_.light_cdf = light_cdf_.get();
  view_.light_total = static_cast<int32_t>(scene.lights.size());
  view_.light_power = scene.light_power;
  view_.sky_pick = scene.sky_pick;
  view_.environment = PiecewiseConstant2D{environment_marginal_.get(), environment_conditional_.get(),
                                          scene.environment.columns, scene.environment.rows};
  view_.node_total = static_cast<int32_t>(scene.nodes.size());
  view_.kinds = scene.primitive_kinds();
  view_.sky = scene.sky;
  view_.camera = Camera::make(scene.camera, width, height);
}

DeviceScene::~DeviceScene() {
  for (cudaTextureObject_t o : objects_) cudaDestroyTextureObject(o);
  for (cudaArray_t a : arrays_) cudaFreeArray(a);
}

}  // namespace wt::cuda

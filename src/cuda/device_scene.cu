#include "cuda/device_scene.hpp"

namespace wt::cuda {

namespace {
constexpr const char* kStage = "scene upload";
}

DeviceScene::DeviceScene(const Scene& scene, int width, int height) {
#define WT_DEVICE_UPLOAD(T, array, at, Return, Index) \
  array##_.upload(scene.array, kStage);    \
  view_.array = array##_.get();
  WT_SCENE_ARRAYS(WT_DEVICE_UPLOAD)
#undef WT_DEVICE_UPLOAD
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

  view_.images = images_.get();
  const PiecewiseConstant2D environment{environment_marginal_.get(), environment_conditional_.get(),
                                        scene.environment.columns, scene.environment.rows};
  static_cast<SceneScalars&>(view_) = scene_scalars(scene, width, height, environment);
}

DeviceScene::~DeviceScene() {
  for (cudaTextureObject_t o : objects_) cudaDestroyTextureObject(o);
  for (cudaArray_t a : arrays_) cudaFreeArray(a);
}

}  // namespace wt::cuda

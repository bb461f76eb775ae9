#include "cuda/device_scene.hpp"

#include <algorithm>

namespace wt::cuda {

namespace {
constexpr const char* kStage = "scene upload";
}

// An array of w x h RGBA float texels on the device, read through a texture object
// by point sampling at unnormalised coordinates; kept until the scene goes.
cudaTextureObject_t DeviceScene::texture_of(const float* texels, int w, int h) {
  cudaChannelFormatDesc desc = cudaCreateChannelDesc<float4>();
  cudaArray_t array = nullptr;
  WT_CUDA(cudaMallocArray(&array, &desc, w, h), kStage);
  arrays_.push_back(array);
  const size_t row = static_cast<size_t>(w) * 4 * sizeof(float);
  WT_CUDA(cudaMemcpy2DToArray(array, 0, 0, texels, row, row, h, cudaMemcpyHostToDevice), kStage);
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
  return object;
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
  // bilinear and trilinear code, so the GPU computes exactly what the CPU computes.
  for (const Image& im : scene.images) {
    const cudaTextureObject_t object = texture_of(im.texels.data(), im.width, im.height);
    cudaTextureObject_t mips = 0;
    if (im.levels > 1) {
      const int pitch = std::max(im.width / 2, 1);
      mips = texture_of(im.mip_texels.data(), pitch, static_cast<int>(im.mip_texels.size() / (4 * pitch)));
    }
    image_views_.push_back(ImageView{object, nullptr, im.width, im.height, mips, nullptr, im.levels});
  }
  images_.upload(image_views_, kStage);

  view_.images = images_.get();
  const PiecewiseConstant2D environment{environment_marginal_.get(), environment_conditional_.get(),
                                        scene.environment.columns, scene.environment.rows};
  static_cast<SceneScalars&>(view_) = scene_scalars(scene, width, height, environment);
}

SceneView DeviceScene::view_at(const Scene& scene, int width, int height) const {
  SceneView v = view_;
  static_cast<SceneScalars&>(v) = scene_scalars(scene, width, height, view_.environment);
  return v;
}

DeviceScene::~DeviceScene() {
  for (cudaTextureObject_t o : objects_) cudaDestroyTextureObject(o);
  for (cudaArray_t a : arrays_) cudaFreeArray(a);
}

}  // namespace wt::cuda

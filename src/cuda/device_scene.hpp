// A scene uploaded to the GPU: its arrays in global memory and its images as
// CUDA texture objects.
#pragma once

#include <vector>

#include "cuda/buffer.hpp"
#include "scene/scene.hpp"

namespace wt::cuda {

class DeviceScene {
 public:
  DeviceScene(const Scene& scene, int width, int height);
  ~DeviceScene();
  DeviceScene(const DeviceScene&) = delete;
  DeviceScene& operator=(const DeviceScene&) = delete;

  const SceneView& view() const { return view_; }
  // The view for a render of width x height of `scene` (the one uploaded): the same
  // arrays, the camera made for that film.
  SceneView view_at(const Scene& scene, int width, int height) const;
  // The host copies of the image views (texture objects filled in), for constant memory.
  const std::vector<ImageView>& image_views() const { return image_views_; }

 private:
  cudaTextureObject_t texture_of(const float* texels, int w, int h);

#define WT_DEVICE_BUFFER(T, array, at, Return, Index) DeviceBuffer<T> array##_;
  WT_SCENE_ARRAYS(WT_DEVICE_BUFFER)
#undef WT_DEVICE_BUFFER
  DeviceBuffer<ImageView> images_;
  DeviceBuffer<float> environment_marginal_, environment_conditional_;
  std::vector<cudaArray_t> arrays_;
  std::vector<cudaTextureObject_t> objects_;
  std::vector<ImageView> image_views_;
  SceneView view_{};
};

}  // namespace wt::cuda

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
  // The host copies of the image views (texture objects filled in), for constant memory.
  const std::vector<ImageView>& image_views() const { return image_views_; }

 private:
  DeviceBuffer<BvhNode> nodes_;
  DeviceBuffer<Instance> instances_;
  DeviceBuffer<SphereGeom> spheres_;
  DeviceBuffer<uint32_t> sphere_material_;
  DeviceBuffer<TriangleGeom> triangles_;
  DeviceBuffer<TriangleShading> triangle_shading_;
  DeviceBuffer<uint32_t> triangle_material_;
  DeviceBuffer<vec3> normals_;
  DeviceBuffer<vec2> uvs_;
  DeviceBuffer<Material> materials_;
  DeviceBuffer<Texture> textures_;
  DeviceBuffer<ImageView> images_;
  DeviceBuffer<LightRef> lights_;
  DeviceBuffer<float> light_cdf_;
  DeviceBuffer<float> environment_marginal_, environment_conditional_;
  std::vector<cudaArray_t> arrays_;
  std::vector<cudaTextureObject_t> objects_;
  std::vector<ImageView> image_views_;
  SceneView view_{};
};

}  // namespace wt::cuda

// One entry point for every backend and kernel: render a scene, get linear
// radiance, counted rays and timings back.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace wt {

enum class Backend { Cpu, Cuda };
enum class Kernel { Megakernel, MegakernelConstant, Wavefront, WavefrontUnsorted };

const char* backend_name(Backend b);
const char* kernel_name(Kernel k);

// Progress of a render: fraction of paths done, rays so far, seconds since start.
using ProgressFn = std::function<void(double done, uint64_t rays, double seconds)>;

struct RenderOptions {
  RenderParams params{};
  Backend backend = Backend::Cpu;
  Kernel kernel = Kernel::Megakernel;
  int warmup = 0;          // untimed renders before the timed one (CUDA)
  int64_t wave_size = 0;   // wavefront path slots; 0 chooses from free memory
  int threads = 0;         // CPU threads; 0 uses every core
  ProgressFn progress;     // may be empty
};

struct StageTime {
  std::string name;
  double ms = 0;
};

struct RenderResult {
  std::vector<float> rgb;  // mean linear radiance per pixel, row 0 = top, RGB (a backend returns sums)
  uint64_t rays = 0;       // every ray intersected, counted once
  uint64_t paths = 0;      // pixels x samples
  double seconds = 0;      // the render alone: CUDA events on the GPU, wall clock on the CPU
  double upload_seconds = 0;
  std::string device;
  std::vector<StageTime> stages;         // wavefront: each stage's time, summed over bounces
  std::vector<uint64_t> live_per_bounce; // wavefront: paths alive entering each bounce, summed over waves
};

// Fails with SceneError for settings the backend cannot honour (naming the setting),
// and cuda::CudaError for CUDA failures (naming the call and the stage).
RenderResult render(const Scene& scene, const RenderOptions& options);

// Checks RenderParams against the sane limits; throws SceneError naming the setting.
void validate_params(const RenderParams& p);

// Params from the scene's defaults.
RenderParams default_params(const Scene& scene);

}  // namespace wt

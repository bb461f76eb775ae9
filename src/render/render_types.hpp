// What the dispatcher (render/renderer.hpp) and the backends (cpu/, cuda/) exchange:
// the options of one render and its result. A leaf header, so that the backends
// stand on it without depending on the dispatcher that calls them.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "render/errors.hpp"
#include "wavetrace/scene_view.hpp"

namespace wt {

enum class Backend { Cpu, Cuda };
enum class Kernel { Megakernel, MegakernelConstant, Wavefront, WavefrontUnsorted };

inline bool is_wavefront(Kernel k) { return k == Kernel::Wavefront || k == Kernel::WavefrontUnsorted; }

// Progress of a render: fraction of paths done, rays so far, seconds since start.
using ProgressFn = std::function<void(double done, uint64_t rays, double seconds)>;

struct RenderOptions {
  RenderParams params{};
  Backend backend = Backend::Cpu;
  Kernel kernel = Kernel::Megakernel;
  int warmup = 0;         // untimed renders before the timed one, on every backend
  int64_t wave_size = 0;  // wavefront path slots; 0 chooses (queues/wave.hpp)
  int threads = 0;        // CPU threads; 0 uses every core
  ProgressFn progress;    // may be empty
};

struct StageTime {
  std::string name;
  double ms = 0;
};

// What `RenderResult::rgb` holds: a backend adds every sample into its pixel;
// render() divides by the samples per pixel once, for every backend.
enum class Radiance { SumOfSamples, MeanOfSamples };

struct RenderResult {
  std::vector<float> rgb;  // linear RGB per pixel, row 0 = top; what it holds: `radiance`
  Radiance radiance = Radiance::SumOfSamples;
  uint64_t rays = 0;   // every ray intersected, counted once
  uint64_t paths = 0;  // pixels x samples
  double seconds = 0;  // the render alone: CUDA events on the GPU, wall clock on the CPU
  double upload_seconds = 0;
  std::string device;
  std::vector<StageTime> stages;          // wavefront: each stage's time, summed over bounces
  std::vector<uint64_t> live_per_bounce;  // wavefront: paths alive entering each bounce
};

}  // namespace wt

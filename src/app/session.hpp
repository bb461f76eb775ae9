// A render session: a scene loaded once and rendered as often as asked with a job's
// settings, in memory. The Python module (python/) drives it. The settings, their
// validation and the messages are those of `render` (resolve_options); nothing is
// written, and the stats are `--stats`'s.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/job.hpp"
#include "cuda/device_image.hpp"

namespace wt::app {

// A session's render: the outcome (its result holding each pixel's mean radiance),
// and what the job asked for beside it.
struct SessionRender {
  JobOutcome outcome;
  std::vector<float> denoised;  // the denoiser's image (width x height x 3) where the job denoises
  std::vector<AovImage> aovs;   // the job's AOVs (its `aov` list), in its order
  int cuda_device = 0;          // the CUDA device it ran on (the first of several); 0 on the CPU
  // A render on one CUDA device with no AOV and no denoiser: its image, finished on
  // the device (cuda/device_image.hpp), and the outcome's result.rgb is empty. Null
  // rgba otherwise. Its writing may still be under way when render() returns (the
  // outcome, its count of non-finite pixels and its job_seconds are whole): wait()
  // before reading it.
  cuda::DeviceImage image;
};

class Session {
 public:
  // `scene` as loaded from `source`, the name the messages and the stats give it.
  Session(std::shared_ptr<const Scene> scene, std::string source);

  // Renders the scene with the job's settings, its AOVs and its denoiser (its scene,
  // output, stats, checkpoint and keep_noisy fields are not read). On the CUDA backend
  // the scene is uploaded to a device at its first render there and kept for the
  // next (uploads() counts them); renders may run from several threads at once.
  // `progress`: the share done, called from the rendering thread; `stop`: asked
  // wherever the render tells its progress (each bounce of a wavefront, each chunk
  // of rows of the CPU megakernel, each of the CUDA megakernel's passes, at least
  // ten; each step of an adaptive render), at most every 10 ms, so that the render
  // keeps the passes and the speed it has without them; progress is told 1 once, when
  // the render has returned whole. True ends the render there (the outcome's result
  // then says interrupted and holds no image, and no AOV or denoiser runs). Throws
  // InputError for bad settings and DeviceError when the machine fails, as run_job
  // reports them. The result holds each pixel's mean radiance, or the render's image
  // on its CUDA device holds them (SessionRender::image).
  // `image_memory`: where an image finished on the device is written (page-locked host
  // memory for an image wanted on the host); empty: device memory.
  SessionRender render(const Job& job, const std::function<void(double)>& progress = {},
                       const std::function<bool()>& stop = {}, const cuda::ImageMemory& image_memory = {}) const;

  // What `--stats` writes for that render.
  nlohmann::json stats(const Job& job, const JobOutcome& outcome) const;

  const Scene& scene() const { return *scene_; }
  const std::string& source() const { return source_; }
  // The scene's uploads to devices so far.
  int64_t uploads() const;
  // Frees the scene's copies on the devices (the next render uploads it again).
  void release_devices();

 private:
  std::shared_ptr<const Scene> scene_;
  std::string source_;
  mutable std::mutex resident_mutex_;
  mutable std::shared_ptr<ResidentScenes> resident_;  // made at the first CUDA render
  mutable int64_t released_uploads_ = 0;              // of copies released since
};

}  // namespace wt::app

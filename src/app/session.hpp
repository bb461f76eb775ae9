// A render session: a scene loaded once and rendered as often as asked with a job's
// settings, in memory. The Python module (python/) drives it. The settings, their
// validation and the messages are those of `render` (resolve_options); nothing is
// written, and the stats are `--stats`'s.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "app/job.hpp"

namespace wt::app {

class Session {
 public:
  // `scene` as loaded from `source`, the name the messages and the stats give it.
  Session(std::shared_ptr<const Scene> scene, std::string source);

  // Renders the scene with the job's settings (its scene, output, stats, checkpoint,
  // denoise and AOV fields are not read). `progress`: the share done, called from the
  // rendering thread; `stop`: asked after every pass (a uniform render then takes
  // passes of 1/256 of its samples, as a checkpointed `render` does; an adaptive one
  // asks after each step), true ends the render there (the outcome's result then says
  // interrupted). Throws InputError for bad settings and
  // DeviceError when the machine fails, as run_job reports them. The result holds
  // each pixel's mean radiance.
  JobOutcome render(const Job& job, const std::function<void(double)>& progress = {},
                    const std::function<bool()>& stop = {}) const;

  // What `--stats` writes for that render.
  nlohmann::json stats(const Job& job, const JobOutcome& outcome) const;

  const Scene& scene() const { return *scene_; }
  const std::string& source() const { return source_; }

 private:
  std::shared_ptr<const Scene> scene_;
  std::string source_;
};

}  // namespace wt::app

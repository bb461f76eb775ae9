// The small job the job tests render: on the CPU, 16 x 9 at 2 spp, quiet.
#pragma once

#include <string>

#include "app/job.hpp"

namespace wt::test {

inline app::Job small_job(const std::string& scene, const std::string& output) {
  app::Job j;
  j.scene = scene;
  j.output = output;
  j.backend = "cpu";
  j.width = 16;
  j.height = 9;
  j.spp = 2;
  j.progress = false;
  return j;
}

}  // namespace wt::test

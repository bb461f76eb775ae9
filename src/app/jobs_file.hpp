// Jobs files ({"defaults": {...}, "jobs": [{"scene": ..., "output": ..., ...}]}) read
// into jobs, and the one input of `wavetrace batch` told apart: the job descriptions
// alone, which need no renderer (the fuzz build reads them without one).
#pragma once

#include <string>
#include <vector>

#include "app/job.hpp"

namespace wt::app {

// Paths inside a jobs file are relative to the file. A malformed file throws
// InputError; a bad job becomes a job whose error is reported when it runs.
struct PlannedJob {
  Job job;
  std::string error;  // non-empty: the job cannot run, and this says why
};
std::vector<PlannedJob> read_jobs_file(const std::string& path, const Job& base);

// What the one input of `wavetrace batch` is: a jobs file (a JSON object with "jobs")
// or a scene file (one with "camera"). Throws InputError naming the file where it
// cannot be read, is not JSON, or is neither (a jobs file without "jobs" is not
// taken for a scene).
enum class BatchInput { JobsFile, Scene };
BatchInput batch_input(const std::string& path);

}  // namespace wt::app

#pragma once

#include <string>
#include <vector>

#include "app/job.hpp"

namespace wt::app {

// Jobs from a jobs file: {"defaults": {...}, "jobs": [{"scene": ..., "output": ..., ...}]}.
// Paths inside it are relative to the file. A malformed file throws SceneError; a bad
// job becomes a job whose error is reported when it runs.
struct PlannedJob {
  Job job;
  std::string error;  // non-empty: the job cannot run, and this says why
};
std::vector<PlannedJob> read_jobs_file(const std::string& path, const Job& base);

// Whether a file parses as JSON with a top-level "jobs" key (a scene file has none).
bool is_jobs_file(const std::string& path);

// Runs every job, prints a summary table, returns the exit code (non-zero if any failed).
// `skip_done`: jobs whose image exists are skipped (a batch resumed). A job stopped
// by a signal stops the batch, whose exit code is then the job's.
int run_batch(const std::vector<PlannedJob>& jobs, bool skip_done = false);

}  // namespace wt::app

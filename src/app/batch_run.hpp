// The batch's schedule, whichever way its jobs run: which job comes next, what each
// did, and the summary (BatchRun); the lanes that take jobs as they free up
// (run_jobs). Internal to the batch (batch.cpp, batch_ranks.cpp).
#pragma once

#include <cstddef>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "app/jobs_file.hpp"

namespace wt::app {

// Runs one job of a batch in lane `lane`: its outcome, whose message the batch prints.
using JobRunner = std::function<JobOutcome(size_t lane, size_t index, const Job& job)>;
// Called by a lane that has no job left (may be empty).
using LaneDone = std::function<void(size_t lane)>;

// The job as a lane runs it: on the lane's CUDA devices ("": the job's own), without
// a progress line where lanes run at once.
Job lane_job(Job job, const std::string& devices, bool quiet);

// One run of a batch: which job comes next, what each did, and the summary. Its lanes
// (threads of this process, and an MPI run's other ranks) take jobs as they free up.
class BatchRun {
 public:
  BatchRun(const std::vector<PlannedJob>& jobs, bool skip_done, std::function<int()> signal_caught)
      : jobs_(jobs), skip_done_(skip_done), signal_caught_(std::move(signal_caught)), rows_(jobs.size()) {}

  // The next job to run, said on its line with where it runs; none when every job is
  // taken or the batch was interrupted.
  std::optional<size_t> take(const std::string& where);

  // Settles job i where it needs no render: skipped (its image exists, the batch being
  // resumed; images are written through a temporary file renamed into place, so one
  // that exists is complete), or refused when it was read. True if settled.
  bool settle(size_t i);

  // Records job i's outcome: its row of the summary, and whether it stops the batch.
  void record(size_t i, const JobOutcome& o);

  // A lane of this process: runs jobs with `run` until none is left. `devices`: the
  // lane's CUDA devices ("": the job's own); `quiet`: no progress lines (lanes at once).
  void lane(const JobRunner& run, size_t lane_index, const std::string& devices, bool quiet,
            const LaneDone& done = {});

  // Prints the summary table and the count line; the batch's exit code.
  int summary() const;

  const Job& job(size_t i) const { return jobs_[i].job; }

 private:
  struct Row {
    bool done = false;
    std::string scene, settings, kernel, status;
    double seconds = 0, mrays = 0;
  };

  static Row row_of(const PlannedJob& pj) {
    Row row;
    row.done = true;
    row.scene = pj.job.scene;
    row.kernel = pj.job.kernel;
    return row;
  }

  const std::vector<PlannedJob>& jobs_;
  const bool skip_done_;
  const std::function<int()> signal_caught_;
  std::mutex m_;
  std::vector<Row> rows_;
  size_t next_ = 0, run_count_ = 0;
  int failed_ = 0, interrupted_ = 0;
};

// The batch loop and its summary, whichever way the jobs run. `signal_caught`: a
// signal the batch itself caught (0: none), which stops it after the jobs it runs.
// `lanes`: the jobs run in as many lanes at once, each lane's CUDA jobs on its
// devices ("" : the job's own); the summary lists them in the batch's order.
int run_jobs(const std::vector<PlannedJob>& jobs, bool skip_done, const JobRunner& run,
             const std::function<int()>& signal_caught, const std::vector<std::string>& lanes = {""},
             const LaneDone& lane_done = {});

}  // namespace wt::app

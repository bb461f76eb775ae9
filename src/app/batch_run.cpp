#include "app/batch_run.hpp"

#include <cstdio>
#include <filesystem>
#include <thread>

namespace wt::app {

// The job as a lane runs it: on the lane's CUDA devices ("": the job's own), without
// a progress line where lanes run at once.
Job lane_job(Job job, const std::string& devices, bool quiet) {
  if (!devices.empty() && job.backend != "cpu") job.devices = devices;
  if (quiet) job.progress = false;
  return job;
}

std::optional<size_t> BatchRun::take(const std::string& where) {
  std::lock_guard<std::mutex> lock(m_);
  if (interrupted_ || next_ >= jobs_.size()) return std::nullopt;
  const size_t i = next_++;
  std::fprintf(stderr, "[%zu/%zu] %s%s\n", i + 1, jobs_.size(), jobs_[i].job.scene.c_str(),
               where.empty() ? "" : (" on " + where).c_str());
  return i;
}

bool BatchRun::settle(size_t i) {
  const PlannedJob& pj = jobs_[i];
  if (skip_done_ && pj.error.empty() && std::filesystem::exists(pj.job.output)) {
    Row row = row_of(pj);
    row.status = "skipped: " + pj.job.output + " exists";
    std::lock_guard<std::mutex> lock(m_);
    rows_[i] = row;
    ++run_count_;
    return true;
  }
  if (pj.error.empty()) return false;
  JobOutcome o;
  o.exit_code = kExitBadInput;
  o.message = pj.error;
  record(i, o);
  return true;
}

void BatchRun::record(size_t i, const JobOutcome& o) {
  const PlannedJob& pj = jobs_[i];
  Row row = row_of(pj);
  if (o.exit_code != 0) {
    row.status = "FAILED: " + o.message;
    std::fprintf(stderr, "wavetrace: %s\n", o.message.c_str());
  } else {
    row.status = "ok -> " + pj.job.output;
    row.kernel = o.backend + "/" + o.kernel;
    row.settings = std::to_string(o.params.width) + "x" + std::to_string(o.params.height) + " " +
                   std::to_string(o.params.spp) + "spp d" + std::to_string(o.params.depth);
    row.seconds = o.result.seconds;
    row.mrays = o.result.seconds > 0 ? o.result.rays / o.result.seconds / 1e6 : 0;
  }
  std::lock_guard<std::mutex> lock(m_);
  rows_[i] = row;
  ++run_count_;
  if (o.exit_code != 0) ++failed_;
  // A signal stopped the job (after its last checkpoint), or reached the batch
  // while the job ran: the batch stops too, after the jobs running finish.
  if (o.exit_code >= 128 && !interrupted_) interrupted_ = o.exit_code;
  if (const int sig = signal_caught_ ? signal_caught_() : 0; sig != 0 && !interrupted_) interrupted_ = 128 + sig;
}

void BatchRun::lane(const JobRunner& run, size_t lane_index, const std::string& devices, bool quiet,
            const LaneDone& done) {
  while (const std::optional<size_t> i = take(devices.empty() ? "" : "cuda " + devices)) {
    if (settle(*i)) continue;
    record(*i, run(lane_index, *i, lane_job(jobs_[*i].job, devices, quiet)));
  }
  if (done) done(lane_index);
}

int BatchRun::summary() const {
  std::printf("%-4s %-32s %-22s %-26s %9s %10s  %s\n", "job", "scene", "settings", "backend/kernel", "seconds",
              "M rays/s", "result");
  for (size_t i = 0; i < rows_.size(); ++i) {
    const Row& r = rows_[i];
    if (!r.done) continue;
    std::printf("%-4zu %-32s %-22s %-26s %9.3f %10.2f  %s\n", i + 1, r.scene.c_str(), r.settings.c_str(),
                r.kernel.c_str(), r.seconds, r.mrays, r.status.c_str());
  }
  std::printf("%zu jobs: %zu ok, %d failed", run_count_, run_count_ - failed_, failed_);
  if (interrupted_) std::printf("; interrupted, %zu not run", jobs_.size() - run_count_);
  std::printf("\n");
  std::fflush(stdout);
  if (interrupted_) return interrupted_;
  return failed_ ? kExitFailure : 0;
}

int run_jobs(const std::vector<PlannedJob>& jobs, bool skip_done, const JobRunner& run,
             const std::function<int()>& signal_caught, const std::vector<std::string>& lanes,
             const LaneDone& lane_done) {
  BatchRun batch(jobs, skip_done, signal_caught);
  if (lanes.size() <= 1) {
    batch.lane(run, 0, lanes.empty() ? std::string() : lanes[0], false, lane_done);
  } else {
    std::vector<std::thread> threads;
    for (size_t l = 0; l < lanes.size(); ++l) {
      threads.emplace_back([&, l] { batch.lane(run, l, lanes[l], true, lane_done); });
    }
    for (std::thread& t : threads) t.join();
  }
  return batch.summary();
}

}  // namespace wt::app

#include "app/batch.hpp"

#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "app/batch_ranks.hpp"
#include "app/batch_run.hpp"
#include "app/distributed.hpp"
#include "app/job_processes.hpp"
#include "app/process.hpp"

namespace wt::app {

int run_batch(const std::vector<PlannedJob>& jobs, bool skip_done) {
  // A sticky error poisons this process's CUDA context for good: the CUDA jobs after
  // it fail at once, the CPU jobs still run.
  std::string lost_in;
  const JobRunner run = [&](size_t, size_t index, const Job& job) {
    if (!lost_in.empty() && job.backend != "cpu") {
      JobOutcome o;
      o.exit_code = kExitFailure;
      o.device_lost = true;
      o.message = "CUDA device lost in this process: job " + lost_in +
                  " met a sticky error; a new process gets a clean context (wavetrace batch runs each job in its own)";
      return o;
    }
    JobOutcome o = run_job(job);
    if (o.device_lost) lost_in = std::to_string(index + 1);
    return o;
  };
  return run_jobs(jobs, skip_done, run, nullptr);
}

std::vector<std::string> batch_lanes(const std::string& devices, const std::string& backend, size_t jobs,
                                     int present, const Cluster& cluster) {
  if (backend == "cpu" || present == 0 || jobs == 0) return {""};
  // The ranks of an MPI run on one host share its GPUs out.
  const std::vector<int> list =
      local_share(parse_devices(devices, Backend::Cuda, present), cluster.local_rank(), cluster.local_ranks());
  if (list.size() <= 1) {
    if (cluster.local_ranks() > 1 && list.size() == 1) return {std::to_string(list[0])};
    return {devices == "all" ? "" : devices};
  }
  // A lane per device; with fewer jobs than devices, a lane per job, each over its
  // share of the devices.
  const size_t lanes = std::min(list.size(), jobs);
  std::vector<std::string> out(lanes);
  for (size_t i = 0; i < list.size(); ++i) {
    std::string& lane = out[i % lanes];
    lane += (lane.empty() ? "" : ",") + std::to_string(list[i]);
  }
  return out;
}

int run_batch_in_processes(const std::vector<PlannedJob>& jobs, bool skip_done, const std::string& executable,
                           const std::vector<std::string>& lanes, const Cluster& cluster, JobProcesses processes) {
  const SignalForwarder signals;
  // A worker per lane (made before the lanes start, ended before the forwarder).
  std::vector<std::unique_ptr<WorkerProcess>> workers;
  if (processes == JobProcesses::PerLane) {
    for (size_t l = 0; l < lanes.size(); ++l) workers.push_back(std::make_unique<WorkerProcess>(executable));
  }
  const JobRunner run = [&](size_t lane, size_t index, const Job& job) {
    return processes == JobProcesses::PerJob ? run_job_in_process(executable, index, job, signals)
                                             : run_job_in_worker(*workers.at(lane), index, job, signals);
  };
  // A lane out of jobs lets its worker end (freeing its GPU) while the others work.
  const LaneDone lane_done = [&](size_t lane) {
    if (lane < workers.size()) workers[lane]->finish();
  };
  if (!cluster.distributed()) {
    return run_jobs(jobs, skip_done, run, [&] { return signals.caught(); }, lanes, lane_done);
  }

  // An MPI run: every rank's lanes take jobs as they free up; rank 0 hands them out
  // and alone prints the summary.
  const std::vector<std::string> counts = cluster.gather(std::to_string(lanes.size()));
  const bool quiet = cluster.ranks() > 1 || lanes.size() > 1;
  std::vector<std::thread> threads;
  if (!cluster.root()) {
    for (size_t l = 0; l < lanes.size(); ++l) {
      threads.emplace_back([&, l] { rank_lane(cluster, static_cast<int>(l), lanes[l], quiet, run, lane_done); });
    }
    for (std::thread& t : threads) t.join();
    return signals.caught() ? 128 + signals.caught() : 0;
  }
  size_t remote_lanes = 0;
  for (size_t r = 1; r < counts.size(); ++r) remote_lanes += std::stoul(counts[r]);
  BatchRun batch(jobs, skip_done, [&] { return signals.caught(); });
  for (size_t l = 0; l < lanes.size(); ++l) {
    threads.emplace_back([&, l] { batch.lane(run, l, lanes[l], quiet, lane_done); });
  }
  serve_ranks(cluster, batch, remote_lanes);
  for (std::thread& t : threads) t.join();
  return batch.summary();
}

}  // namespace wt::app

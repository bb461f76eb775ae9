#include "app/batch.hpp"

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <nlohmann/json.hpp>

#include "app/cli.hpp"
#include "app/distributed.hpp"
#include "app/process.hpp"
#include "app/signals.hpp"

#include "errors/errors.hpp"
#include "render/settings.hpp"
#include "scene/json_reader.hpp"

namespace wt::app {

namespace fs = std::filesystem;

namespace {

// Runs one job of a batch in lane `lane`: its outcome, whose message the batch prints.
using JobRunner = std::function<JobOutcome(size_t lane, size_t index, const Job& job)>;
// Called by a lane that has no job left (may be empty).
using LaneDone = std::function<void(size_t lane)>;

// The job as a lane runs it: on the lane's CUDA devices ("": the job's own), without
// a progress line where lanes run at once.
Job lane_job(Job job, const std::string& devices, bool quiet) {
  if (!devices.empty() && job.backend != "cpu") job.devices = devices;
  if (quiet) job.progress = false;
  return job;
}

// One run of a batch: which job comes next, what each did, and the summary. Its lanes
// (threads of this process, and an MPI run's other ranks) take jobs as they free up.
class BatchRun {
 public:
  BatchRun(const std::vector<PlannedJob>& jobs, bool skip_done, std::function<int()> signal_caught)
      : jobs_(jobs), skip_done_(skip_done), signal_caught_(std::move(signal_caught)), rows_(jobs.size()) {}

  // The next job to run, said on its line with where it runs; none when every job is
  // taken or the batch was interrupted.
  std::optional<size_t> take(const std::string& where) {
    std::lock_guard<std::mutex> lock(m_);
    if (interrupted_ || next_ >= jobs_.size()) return std::nullopt;
    const size_t i = next_++;
    std::fprintf(stderr, "[%zu/%zu] %s%s\n", i + 1, jobs_.size(), jobs_[i].job.scene.c_str(),
                 where.empty() ? "" : (" on " + where).c_str());
    return i;
  }

  // Settles job i where it needs no render: skipped (its image exists, the batch being
  // resumed; images are written through a temporary file renamed into place, so one
  // that exists is complete), or refused when it was read. True if settled.
  bool settle(size_t i) {
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

  void record(size_t i, const JobOutcome& o) {
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

  // A lane of this process: runs jobs with `run` until none is left. `devices`: the
  // lane's CUDA devices ("": the job's own); `quiet`: no progress lines (lanes at once).
  void lane(const JobRunner& run, size_t lane_index, const std::string& devices, bool quiet,
            const LaneDone& done = {}) {
    while (const std::optional<size_t> i = take(devices.empty() ? "" : "cuda " + devices)) {
      if (settle(*i)) continue;
      record(*i, run(lane_index, *i, lane_job(jobs_[*i].job, devices, quiet)));
    }
    if (done) done(lane_index);
  }

  // Prints the summary table and the count line; the batch's exit code.
  int summary() const {
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
             const LaneDone& lane_done = {}) {
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

// What a job's stats file says about its render, for the summary.
void read_measurements(const std::string& path, JobOutcome& o) {
  std::string text;
  try {
    text = read_input_file(path, InputKind{"stats file", input::kJobs.max_bytes});
  } catch (const InputError&) {
    return;
  }
  const json j = json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return;
  for (SettingId id : render_settings()) set_param(o.params, id, j["settings"].value(setting(id).key, int64_t(0)));
  o.backend = j.value("backend", "");
  o.kernel = j.value("kernel", "");
  o.result.seconds = j.value("seconds", 0.0);
  o.result.rays = j.value("rays", uint64_t(0));
}

// A job whose process a signal killed: a signal the batch passed on stops the batch,
// as a job interrupted after its checkpoint does; any other signal fails this job alone.
void killed(const ChildEnd& end, const SignalForwarder& signals, JobOutcome& o) {
  o.exit_code = end.signal == signals.caught() ? 128 + end.signal : kExitFailure;
  o.message = "the job's process was killed by " + signal_name(end.signal);
}

std::string exited_silently(int code) {
  return "the job's process exited with " + std::to_string(code) + " without saying why";
}

// Runs one job as `wavetrace render` in a process of its own.
JobOutcome run_job_in_process(const std::string& executable, size_t index, const Job& job,
                              const SignalForwarder& signals) {
  JobOutcome o;
  Job child_job = job;
  // The summary's figures come from a stats file: the job's own, or one of ours.
  if (child_job.stats.empty()) {
    child_job.stats = (fs::temp_directory_path() / ("wavetrace-batch-" + std::to_string(::getpid()) + "-" +
                                                    std::to_string(index + 1) + ".json"))
                          .string();
  }
  ChildEnd end;
  try {
    end = run_child(executable, render_arguments(child_job));
  } catch (const std::exception& e) {
    o.exit_code = kExitFailure;
    o.message = e.what();
    return o;
  }
  if (end.exited) {
    o.exit_code = end.exit_code;
    o.message = end.last_line;
    if (o.exit_code == 0) {
      read_measurements(child_job.stats, o);
      if (!end.last_line.empty()) std::fprintf(stderr, "wavetrace: %s\n", end.last_line.c_str());
    } else if (o.message.empty()) {
      o.message = exited_silently(o.exit_code);
    }
  } else {
    killed(end, signals, o);
  }
  if (child_job.stats != job.stats) {
    std::error_code ignored;
    fs::remove(child_job.stats, ignored);
  }
  return o;
}

}  // namespace

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

namespace {

// What a rank's lane says of the job it ran, and rank 0 reads back.
json outcome_json(size_t index, const JobOutcome& o) {
  return json{{"index", index},        {"exit_code", o.exit_code},        {"message", o.message},
              {"backend", o.backend},  {"kernel", o.kernel},              {"width", o.params.width},
              {"height", o.params.height}, {"spp", o.params.spp},         {"depth", o.params.depth},
              {"seconds", o.result.seconds}, {"rays", o.result.rays},     {"device_lost", o.device_lost}};
}

JobOutcome outcome_of(const json& j) {
  JobOutcome o;
  o.exit_code = j.value("exit_code", kExitFailure);
  o.message = j.value("message", "");
  o.backend = j.value("backend", "");
  o.kernel = j.value("kernel", "");
  o.params.width = j.value("width", 0);
  o.params.height = j.value("height", 0);
  o.params.spp = j.value("spp", 0);
  o.params.depth = j.value("depth", 0);
  o.result.seconds = j.value("seconds", 0.0);
  o.result.rays = j.value("rays", uint64_t(0));
  o.device_lost = j.value("device_lost", false);
  return o;
}

// Runs one job in the lane's worker (`wavetrace worker`, run_batch_worker). A job
// that lost the worker's CUDA context, or that a signal interrupted, ends the worker
// (the next job starts a new one); so does a worker that dies, failing its job alone.
JobOutcome run_job_in_worker(WorkerProcess& worker, size_t index, const Job& job, const SignalForwarder& signals) {
  JobOutcome o;
  ChildEnd end;
  std::optional<std::string> answer;
  try {
    answer = worker.ask(json{{"index", index}, {"args", render_arguments(job)}}.dump(), end);
  } catch (const std::exception& e) {
    o.exit_code = kExitFailure;
    o.message = e.what();
    return o;
  }
  if (answer) {
    const json said = json::parse(*answer, nullptr, false);
    if (said.is_object() && said.value("index", index + 1) == index) {
      o = outcome_of(said);
      if (o.device_lost || o.exit_code >= 128) worker.stop();
      return o;
    }
    end = worker.stop();
    o.exit_code = kExitFailure;
    o.message = "the job's process answered what it was not asked: " + answer->substr(0, 200);
    return o;
  }
  if (end.exited) {
    o.exit_code = end.exit_code == 0 ? kExitFailure : end.exit_code;
    o.message = exited_silently(end.exit_code);
  } else {
    killed(end, signals, o);
  }
  return o;
}

// Rank 0 of an MPI batch, on its main thread while its own lanes run: answers the
// other ranks' lanes, each asking for a job with what its last one did, until every
// one has been told that none is left.
void serve_ranks(const Cluster& cluster, BatchRun& batch, size_t remote_lanes) {
  while (remote_lanes > 0) {
    const ClusterMessage m = cluster.receive_any();
    const json said = json::parse(m.text);
    if (said.contains("index")) batch.record(said["index"].get<size_t>(), outcome_of(said));
    const std::string where = "rank " + std::to_string(m.from) + " (" + said.value("host", "") + ")" +
                              (said.value("devices", "").empty() ? "" : " cuda " + said.value("devices", ""));
    std::optional<size_t> i;
    while ((i = batch.take(where)) && batch.settle(*i)) {
    }
    if (!i) {
      cluster.send(m.from, m.tag, "");
      --remote_lanes;
    } else {
      cluster.send(m.from, m.tag, json{{"index", *i}, {"args", render_arguments(batch.job(*i))}}.dump());
    }
  }
}

// A lane of another rank than 0: asks rank 0 for jobs (its tag: the lane's number),
// runs each as a process of its own on the lane's devices, and says how it went.
void rank_lane(const Cluster& cluster, int tag, const std::string& devices, bool quiet, const JobRunner& run,
               const LaneDone& done) {
  json said = {{"host", cluster.host()}, {"devices", devices}};
  for (;;) {
    cluster.send(0, tag, said.dump());
    const std::string answer = cluster.receive(0, tag);
    if (answer.empty()) {
      done(static_cast<size_t>(tag));
      return;
    }
    const json given = json::parse(answer);
    const size_t index = given["index"].get<size_t>();
    JobOutcome o;
    try {
      const Job job = parse_render_arguments(given["args"].get<std::vector<std::string>>());
      o = run(static_cast<size_t>(tag), index, lane_job(job, devices, quiet));
    } catch (const std::exception& e) {
      o.exit_code = kExitFailure;
      o.message = std::string("rank ") + std::to_string(cluster.rank()) + " could not take the job: " + e.what();
    }
    said = outcome_json(index, o);
    said["host"] = cluster.host();
    said["devices"] = devices;
  }
}

}  // namespace

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

int run_batch_worker(int answers) {
  FILE* out = ::fdopen(answers, "w");
  if (!out) {
    std::fprintf(stderr,
                 "wavetrace: worker: descriptor %d is not open for answers (the worker is started by wavetrace batch)\n",
                 answers);
    return kExitFailure;
  }
  for (std::string line; std::getline(std::cin, line);) {
    const json asked = json::parse(line, nullptr, false);
    const size_t index = asked.is_object() ? asked.value("index", size_t(0)) : 0;
    JobOutcome o;
    try {
      const Job job = parse_render_arguments(asked.at("args").get<std::vector<std::string>>());
      o = run_job(job);
      if (o.exit_code == 0) print_outcome(job, o);
    } catch (const std::exception& e) {
      o.exit_code = kExitBadInput;
      o.message = std::string("the worker could not read its job: ") + e.what();
    }
    std::fflush(stderr);
    if (std::fputs((outcome_json(index, o).dump() + "\n").c_str(), out) < 0 || std::fflush(out) != 0) {
      return kExitFailure;  // the batch is gone
    }
    // A lost CUDA context stays lost in this process; an interrupted job stops the batch.
    if (o.device_lost) return kExitFailure;
    if (o.exit_code >= 128) return o.exit_code;
  }
  std::fclose(out);
  return 0;
}

void release_ranks(const Cluster& cluster) {
  const std::vector<std::string> counts = cluster.gather("0");
  size_t remote_lanes = 0;
  for (size_t r = 1; r < counts.size(); ++r) remote_lanes += std::stoul(counts[r]);
  const std::vector<PlannedJob> none;
  BatchRun batch(none, false, nullptr);
  serve_ranks(cluster, batch, remote_lanes);
}

}  // namespace wt::app

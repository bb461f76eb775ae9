#include "app/batch.hpp"

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <thread>
#include <nlohmann/json.hpp>

#include "app/cli.hpp"
#include "app/process.hpp"
#include "app/signals.hpp"

#include "render/settings.hpp"
#include "scene/json_reader.hpp"

namespace wt::app {

namespace fs = std::filesystem;

namespace {

std::string relative_to(const fs::path& base, const std::string& p) {
  fs::path path(p);
  return path.is_absolute() ? p : (base / path).lexically_normal().string();
}

// The keys of a job (and of "defaults"): the files, then every setting of the table.
const std::vector<std::string>& job_keys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k = {"scene", "output", "stats", "checkpoint", "resume", "backend", "kernel", "encoding",
                                  "exr_float"};
    for (const Setting& s : settings()) k.push_back(s.key);
    return k;
  }();
  return keys;
}

// Applies the fields of one JSON object to a job; throws SceneError naming the file and field.
void apply_fields(const JsonReader& r, const json& obj, const JsonPath& path, const fs::path& base, Job& job) {
  r.check_keys(obj, path, job_keys());
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const std::string& key = it.key();
    const json& value = it.value();
    const JsonPath at = path / key;
    if (key == "scene") {
      job.scene = relative_to(base, r.string(value, at));
    } else if (key == "output") {
      job.output = relative_to(base, r.string(value, at));
    } else if (key == "stats") {
      job.stats = relative_to(base, r.string(value, at));
    } else if (key == "checkpoint") {
      job.checkpoint = relative_to(base, r.string(value, at));
    } else if (key == "resume") {
      job.resume = relative_to(base, r.string(value, at));
    } else if (key == "backend") {
      job.backend = backend_choices()[r.choice(value, at, backend_choices())];
    } else if (key == "kernel") {
      job.kernel = kernel_names()[r.choice(value, at, kernel_names())];
    } else if (key == "encoding") {
      job.encoding = r.choice(value, at, encoding_choices()) == 0 ? Encoding::Srgb : Encoding::Gamma2;
    } else if (key == "exr_float") {
      job.exr_float = r.boolean(value, at);
    } else {
      for (const Setting& s : settings()) {
        if (key == s.key) set_setting(job, s.id, r.integer(value, at, s.lo, s.hi));
      }
    }
  }
}

}  // namespace

bool is_jobs_file(const std::string& path) {
  std::ifstream f(path);
  if (!f) return false;
  json doc = json::parse(f, nullptr, false);
  return !doc.is_discarded() && doc.is_object() && doc.contains("jobs");
}

std::vector<PlannedJob> read_jobs_file(const std::string& path, const Job& base) {
  const json doc = read_json_file(path, "jobs file");
  const JsonReader r(path);
  const JsonPath top;
  r.check_keys(doc, top, {"jobs", "defaults"});
  const JsonPath jobs_path = top / "jobs";
  const json& list = r.array(r.required(doc, top, "jobs"), jobs_path);
  const fs::path folder = fs::path(path).parent_path();
  Job defaults = base;
  if (doc.contains("defaults")) apply_fields(r, doc["defaults"], top / "defaults", folder, defaults);
  std::vector<PlannedJob> jobs;
  for (size_t i = 0; i < list.size(); ++i) {
    PlannedJob planned{defaults, ""};
    const JsonPath at = jobs_path / i;
    try {
      apply_fields(r, list[i], at, folder, planned.job);
      if (planned.job.scene.empty()) r.fail_at(at / "scene", "required key is missing (in the job or its defaults)");
      if (planned.job.output.empty()) r.fail_at(at / "output", "required key is missing (in the job or its defaults)");
    } catch (const SceneError& e) {
      planned.error = e.what();
    }
    jobs.push_back(planned);
  }
  return jobs;
}

namespace {

// Runs one job of a batch: its outcome, whose message the batch prints.
using JobRunner = std::function<JobOutcome(size_t index, const Job& job)>;

// The batch loop and its summary, whichever way the jobs run. `signal_caught`: a
// signal the batch itself caught (0: none), which stops it after the jobs it runs.
// `lanes`: the jobs run in as many lanes at once, each lane's CUDA jobs on its
// devices ("" : the job's own); the summary lists them in the batch's order.
int run_jobs(const std::vector<PlannedJob>& jobs, bool skip_done, const JobRunner& run,
             const std::function<int()>& signal_caught, const std::vector<std::string>& lanes = {""}) {
  struct Row {
    bool done = false;
    std::string scene, settings, kernel, status;
    double seconds = 0, mrays = 0;
  };
  std::vector<Row> rows(jobs.size());
  int failed = 0, interrupted = 0;
  size_t next = 0, run_count = 0;
  std::mutex m;
  auto lane = [&](const std::string& devices) {
    for (;;) {
      size_t i;
      {
        std::lock_guard<std::mutex> lock(m);
        if (interrupted || next >= jobs.size()) return;
        i = next++;
        std::fprintf(stderr, "[%zu/%zu] %s%s\n", i + 1, jobs.size(), jobs[i].job.scene.c_str(),
                     devices.empty() ? "" : (" on cuda " + devices).c_str());
      }
      const PlannedJob& pj = jobs[i];
      Row row;
      row.done = true;
      row.scene = pj.job.scene;
      row.kernel = pj.job.kernel;
      // Images are written through a temporary file renamed into place: one that
      // exists is complete.
      if (skip_done && pj.error.empty() && std::filesystem::exists(pj.job.output)) {
        row.status = "skipped: " + pj.job.output + " exists";
        std::lock_guard<std::mutex> lock(m);
        rows[i] = row;
        ++run_count;
        continue;
      }
      JobOutcome o;
      if (!pj.error.empty()) {
        o.exit_code = kExitBadInput;
        o.message = pj.error;
      } else {
        Job job = pj.job;
        if (!devices.empty() && job.backend != "cpu") job.devices = devices;
        if (lanes.size() > 1) job.progress = false;  // one line per job, not interleaved progress
        o = run(i, job);
      }
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
      std::lock_guard<std::mutex> lock(m);
      rows[i] = row;
      ++run_count;
      if (o.exit_code != 0) ++failed;
      // A signal stopped the job (after its last checkpoint), or reached the batch
      // while the job ran: the batch stops too, after the jobs running finish.
      if (o.exit_code >= 128 && !interrupted) interrupted = o.exit_code;
      if (const int sig = signal_caught ? signal_caught() : 0; sig != 0 && !interrupted) interrupted = 128 + sig;
    }
  };
  if (lanes.size() <= 1) {
    lane(lanes.empty() ? std::string() : lanes[0]);
  } else {
    std::vector<std::thread> threads;
    for (const std::string& devices : lanes) threads.emplace_back(lane, devices);
    for (std::thread& t : threads) t.join();
  }
  std::printf("%-4s %-32s %-22s %-26s %9s %10s  %s\n", "job", "scene", "settings", "backend/kernel", "seconds",
              "M rays/s", "result");
  for (size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    if (!r.done) continue;
    std::printf("%-4zu %-32s %-22s %-26s %9.3f %10.2f  %s\n", i + 1, r.scene.c_str(), r.settings.c_str(),
                r.kernel.c_str(), r.seconds, r.mrays, r.status.c_str());
  }
  std::printf("%zu jobs: %zu ok, %d failed", run_count, run_count - failed, failed);
  if (interrupted) std::printf("; interrupted, %zu not run", jobs.size() - run_count);
  std::printf("\n");
  std::fflush(stdout);
  if (interrupted) return interrupted;
  return failed ? kExitFailure : 0;
}

// What a job's stats file says about its render, for the summary.
void read_measurements(const std::string& path, JobOutcome& o) {
  std::ifstream f(path);
  const json j = json::parse(f, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return;
  for (SettingId id : render_settings()) set_param(o.params, id, j["settings"].value(setting(id).key, int64_t(0)));
  o.backend = j.value("backend", "");
  o.kernel = j.value("kernel", "");
  o.result.seconds = j.value("seconds", 0.0);
  o.result.rays = j.value("rays", uint64_t(0));
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
      o.message = "the job's process exited with " + std::to_string(o.exit_code) + " without saying why";
    }
  } else {
    // A signal the batch passed on stops the batch, as a job interrupted after its
    // checkpoint does; any other signal fails this job alone.
    const bool passed_on = end.signal == signals.caught();
    o.exit_code = passed_on ? 128 + end.signal : kExitFailure;
    o.message = "the job's process was killed by " + signal_name(end.signal);
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
  const JobRunner run = [&](size_t index, const Job& job) {
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
                                     int present) {
  if (backend == "cpu" || present == 0 || jobs == 0) return {""};
  const std::vector<int> list = parse_devices(devices, Backend::Cuda, present);
  if (list.size() <= 1) return {devices == "all" ? "" : devices};
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
                           const std::vector<std::string>& lanes) {
  const SignalForwarder signals;
  const JobRunner run = [&](size_t index, const Job& job) {
    return run_job_in_process(executable, index, job, signals);
  };
  return run_jobs(jobs, skip_done, run, [&] { return signals.caught(); }, lanes);
}

}  // namespace wt::app

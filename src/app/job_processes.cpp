#include "app/job_processes.hpp"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include "app/batch.hpp"
#include "app/cli.hpp"
#include "app/signals.hpp"
#include "errors/errors.hpp"
#include "render/settings.hpp"
#include "scene/input_file.hpp"

namespace wt::app {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

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

}  // namespace

// What a rank's lane says of the job it ran, and rank 0 reads back.
nlohmann::json outcome_json(size_t index, const JobOutcome& o) {
  return json{{"index", index},        {"exit_code", o.exit_code},        {"message", o.message},
              {"backend", o.backend},  {"kernel", o.kernel},              {"width", o.params.width},
              {"height", o.params.height}, {"spp", o.params.spp},         {"depth", o.params.depth},
              {"seconds", o.result.seconds}, {"rays", o.result.rays},     {"device_lost", o.device_lost}};
}

JobOutcome outcome_of(const nlohmann::json& j) {
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

}  // namespace wt::app

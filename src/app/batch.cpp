#include "app/batch.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

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
    std::vector<std::string> k = {"scene", "output", "stats", "checkpoint", "resume", "backend", "kernel", "encoding"};
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

int run_batch(const std::vector<PlannedJob>& jobs, bool skip_done) {
  struct Row {
    std::string scene, settings, kernel, status;
    double seconds = 0, mrays = 0;
  };
  std::vector<Row> rows;
  int failed = 0, interrupted = 0, resets = 0;
  for (size_t i = 0; i < jobs.size(); ++i) {
    const PlannedJob& pj = jobs[i];
    std::fprintf(stderr, "[%zu/%zu] %s\n", i + 1, jobs.size(), pj.job.scene.c_str());
    Row row;
    row.scene = pj.job.scene;
    row.kernel = pj.job.kernel;
    // Images are written through a temporary file renamed into place: one that
    // exists is complete.
    if (skip_done && pj.error.empty() && std::filesystem::exists(pj.job.output)) {
      row.status = "skipped: " + pj.job.output + " exists";
      rows.push_back(row);
      continue;
    }
    JobOutcome o;
    if (!pj.error.empty()) {
      o.exit_code = kExitBadInput;
      o.message = pj.error;
    } else {
      o = run_job(pj.job);
    }
    if (o.exit_code != 0) {
      ++failed;
      resets += o.device_reset;
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
    rows.push_back(row);
    // A signal stopped the job (after its last checkpoint): the batch stops too.
    if (o.exit_code >= 128) {
      interrupted = o.exit_code;
      break;
    }
  }
  std::printf("%-4s %-32s %-22s %-26s %9s %10s  %s\n", "job", "scene", "settings", "backend/kernel", "seconds",
              "M rays/s", "result");
  for (size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    std::printf("%-4zu %-32s %-22s %-26s %9.3f %10.2f  %s\n", i + 1, r.scene.c_str(), r.settings.c_str(),
                r.kernel.c_str(), r.seconds, r.mrays, r.status.c_str());
  }
  std::printf("%zu jobs: %zu ok, %d failed", rows.size(), rows.size() - failed, failed);
  std::printf(resets ? " (the device was reset after %d of them)" : "", resets);
  if (interrupted) std::printf("; interrupted, %zu not run", jobs.size() - rows.size());
  std::printf("\n");
  if (interrupted) return interrupted;
  return failed ? kExitFailure : 0;
}

}  // namespace wt::app

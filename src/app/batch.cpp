#include "app/batch.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "queues/path_queue.hpp"

namespace wt::app {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string relative_to(const fs::path& base, const std::string& p) {
  fs::path path(p);
  return path.is_absolute() ? p : (base / path).lexically_normal().string();
}

// Applies the fields of one JSON object to a job; throws SceneError naming the field.
void apply_fields(const json& obj, const std::string& where, const fs::path& base, Job& job) {
  if (!obj.is_object()) throw SceneError(where + ": must be an object");
  for (const auto& [key, value] : obj.items()) {
    const std::string field = where + "/" + key;
    auto integer = [&](int64_t lo, int64_t hi) {
      if (!value.is_number_integer() || value.get<int64_t>() < lo || value.get<int64_t>() > hi) {
        throw SceneError(field + ": must be an integer in " + std::to_string(lo) + ".." + std::to_string(hi));
      }
      return static_cast<int>(value.get<int64_t>());
    };
    auto text = [&]() {
      if (!value.is_string()) throw SceneError(field + ": must be a string");
      return value.get<std::string>();
    };
    if (key == "scene") job.scene = relative_to(base, text());
    else if (key == "output") job.output = relative_to(base, text());
    else if (key == "stats") job.stats = relative_to(base, text());
    else if (key == "width") job.width = integer(1, kMaxImageSide);
    else if (key == "height") job.height = integer(1, kMaxImageSide);
    else if (key == "spp") job.spp = integer(1, kMaxSpp);
    else if (key == "depth") job.depth = integer(1, kMaxPathDepth);
    else if (key == "roulette_depth") job.roulette_depth = integer(0, 1 << 30);
    else if (key == "seed") job.seed = static_cast<uint32_t>(integer(0, 0x7fffffff));
    else if (key == "backend") job.backend = text();
    else if (key == "kernel") job.kernel = text();
    else if (key == "warmup") job.warmup = integer(0, 100);
    else if (key == "wave_size") job.wave_size = integer(kMinWaveSlots, static_cast<int64_t>(kMaxWaveSize));
    else if (key == "encoding") {
      std::string e = text();
      if (e != "srgb" && e != "gamma2") throw SceneError(field + ": must be srgb or gamma2");
      job.encoding = e == "srgb" ? Encoding::Srgb : Encoding::Gamma2;
    } else {
      throw SceneError(field + ": unknown key");
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
  std::ifstream f(path);
  if (!f) throw SceneError(path + ": cannot open jobs file");
  json doc;
  try {
    doc = json::parse(f);
  } catch (const json::exception& e) {  // parse_error, and out_of_range for a number like 1e999
    throw SceneError(path + ": malformed JSON: " + e.what());
  }
  if (!doc.is_object() || !doc.contains("jobs") || !doc["jobs"].is_array()) {
    throw SceneError(path + ": /jobs: a jobs file needs a \"jobs\" array");
  }
  for (const auto& [key, value] : doc.items()) {
    if (key != "jobs" && key != "defaults") throw SceneError(path + ": /" + key + ": unknown key");
  }
  const fs::path folder = fs::path(path).parent_path();
  Job defaults = base;
  if (doc.contains("defaults")) apply_fields(doc["defaults"], path + ": /defaults", folder, defaults);
  std::vector<PlannedJob> jobs;
  for (size_t i = 0; i < doc["jobs"].size(); ++i) {
    PlannedJob planned{defaults, ""};
    try {
      apply_fields(doc["jobs"][i], path + ": /jobs/" + std::to_string(i), folder, planned.job);
      if (planned.job.scene.empty()) throw SceneError(path + ": /jobs/" + std::to_string(i) + ": needs a scene");
      if (planned.job.output.empty()) throw SceneError(path + ": /jobs/" + std::to_string(i) + ": needs an output");
    } catch (const SceneError& e) {
      planned.error = e.what();
    }
    jobs.push_back(planned);
  }
  return jobs;
}

int run_batch(const std::vector<PlannedJob>& jobs) {
  struct Row {
    std::string scene, settings, kernel, status;
    double seconds = 0, mrays = 0;
  };
  std::vector<Row> rows;
  int failed = 0;
  for (size_t i = 0; i < jobs.size(); ++i) {
    const PlannedJob& pj = jobs[i];
    std::fprintf(stderr, "[%zu/%zu] %s\n", i + 1, jobs.size(), pj.job.scene.c_str());
    Row row;
    row.scene = pj.job.scene;
    row.kernel = pj.job.kernel;
    JobOutcome o;
    if (!pj.error.empty()) {
      o.exit_code = kExitBadInput;
      o.message = pj.error;
    } else {
      o = run_job(pj.job);
    }
    if (o.exit_code != 0) {
      ++failed;
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
  }
  std::printf("%-4s %-32s %-22s %-26s %9s %10s  %s\n", "job", "scene", "settings", "backend/kernel", "seconds",
              "M rays/s", "result");
  for (size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    std::printf("%-4zu %-32s %-22s %-26s %9.3f %10.2f  %s\n", i + 1, r.scene.c_str(), r.settings.c_str(),
                r.kernel.c_str(), r.seconds, r.mrays, r.status.c_str());
  }
  std::printf("%zu jobs: %zu ok, %d failed\n", rows.size(), rows.size() - failed, failed);
  return failed ? kExitFailure : 0;
}

}  // namespace wt::app

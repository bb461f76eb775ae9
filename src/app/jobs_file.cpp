#include "app/jobs_file.hpp"

#include <cctype>
#include <filesystem>
#include <map>
#include <optional>

#include "errors/errors.hpp"
#include "render/settings.hpp"
#include "scene/input_file.hpp"
#include "scene/json_reader.hpp"
#include "scene/mitsuba_scene.hpp"

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
    std::vector<std::string> k = {"scene",    "output",    "stats",    "checkpoint",      "resume",    "backend",
                                  "kernel",   "encoding",  "exr_float", "denoise", "denoise_quality", "keep_noisy", "aov", "defines"};
    for (const Setting& s : settings()) k.push_back(s.key);
    return k;
  }();
  return keys;
}

// Applies the fields of one JSON object to a job; throws InputError naming the file and field.
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
    } else if (key == "denoise") {
      job.denoise = r.boolean(value, at);
    } else if (key == "denoise_quality") {
      job.denoise_quality = denoise_quality_choices()[r.choice(value, at, denoise_quality_choices())];
    } else if (key == "keep_noisy") {
      job.keep_noisy = r.boolean(value, at);
    } else if (key == "defines") {
      // A Mitsuba scene's parameters, {"name": "value"}: strings, or numbers as written.
      r.object(value, at);
      job.defines.clear();
      for (auto d = value.begin(); d != value.end(); ++d) {
        if (!d.value().is_string() && !d.value().is_number()) r.fail_at(at / d.key(), "must be a string or a number");
        if (!is_define_name(d.key())) r.fail_at(at / d.key(), "a parameter's name is letters, digits and _");
        job.defines[d.key()] = d.value().is_string() ? d.value().get<std::string>() : d.value().dump();
      }
    } else if (key == "aov") {
      job.aov = r.string(value, at);
      try {
        parse_aovs(job.aov, "");
      } catch (const InputError& e) {
        r.fail_at(at, e.what());
      }
    } else {
      for (const Setting& s : settings()) {
        if (key != s.key) continue;
        if (s.type == SettingType::Real) {
          job.noise_threshold = r.real_setting(value, at, s.id);
        } else {
          set_setting(job, s.id, r.integer_setting(value, at, s.id));
        }
      }
    }
  }
}

// The job a JSON pointer lies inside ("/jobs/3/spp": 3); none for one outside every
// job ("/defaults/spp", "/jobs").
std::optional<size_t> job_of_pointer(const std::string& at) {
  const std::string prefix = "/jobs/";
  if (at.rfind(prefix, 0) != 0) return std::nullopt;
  const size_t digits_end = at.find('/', prefix.size());
  if (digits_end == std::string::npos || digits_end == prefix.size()) return std::nullopt;
  size_t job = 0;
  for (size_t i = prefix.size(); i < digits_end; ++i) {
    if (!std::isdigit(static_cast<unsigned char>(at[i])) || job > SIZE_MAX / 10 - 1) return std::nullopt;
    job = job * 10 + static_cast<size_t>(at[i] - '0');
  }
  return job;
}

}  // namespace

BatchInput batch_input(const std::string& path) {
  if (mitsuba::is_mitsuba_scene(path)) return BatchInput::Scene;  // by its extension, as render reads it
  // Either kind of file, so the larger limit of the two.
  const std::string text = read_input_file(path, InputKind{"jobs file or scene file", input::kScene.max_bytes});
  const json doc = json::parse(text, nullptr, false);
  if (doc.is_discarded()) parse_json(text, path);  // throws, saying where the JSON breaks
  if (doc.is_object() && doc.contains("jobs")) return BatchInput::JobsFile;
  if (doc.is_object() && doc.contains("camera")) return BatchInput::Scene;
  if (doc.is_object() && doc.contains("defaults")) {
    throw InputError(path + ": /jobs: required key is missing (a jobs file lists its jobs under \"jobs\")");
  }
  throw InputError(path + ": neither a jobs file nor a scene file: a jobs file needs \"jobs\" (a list of jobs), a "
                          "scene file \"camera\" and \"materials\"");
}

std::vector<PlannedJob> read_jobs_file(const std::string& path, const Job& base) {
  // A key repeated inside one job fails that job alone; anywhere else, the file.
  std::vector<std::string> duplicates;
  const json doc = parse_json(read_input_file(path, input::kJobs), path, &duplicates);
  std::map<size_t, std::string> job_duplicates;
  for (const std::string& at : duplicates) {
    const std::optional<size_t> job = job_of_pointer(at);
    if (!job) throw InputError(path + ": " + at + ": duplicate key");
    job_duplicates.emplace(*job, path + ": " + at + ": duplicate key");
  }
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
      if (auto d = job_duplicates.find(i); d != job_duplicates.end()) throw InputError(d->second);
      apply_fields(r, list[i], at, folder, planned.job);
      if (planned.job.scene.empty()) r.fail_at(at / "scene", "required key is missing (in the job or its defaults)");
      if (planned.job.output.empty()) r.fail_at(at / "output", "required key is missing (in the job or its defaults)");
    } catch (const InputError& e) {
      planned.error = e.what();
    }
    jobs.push_back(planned);
  }
  return jobs;
}

}  // namespace wt::app

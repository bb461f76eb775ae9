#include "app/bench.hpp"

#include "render/adaptive.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/job.hpp"
#include "app/stats.hpp"
#include "build_info.hpp"
#include "device/device.hpp"
#include "errors/errors.hpp"
#include "render/adaptive.hpp"
#include "render/settings.hpp"
#include "scene/json_reader.hpp"

namespace wt::app {

namespace fs = std::filesystem;

BenchSpec read_bench_spec(const std::string& path, const std::string& only) {
  const json doc = read_json_file(path, input::kBenchSpec);
  const JsonReader r(path);
  const JsonPath top;
  r.check_keys(doc, top, {"warmup", "repeats", "check_spp", "check_bound", "groups"});
  BenchSpec spec;
  const Setting& warmup = setting(SettingId::Warmup);
  if (doc.contains("warmup")) spec.warmup = static_cast<int>(r.integer(doc["warmup"], top / "warmup", warmup.lo, warmup.hi));
  if (doc.contains("repeats")) spec.repeats = static_cast<int>(r.integer(doc["repeats"], top / "repeats", 1, kMaxRepeats));
  if (doc.contains("check_spp")) spec.check_spp = static_cast<int>(r.integer(doc["check_spp"], top / "check_spp", 1, kMaxSpp));
  if (doc.contains("check_bound")) spec.check_bound = r.real(doc["check_bound"], top / "check_bound", 0.0, 1e30);

  const fs::path folder = fs::path(path).parent_path();
  const JsonPath groups_path = top / "groups";
  const json& groups = r.array(r.required(doc, top, "groups"), groups_path);
  std::vector<std::string> config_keys;
  for (SettingId id : scene_settings()) config_keys.push_back(setting(id).key);
  for (size_t g = 0; g < groups.size(); ++g) {
    const JsonPath gp = groups_path / g;
    r.check_keys(groups[g], gp, {"name", "scene", "kernels", "configs"});
    const std::string& name = r.string(r.required(groups[g], gp, "name"), gp / "name");
    const std::string scene =
        (folder / r.string(r.required(groups[g], gp, "scene"), gp / "scene")).lexically_normal().string();
    const JsonPath kp = gp / "kernels";
    const json& kernel_list = r.array(r.required(groups[g], gp, "kernels"), kp);
    if (kernel_list.empty()) r.fail_at(kp, "must name at least one kernel");
    std::vector<std::string> kernels;
    for (size_t k = 0; k < kernel_list.size(); ++k) kernels.push_back(kernel_names()[r.choice(kernel_list[k], kp / k, kernel_names())]);
    const JsonPath cp = gp / "configs";
    const json& configs = r.array(r.required(groups[g], gp, "configs"), cp);
    for (size_t c = 0; c < configs.size(); ++c) {
      const JsonPath at = cp / c;
      r.check_keys(configs[c], at, config_keys);
      BenchPoint p{name, scene, RenderDefaults(), kernels};
      p.params.roulette_depth = -1;  // none given: equal to depth (no roulette)
      for (SettingId id : render_settings()) {
        const Setting& s = setting(id);
        const bool needed = id == SettingId::Width || id == SettingId::Height || id == SettingId::Spp ||
                            id == SettingId::Depth;
        if (needed || configs[c].contains(s.key)) {
          set_param(p.params, id, r.integer(needed ? r.required(configs[c], at, s.key) : configs[c][s.key],
                                            at / s.key, s.lo, s.hi));
        }
      }
      if (p.params.roulette_depth < 0) p.params.roulette_depth = p.params.depth;
      const char* threshold = setting(SettingId::NoiseThreshold).key;
      const char* min_spp = setting(SettingId::MinSpp).key;
      if (configs[c].contains(threshold)) {
        p.noise_threshold = r.real_setting(configs[c][threshold], at / threshold, SettingId::NoiseThreshold);
      }
      if (configs[c].contains(min_spp)) {
        if (p.noise_threshold == 0) r.fail_at(at / min_spp, "adaptive sampling's first samples: give noise_threshold too");
        p.min_spp = static_cast<int32_t>(r.integer_setting(configs[c][min_spp], at / min_spp, SettingId::MinSpp));
        if (p.min_spp > p.params.spp) r.fail_at(at / min_spp, "more than the config's spp");
      }
      try {
        validate_params(p.params);
      } catch (const InputError& e) {
        r.fail_at(at, e.what());
      }
      if (only.empty() || name == only) spec.points.push_back(p);
    }
  }
  if (spec.points.empty()) throw InputError(path + ": no points to run" + (only.empty() ? "" : " in group " + only));
  return spec;
}

namespace {

double mean_abs_diff(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += std::fabs(static_cast<double>(a[i]) - b[i]);
  return a.empty() ? 0 : s / a.size();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

json device_json(Backend backend) {
  json d;
  if (backend == Backend::Cuda) {
    cuda::DeviceInfo info = cuda::device_info();
    d = {{"name", info.name},
         {"sm_count", info.sm_count},
         {"sm_clock_mhz", info.sm_clock_khz / 1000},
         {"memory_clock_mhz", info.memory_clock_khz / 1000},
         {"driver_version", info.driver_version},
         {"runtime_version", info.runtime_version},
         {"memory_gib", info.total_memory / double(1 << 30)}};
  } else {
    d = {{"name", "CPU"}};
  }
  return d;
}

std::string utc_now() {
  std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

// What the results say of the run as a whole.
json results_header(const BenchOptions& options, const BenchSpec& spec, Backend backend) {
  json results;
  results["date"] = utc_now();
  results["commit"] = options.commit;
  results["build_flags"] = kBuildFlags;
  results["backend"] = backend_name(backend);
  results["device"] = device_json(backend);
  results["warmup"] = spec.warmup;
  results["repeats"] = spec.repeats;
  results["check"] = {{"spp", spec.check_spp}, {"max_mean_abs_diff", spec.check_bound}, {"against", "megakernel"}};
  results["kernels"] = kernel_names();
  results["points"] = json::array();
  return results;
}

// The timed runs of one kernel at one point, into its row: their seconds, and the
// counts and stage times of the run whose time is the median.
void time_kernel(const Scene& scene, RenderOptions o, const BenchSpec& spec, json& row,
                 std::vector<std::string>& stages, double diff) {
  std::vector<double> seconds;
  std::vector<RenderResult> runs;
  for (int r = 0; r < spec.repeats; ++r) {
    o.warmup = r == 0 ? spec.warmup : 0;
    runs.push_back(render(scene, o));
    runs.back().rgb.clear();
    seconds.push_back(runs.back().seconds);
    std::fprintf(stderr, "    run %d/%d: %.3f s\n", r + 1, spec.repeats, seconds.back());
  }
  std::vector<size_t> order(runs.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return seconds[a] < seconds[b]; });
  const RenderResult& kept = runs[order[order.size() / 2]];
  const double med = median(seconds);
  row["status"] = "ok";
  row["seconds"] = seconds;
  row["seconds_median"] = med;
  row["seconds_min"] = *std::min_element(seconds.begin(), seconds.end());
  row["seconds_max"] = *std::max_element(seconds.begin(), seconds.end());
  add_measurements(row, kept, med, scene.load_times);
  if (o.noise_threshold > 0) {
    // The timed run's adaptive sampling: what it took and how far it converged.
    row["noise_threshold"] = o.noise_threshold;
    row["min_spp"] = resolved_min_spp(o.min_spp, o.params.spp);
    row["mean_spp"] = mean_spp(kept);
    row["converged_pixels"] = kept.converged;
  }
  row["geometry"] = geometry_json(scene.summary());
  for (const StageTime& st : kept.stages) {
    if (std::find(stages.begin(), stages.end(), st.name) == stages.end()) stages.push_back(st.name);
  }
  std::fprintf(stderr, "    median %.3f s, %.1f M rays/s, %.1f M paths/s, check diff %.2e\n", med,
               kept.rays / med / 1e6, kept.paths / med / 1e6, diff);
}

// One kernel at one point: checked against the megakernel's image at the check's
// samples (a kernel that renders another image is not timed), then timed. False
// where it failed.
bool bench_kernel(const Scene& scene, const BenchPoint& p, const std::string& kname, const RenderOptions& check,
                  const RenderResult& reference, const BenchSpec& spec, json& row, std::vector<std::string>& stages) {
  try {
    RenderOptions o;
    o.backend = check.backend;
    o.kernel = parse_kernel(kname);
    o.params = check.params;
    const RenderResult probe = render(scene, o);
    const double diff = mean_abs_diff(reference.rgb, probe.rgb);
    const bool passed = diff <= spec.check_bound;
    row["check"] = {{"mean_abs_diff", diff}, {"passed", passed}, {"rays", probe.rays},
                    {"reference_rays", reference.rays}};
    if (!passed) {
      row["status"] = "image differs from the megakernel's";
      return false;
    }
    o.params = p.params;
    o.noise_threshold = p.noise_threshold;
    o.min_spp = p.min_spp;
    time_kernel(scene, o, spec, row, stages, diff);
    return true;
  } catch (const std::exception& e) {
    row["status"] = std::string("error: ") + e.what();
    std::fprintf(stderr, "    %s\n", e.what());
    return false;
  }
}

// results.csv: a line a row.
std::string results_csv(const json& results) {
  std::ostringstream csv;
  csv << "group,scene,width,height,spp,depth,kernel,status,seconds_median,seconds_min,seconds_max,rays,paths,"
         "m_rays_per_s,m_paths_per_s,rays_per_path,check_mean_abs_diff,shadow_rays,noise_threshold,mean_spp\n";
  for (const json& r : results["points"]) {
    csv << r["group"].get<std::string>() << "," << fs::path(r["scene"].get<std::string>()).filename().string() << ","
        << r["width"] << "," << r["height"] << "," << r["spp"] << "," << r["depth"] << ","
        << r["kernel"].get<std::string>() << "," << r["status"].get<std::string>().substr(0, 40) << ","
        << r.value("seconds_median", 0.0) << "," << r.value("seconds_min", 0.0) << "," << r.value("seconds_max", 0.0)
        << "," << r.value("rays", uint64_t(0)) << "," << r.value("paths", uint64_t(0)) << ","
        << r.value("m_rays_per_s", 0.0) << "," << r.value("m_paths_per_s", 0.0) << ","
        << r.value("rays_per_path", 0.0) << ","
        << (r.contains("check") ? r["check"]["mean_abs_diff"].get<double>() : -1.0) << ","
        << r.value("shadow_rays", uint64_t(0)) << "," << r.value("noise_threshold", 0.0) << ","
        << r.value("mean_spp", 0.0) << "\n";
  }
  return csv.str();
}

}  // namespace

int run_bench(const BenchOptions& options) {
  BenchSpec spec = read_bench_spec(options.spec, options.only);
  if (options.repeats > 0) spec.repeats = options.repeats;
  const Backend backend = parse_backend(options.backend);
  std::error_code ec;
  fs::create_directories(options.out_dir, ec);
  check_output_folder((fs::path(options.out_dir) / "results.json").string());

  json results = results_header(options, spec, backend);
  std::vector<std::string> stages;  // the wavefront's stages, in the order they run
  size_t total = 0, done = 0;
  for (const BenchPoint& p : spec.points) total += p.kernels.size();
  int failures = 0;
  for (const BenchPoint& p : spec.points) {
    Scene scene = load_scene(p.scene);
    // The reference image for the check: the megakernel at the check's sample count.
    RenderOptions check;
    check.backend = backend;
    check.params = p.params;
    check.params.spp = std::min(p.params.spp, spec.check_spp);
    check.kernel = Kernel::Megakernel;
    const RenderResult reference = render(scene, check);
    for (const std::string& kname : p.kernels) {
      ++done;
      json row = settings_json(p.params);
      row["group"] = p.group;
      row["scene"] = p.scene;
      row["kernel"] = kname;
      if (p.noise_threshold > 0) row["noise_threshold"] = p.noise_threshold;
      std::fprintf(stderr, "[%zu/%zu] %s %s %dx%d %d spp depth %d %s%s\n", done, total, p.group.c_str(),
                   fs::path(p.scene).filename().c_str(), p.params.width, p.params.height, p.params.spp,
                   p.params.depth, kname.c_str(), p.noise_threshold > 0 ? " adaptive" : "");
      if (!bench_kernel(scene, p, kname, check, reference, spec, row, stages)) ++failures;
      results["points"].push_back(row);
    }
  }
  results["stages"] = stages;
  write_file((fs::path(options.out_dir) / "results.json").string(), results.dump(1) + "\n");
  write_file((fs::path(options.out_dir) / "results.csv").string(), results_csv(results));
  std::fprintf(stderr, "bench: %zu points, %d failed; results in %s\n", total, failures, options.out_dir.c_str());
  return failures ? kExitFailure : 0;
}

}  // namespace wt::app

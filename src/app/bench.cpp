#include "app/bench.hpp"

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
#include "build_info.hpp"
#include "cuda/device.hpp"


namespace wt::app {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct Point {
  std::string group, scene;
  RenderParams params{};
  std::vector<std::string> kernels;
};

struct Spec {
  int warmup = 1, repeats = 3, check_spp = 2;
  double check_bound = 3e-3;
  std::vector<Point> points;
};

template <class T>
T field(const json& j, const char* key, const std::string& where) {
  if (!j.contains(key)) throw SceneError(where + "/" + key + ": missing");
  try {
    return j.at(key).get<T>();
  } catch (const json::exception&) {
    throw SceneError(where + "/" + key + ": wrong type");
  }
}

Spec read_spec(const std::string& path, const std::string& only) {
  std::ifstream f(path);
  if (!f) throw SceneError(path + ": cannot open bench spec");
  json doc = json::parse(f, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) throw SceneError(path + ": malformed JSON");
  Spec spec;
  spec.warmup = doc.value("warmup", spec.warmup);
  spec.repeats = doc.value("repeats", spec.repeats);
  spec.check_spp = doc.value("check_spp", spec.check_spp);
  spec.check_bound = doc.value("check_bound", spec.check_bound);
  const fs::path folder = fs::path(path).parent_path();
  const json groups = doc.value("groups", json::array());
  for (size_t g = 0; g < groups.size(); ++g) {
    const std::string where = path + ": /groups/" + std::to_string(g);
    const std::string name = field<std::string>(groups[g], "name", where);
    if (!only.empty() && name != only) continue;
    const std::string scene = (folder / field<std::string>(groups[g], "scene", where)).lexically_normal().string();
    const auto kernels = field<std::vector<std::string>>(groups[g], "kernels", where);
    for (const std::string& k : kernels) parse_kernel(k);
    const json configs = field<json>(groups[g], "configs", where);
    for (const json& c : configs) {
      Point p{name, scene, {}, kernels};
      p.params.width = field<int>(c, "width", where);
      p.params.height = field<int>(c, "height", where);
      p.params.spp = field<int>(c, "spp", where);
      p.params.depth = field<int>(c, "depth", where);
      p.params.roulette_depth = c.value("roulette_depth", p.params.depth);
      p.params.seed = c.value("seed", 1u);
      validate_params(p.params);
      spec.points.push_back(p);
    }
  }
  if (spec.points.empty()) throw SceneError(path + ": no points to run" + (only.empty() ? "" : " in group " + only));
  return spec;
}

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

}  // namespace

int run_bench(const BenchOptions& options) {
  Spec spec = read_spec(options.spec, options.only);
  if (options.repeats > 0) spec.repeats = options.repeats;
  const Backend backend = parse_backend(options.backend);
  std::error_code ec;
  fs::create_directories(options.out_dir, ec);
  check_output_folder((fs::path(options.out_dir) / "results.json").string());

  json results;
  results["date"] = utc_now();
  results["commit"] = options.commit;
  results["build_flags"] = kBuildFlags;
  results["backend"] = backend_name(backend);
  results["device"] = device_json(backend);
  results["warmup"] = spec.warmup;
  results["repeats"] = spec.repeats;
  results["check"] = {{"spp", spec.check_spp}, {"max_mean_abs_diff", spec.check_bound}, {"against", "megakernel"}};
  results["points"] = json::array();

  size_t total = 0, done = 0;
  for (const Point& p : spec.points) total += p.kernels.size();
  int failures = 0;
  for (const Point& p : spec.points) {
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
      json row = {{"group", p.group},         {"scene", p.scene},       {"width", p.params.width},
                  {"height", p.params.height}, {"spp", p.params.spp},    {"depth", p.params.depth},
                  {"roulette_depth", p.params.roulette_depth},           {"kernel", kname}};
      std::fprintf(stderr, "[%zu/%zu] %s %s %dx%d %d spp depth %d %s\n", done, total, p.group.c_str(),
                   fs::path(p.scene).filename().c_str(), p.params.width, p.params.height, p.params.spp,
                   p.params.depth, kname.c_str());
      try {
        RenderOptions o;
        o.backend = backend;
        o.kernel = parse_kernel(kname);
        o.params = check.params;
        RenderResult probe = render(scene, o);
        double diff = mean_abs_diff(reference.rgb, probe.rgb);
        bool passed = diff <= spec.check_bound;
        row["check"] = {{"mean_abs_diff", diff}, {"passed", passed}, {"rays", probe.rays},
                        {"reference_rays", reference.rays}};
        if (!passed) {
          ++failures;
          row["status"] = "image differs from the megakernel's";
          results["points"].push_back(row);
          continue;
        }
        o.params = p.params;
        std::vector<double> seconds;
        std::vector<RenderResult> runs;
        for (int r = 0; r < spec.repeats; ++r) {
          o.warmup = r == 0 ? spec.warmup : 0;
          runs.push_back(render(scene, o));
          runs.back().rgb.clear();
          seconds.push_back(runs.back().seconds);
          std::fprintf(stderr, "    run %d/%d: %.3f s\n", r + 1, spec.repeats, seconds.back());
        }
        // Counts and stage times come from the run whose time is the median.
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
        row["upload_seconds"] = kept.upload_seconds;
        row["rays"] = kept.rays;
        row["paths"] = kept.paths;
        row["rays_per_path"] = static_cast<double>(kept.rays) / kept.paths;
        row["m_rays_per_s"] = kept.rays / med / 1e6;
        row["m_paths_per_s"] = kept.paths / med / 1e6;
        if (!kept.stages.empty()) {
          json stages = json::object();
          for (const StageTime& s : kept.stages) stages[s.name] = s.ms;
          row["stage_ms"] = stages;
          row["live_per_bounce"] = kept.live_per_bounce;
        }
        std::fprintf(stderr, "    median %.3f s, %.1f M rays/s, %.1f M paths/s, check diff %.2e\n", med,
                     kept.rays / med / 1e6, kept.paths / med / 1e6, diff);
      } catch (const std::exception& e) {
        ++failures;
        row["status"] = std::string("error: ") + e.what();
        std::fprintf(stderr, "    %s\n", e.what());
      }
      results["points"].push_back(row);
    }
  }

  std::ostringstream csv;
  csv << "group,scene,width,height,spp,depth,kernel,status,seconds_median,seconds_min,seconds_max,rays,paths,"
         "m_rays_per_s,m_paths_per_s,rays_per_path,check_mean_abs_diff\n";
  for (const json& r : results["points"]) {
    csv << r["group"].get<std::string>() << "," << fs::path(r["scene"].get<std::string>()).filename().string() << ","
        << r["width"] << "," << r["height"] << "," << r["spp"] << "," << r["depth"] << ","
        << r["kernel"].get<std::string>() << "," << r["status"].get<std::string>().substr(0, 40) << ","
        << r.value("seconds_median", 0.0) << "," << r.value("seconds_min", 0.0) << "," << r.value("seconds_max", 0.0)
        << "," << r.value("rays", uint64_t(0)) << "," << r.value("paths", uint64_t(0)) << ","
        << r.value("m_rays_per_s", 0.0) << "," << r.value("m_paths_per_s", 0.0) << ","
        << r.value("rays_per_path", 0.0) << ","
        << (r.contains("check") ? r["check"]["mean_abs_diff"].get<double>() : -1.0) << "\n";
  }
  write_text_file((fs::path(options.out_dir) / "results.json").string(), results.dump(1) + "\n");
  write_text_file((fs::path(options.out_dir) / "results.csv").string(), csv.str());
  std::fprintf(stderr, "bench: %zu points, %d failed; results in %s\n", total, failures, options.out_dir.c_str());
  return failures ? kExitFailure : 0;
}

}  // namespace wt::app

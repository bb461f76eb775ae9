#include "app/stats.hpp"

#include <filesystem>

namespace wt::app {

void check_output_path_for_text(const std::string& path) {
  if (std::filesystem::path(path).extension() != ".json") {
    throw OutputError(path + ": stats files are JSON; name it *.json");
  }
  check_output_folder(path);
}

nlohmann::json stats_json(const Job& job, const JobOutcome& o) {
  const RenderResult& r = o.result;
  nlohmann::json j;
  j["scene"] = job.scene;
  j["output"] = job.output;
  j["settings"] = {{"width", o.params.width},   {"height", o.params.height},
                   {"spp", o.params.spp},       {"depth", o.params.depth},
                   {"roulette_depth", o.params.roulette_depth}, {"seed", o.params.seed},
                   {"warmup", job.warmup},      {"wave_size", job.wave_size}};
  j["backend"] = o.backend;
  j["kernel"] = o.kernel;
  j["device"] = r.device;
  j["rays"] = r.rays;
  j["paths"] = r.paths;
  j["seconds"] = r.seconds;
  j["timer"] = o.backend == "cuda" ? "cuda events" : "wall clock";
  j["upload_seconds"] = r.upload_seconds;
  j["m_rays_per_s"] = r.seconds > 0 ? r.rays / r.seconds / 1e6 : 0.0;
  j["m_paths_per_s"] = r.seconds > 0 ? r.paths / r.seconds / 1e6 : 0.0;
  j["rays_per_path"] = r.paths ? static_cast<double>(r.rays) / r.paths : 0.0;
  if (!r.stages.empty()) {
    nlohmann::json stages = nlohmann::json::object();
    for (const StageTime& s : r.stages) stages[s.name] = s.ms;
    j["stage_ms"] = stages;
    j["live_per_bounce"] = r.live_per_bounce;
  }
  return j;
}

}  // namespace wt::app

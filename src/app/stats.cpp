#include "app/stats.hpp"

#include <filesystem>

#include "app/job_files.hpp"
#include "render/adaptive.hpp"
#include "errors/errors.hpp"

namespace wt::app {

void check_output_path_for_text(const std::string& path) {
  if (std::filesystem::path(path).extension() != ".json") {
    throw OutputError(path + ": stats files are JSON; name it *.json");
  }
  check_output_folder(path);
}

nlohmann::json settings_json(const RenderParams& params) {
  nlohmann::json j = nlohmann::json::object();
  for (SettingId id : render_settings()) j[setting(id).key] = get_param(params, id);
  return j;
}

namespace {
nlohmann::json bvh_json(const BvhStats& b) {
  return {{"nodes", b.nodes}, {"leaves", b.leaves}, {"depth", b.depth}, {"sah_cost", b.sah_cost}};
}
}  // namespace

nlohmann::json geometry_json(const Scene::Summary& g) {
  nlohmann::json j = {{"spheres", g.spheres},
                      {"triangles", g.triangles},
                      {"instanced_triangles", g.instanced_triangles},
                      {"instances", g.instances},
                      {"dropped_degenerate", g.dropped_degenerate},
                      {"dropped_nan", g.dropped_nan},
                      {"bvh_nodes", g.bvh_nodes},
                      {"device_bytes", g.device_bytes},
                      {"top_level_bvh", bvh_json(g.top_level_bvh)}};
  if (g.spheres) j["sphere_bvh"] = bvh_json(g.sphere_bvh);
  nlohmann::json meshes = nlohmann::json::array();
  size_t warnings = 0;  // over the meshes
  for (const auto& m : g.meshes) {
    meshes.push_back({{"name", m.name},
                      {"file", m.file},
                      {"triangles", m.triangle_count},
                      {"dropped_degenerate", m.dropped_degenerate},
                      {"dropped_nan", m.dropped_nan},
                      {"warnings", m.warnings},
                      {"bvh", bvh_json(m.bvh)}});
    warnings += m.warnings.size();
  }
  j["meshes"] = meshes;
  j["warnings"] = warnings;
  return j;
}

nlohmann::json share_json(const DeviceShare& s) {
  return {{"device", s.device}, {"name", s.name},         {"samples", s.samples},        {"chunks", s.chunks},
          {"paths", s.paths},     {"seconds", s.seconds}, {"rays", s.rays}, {"shadow_rays", s.shadow_rays}};
}

DeviceShare share_of(const nlohmann::json& j) {
  DeviceShare s;
  s.device = j.value("device", "");
  s.name = j.value("name", "");
  s.samples = j.value("samples", 0);
  s.chunks = j.value("chunks", 0);
  s.paths = j.value("paths", uint64_t(0));
  s.seconds = j.value("seconds", 0.0);
  s.rays = j.value("rays", uint64_t(0));
  s.shadow_rays = j.value("shadow_rays", uint64_t(0));
  return s;
}

void add_measurements(nlohmann::json& j, const RenderResult& r, double seconds, const LoadTimes& load) {
  j["rays"] = r.rays;
  j["shadow_rays"] = r.shadow_rays;  // light sampling's, not in `rays`
  j["paths"] = r.paths;
  j["upload_seconds"] = r.upload_seconds;
  j["load_seconds"] = {{"parse", load.parse},
                       {"validate", load.validate},
                       {"texture_load", load.texture_load},
                       {"mesh_load", load.mesh_load},
                       {"bvh_build", load.bvh_build},
                       {"upload", r.upload_seconds}};
  j["m_rays_per_s"] = seconds > 0 ? r.rays / seconds / 1e6 : 0.0;
  j["m_paths_per_s"] = seconds > 0 ? r.paths / seconds / 1e6 : 0.0;
  j["m_shadow_rays_per_s"] = seconds > 0 ? r.shadow_rays / seconds / 1e6 : 0.0;
  j["rays_per_path"] = r.paths ? static_cast<double>(r.rays) / r.paths : 0.0;
  if (!r.shares.empty()) {
    nlohmann::json devices = nlohmann::json::array();
    for (const DeviceShare& s : r.shares) devices.push_back(share_json(s));
    j["devices"] = devices;
  }
  if (!r.stages.empty()) {
    nlohmann::json stages = nlohmann::json::object();
    for (const StageTime& s : r.stages) stages[s.name] = s.ms;
    j["stage_ms"] = stages;
    j["live_per_bounce"] = r.live_per_bounce;
    j["bounces_shaded"] = r.bounces_shaded;
    j["bounces_sorted"] = r.bounces_sorted;
  }
}

nlohmann::json stats_json(const Job& job, const JobOutcome& o) {
  const RenderResult& r = o.result;
  nlohmann::json j;
  j["scene"] = job.scene;
  j["output"] = job.output;
  j["settings"] = settings_json(o.params);
  j["settings"][setting(SettingId::Warmup).key] = job.warmup;
  j["settings"][setting(SettingId::WaveSize).key] = job.wave_size;
  j["settings"][setting(SettingId::MegakernelBatch).key] = job.megakernel_batch;
  j["settings"][setting(SettingId::MinSpp).key] = o.min_spp > 0 ? o.min_spp : job.min_spp;
  if (o.noise_threshold > 0) {
    // Adaptive sampling (the job's or the scene's): its threshold, and how it ended.
    const RenderResult& a = o.result;
    j["settings"][setting(SettingId::NoiseThreshold).key] = o.noise_threshold;
    j["adaptive"] = {{"noise_threshold", o.noise_threshold},
                     {"min_spp", o.min_spp},
                     {"converged_pixels", a.converged},
                     {"pixels", a.pixel_samples.size()},
                     {"mean_spp", mean_spp(a)},
                     {"max_spp", a.samples}};
  }
  j["backend"] = o.backend;
  j["kernel"] = o.kernel;
  j["device"] = r.device;
  j["seconds"] = r.seconds;
  j["nonfinite_pixels"] = o.nonfinite_pixels;
  if (o.resumed_from_sample > 0) j["resumed_from_sample"] = o.resumed_from_sample;
  if (o.ranks > 1) {
    j["ranks"] = o.ranks;
    j["wall_seconds"] = o.wall_seconds;
  }
  j["timer"] = o.backend == "cuda" ? "cuda events" : "wall clock";
  j["job_seconds"] = o.job_seconds;
  j["write_seconds"] = o.write_seconds;
  if (job.denoise) {
    j["denoise"] = {{"quality", job.denoise_quality}, {"device", o.denoise_device}, {"seconds", o.denoise_seconds}};
    if (job.keep_noisy) j["noisy_output"] = noisy_output(job);
  }
  if (!job.aov.empty() || job.denoise) {
    // The first-surface pass: the AOVs asked for and the denoiser's guides.
    nlohmann::json aovs = {{"seconds", o.aovs.seconds}, {"samples", o.aovs.samples}, {"names", nlohmann::json::array()}};
    for (AovKind k : job_aovs(job)) aovs["names"].push_back(aov_name(k));
    const std::vector<JobFile> files = aov_outputs(job);
    if (!files.empty()) {
      aovs["files"] = nlohmann::json::array();
      for (const JobFile& f : files) aovs["files"].push_back(f.path);
    } else if (!job.aov.empty()) {
      aovs["layers_of"] = job.output;
    }
    j["aovs"] = aovs;
  }
  add_measurements(j, r, r.seconds, o.load_times);
  j["geometry"] = geometry_json(o.geometry);
  // A Mitsuba scene's mapping: what it renders otherwise than Mitsuba would.
  j["scene_warnings"] = o.scene_warnings;
  return j;
}

}  // namespace wt::app

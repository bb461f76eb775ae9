// The statistics of a render, one writer for `render --stats` and bench's rows:
// what was rendered, and how fast.
#pragma once

#include <nlohmann/json.hpp>

#include "app/job.hpp"

namespace wt::app {

// The render settings by their keys in the settings table.
nlohmann::json settings_json(const RenderParams& params);

// Adds what a render measured to `j`: counts, rates over `seconds` (the render's
// time, or a median of several), upload and load phase times, and for the wavefront
// the stage times and live paths per bounce.
void add_measurements(nlohmann::json& j, const RenderResult& r, double seconds, const LoadTimes& load);

// What one device did in a split render, as the stats' "devices" list holds it (and
// as the ranks of an MPI run send it to rank 0), and back.
nlohmann::json share_json(const DeviceShare& share);
DeviceShare share_of(const nlohmann::json& j);

// The scene's geometry: counts, dropped triangles, BVH shapes and costs.
nlohmann::json geometry_json(const Scene::Summary& geometry);

// The --stats file of one job.
nlohmann::json stats_json(const Job& job, const JobOutcome& outcome);

// Like check_output_path, for a JSON file.
void check_output_path_for_text(const std::string& path);

}  // namespace wt::app

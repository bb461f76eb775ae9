// The --stats file: what was rendered, where, and how fast.
#pragma once

#include <nlohmann/json.hpp>

#include "app/job.hpp"

namespace wt::app {

nlohmann::json stats_json(const Job& job, const JobOutcome& outcome);

// Like check_output_path, for a JSON file.
void check_output_path_for_text(const std::string& path);

}  // namespace wt::app

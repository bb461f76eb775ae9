#include "app/batch_ranks.hpp"

#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "app/batch.hpp"
#include "app/cli.hpp"
#include "app/job_processes.hpp"

namespace wt::app {

using nlohmann::json;

void serve_ranks(const Cluster& cluster, BatchRun& batch, size_t remote_lanes) {
  while (remote_lanes > 0) {
    const ClusterMessage m = cluster.receive_any();
    const json said = json::parse(m.text);
    if (said.contains("index")) batch.record(said["index"].get<size_t>(), outcome_of(said));
    const std::string where = "rank " + std::to_string(m.from) + " (" + said.value("host", "") + ")" +
                              (said.value("devices", "").empty() ? "" : " cuda " + said.value("devices", ""));
    std::optional<size_t> i;
    while ((i = batch.take(where)) && batch.settle(*i)) {
    }
    if (!i) {
      cluster.send(m.from, m.tag, "");
      --remote_lanes;
    } else {
      cluster.send(m.from, m.tag, json{{"index", *i}, {"args", render_arguments(batch.job(*i))}}.dump());
    }
  }
}

void rank_lane(const Cluster& cluster, int tag, const std::string& devices, bool quiet, const JobRunner& run,
               const LaneDone& done) {
  json said = {{"host", cluster.host()}, {"devices", devices}};
  for (;;) {
    cluster.send(0, tag, said.dump());
    const std::string answer = cluster.receive(0, tag);
    if (answer.empty()) {
      done(static_cast<size_t>(tag));
      return;
    }
    const json given = json::parse(answer);
    const size_t index = given["index"].get<size_t>();
    JobOutcome o;
    try {
      const Job job = parse_render_arguments(given["args"].get<std::vector<std::string>>());
      o = run(static_cast<size_t>(tag), index, lane_job(job, devices, quiet));
    } catch (const std::exception& e) {
      o.exit_code = kExitFailure;
      o.message = std::string("rank ") + std::to_string(cluster.rank()) + " could not take the job: " + e.what();
    }
    said = outcome_json(index, o);
    said["host"] = cluster.host();
    said["devices"] = devices;
  }
}

void release_ranks(const Cluster& cluster) {
  const std::vector<std::string> counts = cluster.gather("0");
  size_t remote_lanes = 0;
  for (size_t r = 1; r < counts.size(); ++r) remote_lanes += std::stoul(counts[r]);
  const std::vector<PlannedJob> none;
  BatchRun batch(none, false, nullptr);
  serve_ranks(cluster, batch, remote_lanes);
}

}  // namespace wt::app

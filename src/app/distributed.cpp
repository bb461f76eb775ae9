#include "app/distributed.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <map>
#include <optional>
#include <nlohmann/json.hpp>

#include "app/stats.hpp"
#include "dispatch/split.hpp"

namespace wt::app {

using nlohmann::json;

std::vector<SamplePass> rank_samples(int32_t first, int32_t count, const std::vector<double>& weights) {
  return weighted_ranges(first, count, weights);
}

std::vector<int> local_share(const std::vector<int>& devices, int local_rank, int local_ranks) {
  if (devices.empty() || local_ranks <= 1) return devices;
  if (static_cast<int>(devices.size()) <= local_ranks) {
    return {devices[static_cast<size_t>(local_rank) % devices.size()]};
  }
  std::vector<int> mine;
  for (size_t i = static_cast<size_t>(local_rank); i < devices.size(); i += static_cast<size_t>(local_ranks)) {
    mine.push_back(devices[i]);
  }
  return mine;
}

std::string describe_failures(const std::vector<RankStatus>& failed, int ranks) {
  // Clauses in the order of their first rank; ranks with the same message share one.
  std::vector<std::string> order;
  std::map<std::string, std::vector<const RankStatus*>> by_message;
  for (const RankStatus& s : failed) {
    if (!by_message.count(s.message)) order.push_back(s.message);
    by_message[s.message].push_back(&s);
  }
  std::string line;
  for (const std::string& message : order) {
    const std::vector<const RankStatus*>& list = by_message[message];
    std::string who = list.size() == 1 ? "rank " : "ranks ";
    std::vector<std::string> hosts;
    for (size_t i = 0; i < list.size(); ++i) {
      who += (i ? ", " : "") + std::to_string(list[i]->rank);
      if (std::find(hosts.begin(), hosts.end(), list[i]->host) == hosts.end()) hosts.push_back(list[i]->host);
    }
    std::string named;
    for (const std::string& h : hosts) named += (named.empty() ? "" : ", ") + h;
    line += (line.empty() ? "" : "; ") + who + " of " + std::to_string(ranks) +
            (named.empty() ? "" : " (" + named + ")") + ": " + message;
  }
  return line;
}

namespace {

json status_of(const Cluster& cluster, const JobOutcome& out) {
  return json{{"host", cluster.host()}, {"exit_code", out.exit_code}, {"message", out.message}};
}

RankStatus rank_status(int rank, const json& j) {
  return RankStatus{rank, j.value("host", ""), j.value("exit_code", 1), j.value("message", "")};
}

// Rank 0's verdict on the gathered statuses: the failed ranks' line, or "" if none.
std::pair<int, std::string> verdict(const Cluster& cluster, const std::vector<json>& statuses) {
  std::vector<RankStatus> failed;
  for (size_t r = 0; r < statuses.size(); ++r) {
    RankStatus s = rank_status(static_cast<int>(r), statuses[r]);
    if (s.exit_code != 0) failed.push_back(s);
  }
  if (failed.empty()) return {0, ""};
  return {failed.front().exit_code, describe_failures(failed, cluster.ranks())};
}

// Every rank takes rank 0's decision: none (and `out` failed) where it says so.
std::optional<json> take_decision(const Cluster& cluster, JobOutcome& out, const json& decision) {
  json d = json::parse(cluster.broadcast(cluster.root() ? decision.dump() : std::string()));
  if (d.value("exit_code", 0) == 0) return d;
  out.exit_code = d.value("exit_code", 1);
  out.message = d.value("message", "");
  return std::nullopt;
}

}  // namespace

bool agree_on_samples(const Cluster& cluster, JobOutcome& out, RenderOptions& options, const std::string& signature,
                      double weight, std::vector<double>* weights_out) {
  json mine = status_of(cluster, out);
  mine["signature"] = signature;
  mine["weight"] = weight;
  json decision;
  if (cluster.root()) {
    std::vector<json> statuses;
    for (const std::string& s : cluster.gather(mine.dump())) statuses.push_back(json::parse(s));
    auto [code, line] = verdict(cluster, statuses);
    if (code == 0) {
      // Every rank renders the same: its settings, kernel and scene as rank 0's.
      std::vector<RankStatus> differing;
      const std::string& ours = statuses[0]["signature"].get_ref<const std::string&>();
      for (size_t r = 1; r < statuses.size(); ++r) {
        const std::string theirs = statuses[r].value("signature", "");
        if (theirs != ours) {
          differing.push_back(RankStatus{static_cast<int>(r), statuses[r].value("host", ""), kExitBadInput,
                                         "renders " + theirs + ", rank 0 " + ours});
        }
      }
      if (!differing.empty()) {
        code = kExitBadInput;
        line = describe_failures(differing, cluster.ranks());
      }
    }
    decision = {{"exit_code", code}, {"message", line}};
    if (code == 0) {
      std::vector<double> weights;
      for (const json& s : statuses) weights.push_back(std::max(1.0, s.value("weight", 1.0)));
      const RenderParams& rp = options.params;
      json ranges = json::array();
      for (const SamplePass& p : rank_samples(options.first_sample, rp.spp - options.first_sample, weights)) {
        ranges.push_back({p.first, p.count});
      }
      decision["ranges"] = ranges;
      decision["weights"] = weights;
    }
  } else {
    cluster.gather(mine.dump());
  }
  const std::optional<json> d = take_decision(cluster, out, decision);
  if (!d) return false;
  const json& range = (*d)["ranges"][static_cast<size_t>(cluster.rank())];
  options.first_sample = range[0].get<int32_t>();
  options.sample_count = range[1].get<int32_t>();
  if (weights_out) *weights_out = (*d)["weights"].get<std::vector<double>>();
  return true;
}

namespace {

// An adaptive render's messages from rank 0: a round ('R', its first sample and
// count, the pixels still going, none listed where every pixel is), or the end ('E').
template <class T>
void put(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

std::string round_message(const RenderOptions& o) {
  std::string m = "R";
  put<int32_t>(m, o.first_sample);
  put<int32_t>(m, o.sample_count);
  if (o.active_pixels) {
    m.append(reinterpret_cast<const char*>(o.active_pixels->data()), o.active_pixels->size() * sizeof(uint32_t));
  }
  return m;
}

struct Round {
  int32_t first = 0, count = 0;
  bool listed = false;
  std::vector<uint32_t> pixels;
};

Round read_round(const std::string& m) {
  Round r;
  std::memcpy(&r.first, m.data() + 1, sizeof r.first);
  std::memcpy(&r.count, m.data() + 1 + sizeof r.first, sizeof r.count);
  const size_t head = 1 + 2 * sizeof(int32_t);
  r.listed = m.size() > head;
  r.pixels.resize((m.size() - head) / sizeof(uint32_t));
  if (!r.pixels.empty()) std::memcpy(r.pixels.data(), m.data() + head, r.pixels.size() * sizeof(uint32_t));
  return r;
}

void add_counts(RenderResult& to, const RenderResult& r) {
  to.rays += r.rays;
  to.shadow_rays += r.shadow_rays;
  to.paths += r.paths;
  to.seconds += r.seconds;
  to.upload_seconds = std::max(to.upload_seconds, r.upload_seconds);
  if (!r.device.empty()) to.device = r.device;
}

}  // namespace

RenderResult render_adaptive_ranks(const Cluster& cluster, const ChunkRenderer& rounds, const RenderOptions& options,
                                   const std::vector<double>& weights, const AdaptiveHooks& hooks) {
  const RenderParams& rp = options.params;
  const size_t pixels = static_cast<size_t>(rp.width) * rp.height;
  std::exception_ptr failed;  // this rank's first error: it renders no more
  RenderResult mine;          // this rank's counts
  // This rank's run of a round's pixels rendered, the runs' sums added on rank 0.
  auto part = [&](int32_t first, int32_t count, const std::vector<uint32_t>* listed) {
    const size_t n = listed ? listed->size() : pixels;
    const std::vector<uint32_t> run =
        pixel_run(listed, weighted_ranges(0, static_cast<int32_t>(n), weights)[static_cast<size_t>(cluster.rank())]);
    RenderResult r;
    if (!failed && !run.empty()) {
      try {
        RenderOptions o = options;
        o.first_sample = first;
        o.sample_count = count;
        o.active_pixels = &run;
        o.progress = nullptr;
        o.warmup = 0;
        r = rounds(o);
        add_counts(mine, r);
      } catch (...) {
        failed = std::current_exception();
        r = RenderResult();
      }
    }
    if (r.rgb.size() != pixels * 3) r.rgb.assign(pixels * 3, 0.0f);
    cluster.sum_to_root(r.rgb);
    return r;
  };
  if (!cluster.root()) {
    for (std::string m = cluster.broadcast(""); !m.empty() && m[0] == 'R'; m = cluster.broadcast("")) {
      const Round round = read_round(m);
      part(round.first, round.count, round.listed ? &round.pixels : nullptr);
    }
    if (failed) std::rethrow_exception(failed);
    return mine;
  }
  RenderResult out;
  try {
    out = render_adaptive_rounds(
        [&](const RenderOptions& o) {
          cluster.broadcast(round_message(o));
          RenderResult r = part(o.first_sample, o.sample_count, o.active_pixels);
          if (failed) std::rethrow_exception(failed);
          return r;  // every rank's sums; rank 0's counts
        },
        options, hooks);
  } catch (...) {
    cluster.broadcast("E");
    throw;
  }
  cluster.broadcast("E");
  return out;
}

void combine_results(const Cluster& cluster, JobOutcome& out, bool adaptive) {
  const RenderResult& r = out.result;
  json mine = status_of(cluster, out);
  if (out.exit_code == 0) {
    // Its devices' shares; a rank that rendered on one device is one share, unnamed.
    json shares = json::array();
    for (const DeviceShare& s : r.shares) shares.push_back(share_json(s));
    if (r.shares.empty()) {
      DeviceShare one;
      one.name = r.device;
      one.samples = static_cast<int32_t>(r.paths / (static_cast<uint64_t>(out.params.width) * out.params.height));
      one.chunks = one.samples > 0 ? 1 : 0;
      one.paths = r.paths;
      one.seconds = r.seconds;
      one.rays = r.rays;
      one.shadow_rays = r.shadow_rays;
      shares.push_back(share_json(one));
    }
    mine["result"] = {{"rays", r.rays},       {"shadow_rays", r.shadow_rays},       {"paths", r.paths},
                      {"seconds", r.seconds}, {"upload_seconds", r.upload_seconds}, {"shares", shares}};
  }
  json decision;
  std::vector<json> statuses;
  if (cluster.root()) {
    for (const std::string& s : cluster.gather(mine.dump())) statuses.push_back(json::parse(s));
    auto [code, line] = verdict(cluster, statuses);
    decision = {{"exit_code", code}, {"message", line}};
  } else {
    cluster.gather(mine.dump());
  }
  if (!take_decision(cluster, out, decision)) return;
  if (!adaptive) cluster.sum_to_root(out.result.rgb);
  if (!cluster.root()) return;
  // The whole render, as rank 0 reports it: every rank's counts, and its devices.
  RenderResult whole;
  if (adaptive) {
    // Rank 0's image is the whole render's already (with its counts, samples and
    // variance); its counts give way to every rank's.
    whole = std::move(out.result);
    whole.rays = whole.shadow_rays = whole.paths = 0;
    whole.seconds = whole.upload_seconds = 0;
    whole.shares.clear();
  } else {
    whole.rgb = std::move(out.result.rgb);
    whole.radiance = Radiance::SumOfSamples;
    whole.samples = out.params.spp;
  }
  whole.device = std::to_string(cluster.ranks()) + " ranks";
  for (size_t rank = 0; rank < statuses.size(); ++rank) {
    const json& s = statuses[rank]["result"];
    const std::string who = "rank " + std::to_string(rank) + " (" + statuses[rank].value("host", "") + ")";
    whole.rays += s.value("rays", uint64_t(0));
    whole.shadow_rays += s.value("shadow_rays", uint64_t(0));
    whole.paths += s.value("paths", uint64_t(0));
    whole.seconds = std::max(whole.seconds, s.value("seconds", 0.0));
    whole.upload_seconds = std::max(whole.upload_seconds, s.value("upload_seconds", 0.0));
    for (const json& j : s["shares"]) {
      DeviceShare d = share_of(j);
      d.device = d.device.empty() ? who : who + " " + d.device;
      whole.shares.push_back(d);
    }
  }
  out.result = std::move(whole);
}

}  // namespace wt::app

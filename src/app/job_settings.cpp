// The settings a job was given (set_setting, given_setting): part of the job's
// description, which needs no renderer.
#include "app/job.hpp"

#include <algorithm>
#include <cctype>

namespace wt::app {

namespace {

// The job's field for a render setting (const or not, as the job); null for the others.
template <class J>
auto render_override(J& job, SettingId id) -> decltype(&job.width) {
  switch (id) {
    case SettingId::Width: return &job.width;
    case SettingId::Height: return &job.height;
    case SettingId::Spp: return &job.spp;
    case SettingId::Depth: return &job.depth;
    case SettingId::RouletteDepth: return &job.roulette_depth;
    case SettingId::Seed: return &job.seed;
    case SettingId::Nee: return &job.nee;
    default: return nullptr;
  }
}

}  // namespace

void set_setting(Job& job, SettingId id, int64_t value) {
  if (std::optional<int64_t>* o = render_override(job, id)) {
    *o = value;
  } else if (id == SettingId::Warmup) {
    job.warmup = value;
  } else if (id == SettingId::WaveSize) {
    job.wave_size = value;
  } else if (id == SettingId::Threads) {
    job.threads = value;
  } else if (id == SettingId::CheckpointEvery) {
    job.checkpoint_every = value;
  } else if (id == SettingId::MegakernelBatch) {
    job.megakernel_batch = value;
  } else if (id == SettingId::MinSpp) {
    job.min_spp = value;
  }
}

std::optional<int64_t> given_setting(const Job& job, SettingId id) {
  if (const std::optional<int64_t>* o = render_override(job, id)) return *o;
  static const Job defaults;
  const auto unless_default = [](int64_t v, int64_t d) { return v == d ? std::nullopt : std::optional<int64_t>(v); };
  switch (id) {
    case SettingId::Warmup: return unless_default(job.warmup, defaults.warmup);
    case SettingId::WaveSize: return unless_default(job.wave_size, defaults.wave_size);
    case SettingId::Threads: return unless_default(job.threads, defaults.threads);
    case SettingId::CheckpointEvery: return unless_default(job.checkpoint_every, defaults.checkpoint_every);
    case SettingId::MegakernelBatch: return unless_default(job.megakernel_batch, defaults.megakernel_batch);
    case SettingId::MinSpp: return unless_default(job.min_spp, defaults.min_spp);
    default: return std::nullopt;
  }
}

bool is_define_name(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

void add_defines(Job& job, const std::vector<std::string>& defines, const std::string& where) {
  for (const std::string& d : defines) {
    const size_t eq = d.find('=');
    if (eq == std::string::npos || !is_define_name(d.substr(0, eq))) {
      throw InputError(where + ": '" + d + "' is not name=value (a name of letters, digits and _)");
    }
    job.defines[d.substr(0, eq)] = d.substr(eq + 1);
  }
}

}  // namespace wt::app

// compact: keeps the entries of rays that hit something, in order. The backends
// run it with their library's select (cub::DeviceSelect::If, std::copy_if) over
// this one predicate.
#pragma once

#include "queues/path_queue.hpp"
#include "wavetrace/material.hpp"

namespace wt {

struct HitSomething {
  WT_HD bool operator()(uint32_t entry) const { return entry_key(entry) != kSortKeyMiss; }
};

}  // namespace wt

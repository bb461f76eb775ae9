// The CPU's compact and sort: the standard library in place of CUB, with the
// same results (stable, key bits only).
#pragma once

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <vector>

#include "queues/path_queue.hpp"
#include "wavetrace/material.hpp"

namespace wt::cpu {

// Keeps the entries of paths that hit something, in order.
inline void compact_entries(const uint32_t* entries, size_t count, std::vector<uint32_t>& selected) {
  selected.clear();
  std::copy_if(entries, entries + count, std::back_inserter(selected),
               [](uint32_t entry) { return entry_key(entry) != kSortKeyMiss; });
}

// Entries hold the key above the slot, so ordering whole entries orders by key and
// keeps slot order within a key, as the GPU's stable key-bits-only radix sort does
// on compact's ordered output.
inline void sort_entries(std::vector<uint32_t>& entries) { std::sort(entries.begin(), entries.end()); }

}  // namespace wt::cpu

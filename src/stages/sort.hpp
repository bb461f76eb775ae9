// sort: orders compact's entries by material key so that shade's warps see one
// material. Only the key bits take part (fewer radix passes), and the sort is
// stable, so slots keep compact's order within a key. The backends run it with
// their library's sort (cub::DeviceRadixSort over a double buffer, std::stable_sort).
#pragma once

#include "queues/path_queue.hpp"
#include "wavetrace/material.hpp"

namespace wt {

struct SortBits {
  int begin;  // the lowest key bit
  int end;    // one past the highest
};

// The bits of an entry that hold a key of `key_bits` bits.
inline SortBits sort_bits(int key_bits) { return SortBits{kSlotBits, kSlotBits + key_bits}; }

// Where each key's entries start in a sorted list of `count` (at[k], k up to the
// miss key; at[kSortKeyMiss] = count, the misses being compacted away), for
// shading a bounce one launch per kind (RenderOptions::shade_by_kind).
struct KeyStarts {
  uint32_t at[kSortKeyMiss + 1];
};

// One item per key k: the first entry of the sorted list whose key is k or more.
struct FindKeyStartsItem {
  const uint32_t* list;
  uint32_t count;
  KeyStarts* out;

  WT_HD void operator()(uint32_t k) const {
    uint32_t lo = 0, hi = count;
    while (lo < hi) {
      const uint32_t mid = lo + (hi - lo) / 2;
      if (entry_key(list[mid]) < k) lo = mid + 1; else hi = mid;
    }
    out->at[k] = lo;
  }
};

}  // namespace wt

// sort: orders compact's entries by material key so that shade's warps see one
// material. Only the key bits take part (fewer radix passes), and the sort is
// stable, so slots keep compact's order within a key. The backends run it with
// their library's sort (cub::DeviceRadixSort over a double buffer, std::stable_sort).
#pragma once

#include "queues/path_queue.hpp"

namespace wt {

struct SortBits {
  int begin;  // the lowest key bit
  int end;    // one past the highest
};

// The bits of an entry that hold a key of `key_bits` bits.
inline SortBits sort_bits(int key_bits) { return SortBits{kSlotBits, kSlotBits + key_bits}; }

}  // namespace wt

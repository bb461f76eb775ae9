// Structure-of-arrays queues declared from one field list, and the arena that lays
// every array of a wave out in one allocation. A field list names, per field, its
// element type, its array and the member of the value type it holds; the queue's
// pointers, its allocation, its load and its store all follow from that one line.
#pragma once

#include <cstddef>
#include <cstdint>

#include "wavetrace/config.hpp"

namespace wt {

// Lays arrays out one after another in one block, each aligned for coalesced
// access. Over a null base it only counts: the same calls give the block's size.
class Arena {
 public:
  static constexpr size_t kAlign = 256;

  explicit Arena(unsigned char* base) : base_(base) {}

  template <class T>
  T* take(size_t count) {
    offset_ = (offset_ + kAlign - 1) / kAlign * kAlign;
    T* p = base_ ? reinterpret_cast<T*>(base_ + offset_) : nullptr;
    offset_ += count * sizeof(T);
    return p;
  }

  size_t size() const { return offset_; }

 private:
  unsigned char* base_;
  size_t offset_ = 0;
};

}  // namespace wt

#define WT_SOA_POINTER(T, array, member) T* array;
#define WT_SOA_TAKE(T, array, member) q.array = arena.take<T>(capacity);
#define WT_SOA_LOAD(T, array, member) v.member = array[i];
#define WT_SOA_STORE(T, array, member) array[i] = v.member;
#define WT_SOA_BYTES(T, array, member) +sizeof(T)

// Declares `Queue`, a non-owning view of one array per field of FIELDS, holding
// values of type `Value` slot by slot.
#define WT_SOA_QUEUE(Queue, Value, FIELDS)                                  \
  struct Queue {                                                            \
    FIELDS(WT_SOA_POINTER)                                                  \
    static constexpr size_t kBytesPerSlot = 0 FIELDS(WT_SOA_BYTES);         \
    static Queue take(::wt::Arena& arena, size_t capacity) {                \
      Queue q;                                                              \
      FIELDS(WT_SOA_TAKE)                                                   \
      return q;                                                             \
    }                                                                       \
    WT_HD Value load(uint32_t i) const {                                    \
      Value v;                                                              \
      FIELDS(WT_SOA_LOAD)                                                   \
      return v;                                                             \
    }                                                                       \
    WT_HD void store(uint32_t i, const Value& v) const { FIELDS(WT_SOA_STORE) } \
  }

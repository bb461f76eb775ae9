// The wavefront's path state, structure-of-arrays: one array per field, so that a
// warp reading one field of consecutive slots makes one coalesced transaction.
#pragma once

#include "wavetrace/ray.hpp"

namespace wt {

// One path between bounces, as a value. Its home is a slot of a PathQueue.
struct PathState {
  Ray ray;
  vec3 throughput;
  uint32_t path;    // path index: pixel = path % pixels, sample = path / pixels
  uint32_t bounce;  // rays this path has traced so far
};

// Non-owning view of a queue's arrays (device or host memory).
struct PathQueue {
  float* ox;
  float* oy;
  float* oz;
  float* dx;
  float* dy;
  float* dz;
  float* tr;
  float* tg;
  float* tb;
  uint32_t* path;
  uint32_t* bounce;

  static constexpr int kFloatFields = 9;
  static constexpr int kUintFields = 2;
  static constexpr size_t kBytesPerSlot = kFloatFields * sizeof(float) + kUintFields * sizeof(uint32_t);

  // Lays a queue of `capacity` slots over one allocation of capacity * kBytesPerSlot bytes.
  static PathQueue over(void* memory, size_t capacity) {
    float* f = static_cast<float*>(memory);
    PathQueue q;
    float** fields[kFloatFields] = {&q.ox, &q.oy, &q.oz, &q.dx, &q.dy, &q.dz, &q.tr, &q.tg, &q.tb};
    for (int i = 0; i < kFloatFields; ++i) *fields[i] = f + i * capacity;
    uint32_t* u = reinterpret_cast<uint32_t*>(f + kFloatFields * capacity);
    q.path = u;
    q.bounce = u + capacity;
    return q;
  }

  WT_HD PathState load(uint32_t i) const {
    PathState s;
    s.ray.origin = vec3(ox[i], oy[i], oz[i]);
    s.ray.dir = vec3(dx[i], dy[i], dz[i]);
    s.throughput = vec3(tr[i], tg[i], tb[i]);
    s.path = path[i];
    s.bounce = bounce[i];
    return s;
  }

  WT_HD void store(uint32_t i, const PathState& s) const {
    ox[i] = s.ray.origin.x;
    oy[i] = s.ray.origin.y;
    oz[i] = s.ray.origin.z;
    dx[i] = s.ray.dir.x;
    dy[i] = s.ray.dir.y;
    dz[i] = s.ray.dir.z;
    tr[i] = s.throughput.x;
    tg[i] = s.throughput.y;
    tb[i] = s.throughput.z;
    path[i] = s.path;
    bounce[i] = s.bounce;
  }
};

// The closest hit of each slot's ray, SoA like the queue.
struct HitQueue {
  float* t;
  int32_t* sphere;

  WT_HD Hit load(uint32_t i) const { return Hit{t[i], sphere[i]}; }
  WT_HD void store(uint32_t i, const Hit& h) const {
    t[i] = h.t;
    sphere[i] = h.sphere;
  }
};

// Sort entries pack the material sort key above the slot index, so one 32-bit
// radix sort over the key bits alone carries the slot with it.
constexpr int kSlotBits = 27;
constexpr uint32_t kSlotMask = (1u << kSlotBits) - 1;
constexpr size_t kMaxWaveSize = size_t(1) << kSlotBits;

WT_HD WT_INLINE uint32_t pack_entry(uint32_t key, uint32_t slot) { return (key << kSlotBits) | slot; }
WT_HD WT_INLINE uint32_t entry_key(uint32_t entry) { return entry >> kSlotBits; }
WT_HD WT_INLINE uint32_t entry_slot(uint32_t entry) { return entry & kSlotMask; }

}  // namespace wt

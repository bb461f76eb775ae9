// The wavefront's path and hit state, structure-of-arrays: one array per field, so
// that a warp reading one field of consecutive slots makes one coalesced
// transaction. Each queue is declared by its field list alone (soa.hpp): adding a
// field is one line here (and the member it holds).
#pragma once

#include "queues/soa.hpp"
#include "wavetrace/geometry/geometry.hpp"
#include "wavetrace/ray.hpp"

namespace wt {

// One path between bounces, as a value. Its home is a slot of a PathQueue.
struct PathState {
  Ray ray;
  vec3 throughput;
  uint32_t path;    // path index within its pass: pixel = path_pixel(path), sample = pass's first + path / pixels
  uint32_t bounce;  // rays this path has traced so far
  float pdf;        // the last bounce's BSDF density (0: specular, or the camera), for MIS
};

// The pixel of path `path` of a pass (of width x height pixels a sample): the pass
// takes its pixels in tiles of 8 x 4, a row of tiles after another (the tiles at the
// right and bottom edges narrower or lower), so that the 32 slots of a warp start
// their rays at neighbouring pixels in both directions, as a megakernel warp does;
// every sample of a pass visits every pixel once.
WT_HD WT_INLINE uint32_t path_pixel(uint32_t path, uint32_t width, uint32_t height) {
  constexpr uint32_t kTileWidth = 8, kTileHeight = 4, kTile = kTileWidth * kTileHeight;
  const uint32_t p = path % (width * height);
  const uint32_t band = p / (width * kTileHeight);  // a row of tiles
  const uint32_t y0 = band * kTileHeight;
  const uint32_t q = p - band * width * kTileHeight;  // within the band
  if (y0 + kTileHeight <= height) {
    const uint32_t x0 = q / kTile * kTileWidth;
    // A whole tile: shifts and masks (the common case, on the path of every bounce).
    if (x0 + kTileWidth <= width) return (y0 + q % kTile / kTileWidth) * width + x0 + q % kTileWidth;
  }
  // The right and bottom edges: tiles of w x h.
  const uint32_t h = height - y0 < kTileHeight ? height - y0 : kTileHeight;
  const uint32_t tile = q / (kTileWidth * h);
  const uint32_t x0 = tile * kTileWidth;
  const uint32_t w = width - x0 < kTileWidth ? width - x0 : kTileWidth;
  const uint32_t r = q - tile * kTileWidth * h;
  return (y0 + r / w) * width + x0 + r % w;
}

// The pixels a pass's samples visit: every pixel (`active` null), in path_pixel's
// tiles, or the `count` listed (adaptive sampling's pixels still going), in the
// list's order. Path `path` of the pass is sample first + path / pixels of pixel
// pass_pixel(path).
struct PassPixels {
  const uint32_t* active = nullptr;
  uint32_t count = 0;  // with `active`
};

WT_HD WT_INLINE uint32_t pass_pixels(const PassPixels& pass, uint32_t width, uint32_t height) {
  return pass.active ? pass.count : width * height;
}

WT_HD WT_INLINE uint32_t pass_pixel(uint32_t path, const PassPixels& pass, uint32_t width, uint32_t height) {
  return pass.active ? pass.active[path % pass.count] : path_pixel(path, width, height);
}

// A light sample waiting for its shadow ray (path.hpp's ShadowRay, and the pixel
// it lights).
struct ShadowState {
  Ray ray;
  float tmax;
  vec3 contribution;
  uint32_t pixel;
};

// (element type, array, member of PathState)
#define WT_PATH_FIELDS(X)                                                                     \
  X(float, ox, ray.origin.x) X(float, oy, ray.origin.y) X(float, oz, ray.origin.z)          \
  X(float, dx, ray.dir.x) X(float, dy, ray.dir.y) X(float, dz, ray.dir.z)                   \
  X(float, tr, throughput.x) X(float, tg, throughput.y) X(float, tb, throughput.z)          \
  X(uint32_t, path, path) X(uint32_t, bounce, bounce) X(float, pdf, pdf)

// (element type, array, member of Hit): the closest hit of each slot's ray.
#define WT_HIT_FIELDS(X) \
  X(float, t, t) X(int32_t, instance, instance) X(int32_t, prim, prim) X(float, b1, b1) X(float, b2, b2)

// (element type, array, member of ShadowState)
#define WT_SHADOW_FIELDS(X)                                                              \
  X(float, ox, ray.origin.x) X(float, oy, ray.origin.y) X(float, oz, ray.origin.z)     \
  X(float, dx, ray.dir.x) X(float, dy, ray.dir.y) X(float, dz, ray.dir.z)              \
  X(float, tmax, tmax) X(float, cr, contribution.x) X(float, cg, contribution.y)        \
  X(float, cb, contribution.z) X(uint32_t, pixel, pixel)

WT_SOA_QUEUE(PathQueue, PathState, WT_PATH_FIELDS);
WT_SOA_QUEUE(ShadowQueue, ShadowState, WT_SHADOW_FIELDS);
WT_SOA_QUEUE(HitQueue, Hit, WT_HIT_FIELDS);

// A hit as intersect keeps it for shade. Of a scene of spheres alone, only its
// distance and sphere: a sphere's surface, material and emitter need no more, and
// the other three fields are 12 of the 20 bytes a ray would write (and a warp's
// whole 32-byte sectors). Kinds: the scene's, as both stages are compiled for.
template <uint32_t Kinds>
WT_HD WT_INLINE void store_hit(const HitQueue& q, uint32_t i, const Hit& h) {
  if constexpr (spheres_only(Kinds)) {
    q.t[i] = h.t;
    q.prim[i] = h.prim;
  } else {
    q.store(i, h);
  }
}

template <uint32_t Kinds>
WT_HD WT_INLINE Hit load_hit(const HitQueue& q, uint32_t i) {
  if constexpr (spheres_only(Kinds)) {
    return Hit{q.t[i], 0, q.prim[i], 0.0f, 0.0f};
  } else {
    return q.load(i);
  }
}

// Sort entries pack the material sort key above the slot index, so one 32-bit
// radix sort over the key bits alone carries the slot with it.
constexpr int kSlotBits = 27;
constexpr uint32_t kSlotMask = (1u << kSlotBits) - 1;
constexpr size_t kMaxWaveSize = size_t(1) << kSlotBits;

WT_HD WT_INLINE uint32_t pack_entry(uint32_t key, uint32_t slot) { return (key << kSlotBits) | slot; }
WT_HD WT_INLINE uint32_t entry_key(uint32_t entry) { return entry >> kSlotBits; }
WT_HD WT_INLINE uint32_t entry_slot(uint32_t entry) { return entry & kSlotMask; }

}  // namespace wt

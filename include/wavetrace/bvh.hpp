// Bounding volume hierarchy over spheres: the node layout and its traversal.
// The traversal is written once against a geometry accessor, so the global-memory
// megakernel, the constant-memory megakernel, the wavefront and the CPU backend all
// run the same code over different memories.
#pragma once

#include "wavetrace/sphere.hpp"

namespace wt {

// Two 16-byte rows: the bounds, and either the first of two adjacent children
// (inner node, count == 0) or the first sphere and the sphere count (leaf).
struct alignas(16) BvhNode {
  float lo[3];
  int32_t left_or_first;
  float hi[3];
  int32_t count;
};

// Traversal keeps a stack of this many deferred nodes; the builder keeps trees shallower.
constexpr int kBvhStackSize = 32;

// Slab test; returns the entry distance or a value > tmax when the box is missed.
WT_HD WT_INLINE float box_entry(const BvhNode& n, const vec3& o, const vec3& inv, float tmax) {
  float tx0 = (n.lo[0] - o.x) * inv.x, tx1 = (n.hi[0] - o.x) * inv.x;
  float ty0 = (n.lo[1] - o.y) * inv.y, ty1 = (n.hi[1] - o.y) * inv.y;
  float tz0 = (n.lo[2] - o.z) * inv.z, tz1 = (n.hi[2] - o.z) * inv.z;
  float tnear = fmaxf(fmaxf(fminf(tx0, tx1), fminf(ty0, ty1)), fmaxf(fminf(tz0, tz1), 0.0f));
  float tfar = fminf(fminf(fmaxf(tx0, tx1), fmaxf(ty0, ty1)), fminf(fmaxf(tz0, tz1), tmax));
  return tnear <= tfar ? tnear : tmax * 2.0f + 1.0f;
}

// Closest hit in (tmin, tmax). Geometry provides node(i) -> BvhNode,
// sphere(i) -> (center, radius) as a float4-like with x, y, z, w.
template <class Geometry>
WT_HD Hit intersect_closest(const Geometry& g, const Ray& ray, float tmin, float tmax) {
  Hit hit{tmax, -1};
  vec3 inv(1.0f / ray.dir.x, 1.0f / ray.dir.y, 1.0f / ray.dir.z);
  int stack[kBvhStackSize];
  float stack_t[kBvhStackSize];
  int top = 0;
  int node = 0;
  if (g.node_count() == 0) return hit;
  for (;;) {
    BvhNode n = g.node(node);
    if (n.count > 0) {
      for (int i = 0; i < n.count; ++i) {
        int s = n.left_or_first + i;
        auto sp = g.sphere(s);
        float t;
        if (intersect_sphere(ray, vec3(sp.x, sp.y, sp.z), sp.w, tmin, hit.t, t)) {
          hit.t = t;
          hit.sphere = s;
        }
      }
    } else {
      int a = n.left_or_first, b = n.left_or_first + 1;
      float ta = box_entry(g.node(a), ray.origin, inv, hit.t);
      float tb = box_entry(g.node(b), ray.origin, inv, hit.t);
      if (ta > tb) {
        float tt = ta;
        ta = tb;
        tb = tt;
        int ti = a;
        a = b;
        b = ti;
      }
      if (ta <= hit.t) {
        if (tb <= hit.t && top < kBvhStackSize) {
          stack[top] = b;
          stack_t[top++] = tb;
        }
        node = a;
        continue;
      }
    }
    // Pop, skipping nodes whose boxes the closest hit so far already passed.
    bool found = false;
    while (top > 0) {
      --top;
      if (stack_t[top] <= hit.t) {
        node = stack[top];
        found = true;
        break;
      }
    }
    if (!found) break;
  }
  return hit;
}

}  // namespace wt

// What the BVH tests share: walks over a wide tree and box containment.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "scene/bvh_build.hpp"

namespace wt::test {

// Calls visit(node, parent) for every node reachable from `root`, depth first
// (parent -1 for the root); fails the test on a child index outside the array.
template <class Visit>
void walk(const std::vector<WideBvhNode>& nodes, int root, Visit visit) {
  std::vector<std::pair<int, int>> todo = {{root, -1}};
  while (!todo.empty()) {
    auto [node, parent] = todo.back();
    todo.pop_back();
    ASSERT_GE(node, 0);
    ASSERT_LT(node, static_cast<int>(nodes.size()));
    visit(node, parent);
    const WideBvhNode& n = nodes[node];
    ASSERT_GE(n.child_count(), 1);
    ASSERT_LE(n.child_count(), kBvhWidth);
    for (int s = n.child_count() - 1; s >= 0; --s) {
      if (!is_leaf(n.child[s])) todo.push_back({n.child[s], node});
    }
  }
}

// Calls leaf(first, count, box) for every leaf below `root`, with its decoded box.
template <class Leaf>
void for_each_leaf(const std::vector<WideBvhNode>& nodes, int root, Leaf leaf) {
  walk(nodes, root, [&](int node, int) {
    const WideBvhNode& n = nodes[node];
    for (int s = 0; s < n.child_count(); ++s) {
      if (is_leaf(n.child[s])) leaf(leaf_first(n.child[s]), leaf_count(n.child[s]), child_bounds(n, s));
    }
  });
}

// The most nodes on a path from `root` down.
inline int wide_depth(const std::vector<WideBvhNode>& nodes, int root) {
  const WideBvhNode& n = nodes[root];
  int below = 0;
  for (int s = 0; s < n.child_count(); ++s) {
    if (!is_leaf(n.child[s])) below = std::max(below, wide_depth(nodes, n.child[s]));
  }
  return 1 + below;
}

inline bool box_contains(const Aabb& outer, const vec3& lo, const vec3& hi) {
  for (int k = 0; k < 3; ++k) {
    if (lo[k] < outer.lo[k] || hi[k] > outer.hi[k]) return false;
  }
  return true;
}

inline bool box_contains(const Aabb& outer, const Aabb& inner) { return box_contains(outer, inner.lo, inner.hi); }

// Every child's decoded box holds the box of every primitive below it (prim_box(i):
// primitive i's exact box). The decoded boxes of a node's children need not lie
// inside the node's own decoded box (each is rounded outward on its own grid); what
// traversal needs is that no box on the way down to a primitive misses it.
template <class PrimBox>
void expect_boxes_hold_primitives(const std::vector<WideBvhNode>& nodes, int root, PrimBox prim_box) {
  auto below = [&](auto& self, int32_t ref) -> Aabb {
    Aabb all;
    if (is_leaf(ref)) {
      for (int i = leaf_first(ref); i < leaf_first(ref) + leaf_count(ref); ++i) all.grow(prim_box(i));
      return all;
    }
    const WideBvhNode& n = nodes.at(ref);
    for (int s = 0; s < n.child_count(); ++s) {
      const Aabb under = self(self, n.child[s]);
      EXPECT_TRUE(box_contains(child_bounds(n, s), under)) << "node " << ref << " slot " << s;
      all.grow(under);
    }
    return all;
  };
  below(below, root);
}

}  // namespace wt::test

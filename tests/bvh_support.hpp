// What the BVH tests share: a walk over a tree and box containment.
#pragma once

#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "scene/bvh_build.hpp"

namespace wt::test {

// Calls visit(node, parent) for every node reachable from `root`, depth first
// (parent -1 for the root); fails the test on a child index outside the array.
template <class Visit>
void walk(const std::vector<BvhNode>& nodes, int root, Visit visit) {
  std::vector<std::pair<int, int>> todo = {{root, -1}};
  while (!todo.empty()) {
    auto [node, parent] = todo.back();
    todo.pop_back();
    ASSERT_GE(node, 0);
    ASSERT_LT(node, static_cast<int>(nodes.size()));
    visit(node, parent);
    if (nodes[node].count == 0) {
      todo.push_back({nodes[node].left_or_first, node});
      todo.push_back({nodes[node].left_or_first + 1, node});
    }
  }
}

inline bool box_contains(const BvhNode& outer, const vec3& lo, const vec3& hi) {
  for (int k = 0; k < 3; ++k) {
    if (lo[k] < outer.lo[k] || hi[k] > outer.hi[k]) return false;
  }
  return true;
}

inline bool box_contains(const BvhNode& outer, const BvhNode& inner) {
  const Aabb b = node_bounds(inner);
  return box_contains(outer, b.lo, b.hi);
}

}  // namespace wt::test

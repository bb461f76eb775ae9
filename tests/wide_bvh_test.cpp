// The wide node layout: leaf references, compressed child boxes that never miss
// what they bound, the slab test that never culls a box a ray touches, and the
// order in which a node's children are visited.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "bvh_support.hpp"
#include "wavetrace/path.hpp"

namespace wt {
namespace {

using test::box_contains;

TEST(WideBvh, LeafReferencesRoundTrip) {
  for (int32_t first : {0, 1, 4095, 123456, kMaxLeafFirst - 1}) {
    for (int count = 1; count <= kMaxLeafCount; ++count) {
      const int32_t ref = leaf_ref(first, count);
      ASSERT_TRUE(is_leaf(ref));
      EXPECT_EQ(leaf_first(ref), first);
      EXPECT_EQ(leaf_count(ref), count);
    }
  }
  EXPECT_FALSE(is_leaf(0));
  EXPECT_FALSE(is_leaf(INT32_MAX));
}

// The sorting network sorts: every input of zeros and ones (which proves it for
// all inputs), and random keys.
TEST(WideBvh, KeySortingNetworkSorts) {
  for (uint32_t bits = 0; bits < (1u << kBvhWidth); ++bits) {
    uint32_t k[kBvhWidth];
    for (int i = 0; i < kBvhWidth; ++i) k[i] = (bits >> i) & 1u;
    sort_keys(k);
    EXPECT_TRUE(std::is_sorted(k, k + kBvhWidth)) << "input " << bits;
  }
  std::mt19937 rng(5);
  for (int trial = 0; trial < 1000; ++trial) {
    uint32_t k[kBvhWidth];
    for (uint32_t& key : k) key = rng();
    std::vector<uint32_t> expect(k, k + kBvhWidth);
    std::sort(expect.begin(), expect.end());
    sort_keys(k);
    EXPECT_EQ(std::vector<uint32_t>(k, k + kBvhWidth), expect);
  }
}

// A one-node tree over `boxes` (at most kBvhWidth): a binary tree with one box per
// leaf, collapsed; its leaves renumbered to say which box they hold.
std::vector<WideBvhNode> one_node(const std::vector<Aabb>& boxes) {
  std::vector<BuildPrimitive> prims;
  for (const Aabb& b : boxes) prims.push_back({b, b.centre()});
  BvhBuildOptions options;
  options.max_leaf_size = 1;
  options.traversal_cost = 0.0;  // always split: one box per leaf
  const BvhTree tree = build_bvh(prims, options);
  std::vector<WideBvhNode> nodes;
  EXPECT_EQ(append_wide(nodes, tree.nodes, 0), 0);
  EXPECT_EQ(nodes.size(), 1u);
  EXPECT_EQ(nodes[0].child_count(), static_cast<int>(boxes.size()));
  for (int s = 0; s < nodes[0].child_count(); ++s) {
    nodes[0].child[s] = leaf_ref(static_cast<int32_t>(tree.order[leaf_first(nodes[0].child[s])]), 1);
  }
  return nodes;
}

// Whether the ray (o, d) meets the box, in double precision: exactly enough, next to
// the slab test's widening.
bool meets(const vec3& o, const vec3& d, const Aabb& b) {
  double enter = 0.0, leave = 1e300;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0.0f) {
      if (o[k] < b.lo[k] || o[k] > b.hi[k]) return false;
      continue;
    }
    const double t0 = (double(b.lo[k]) - o[k]) / d[k], t1 = (double(b.hi[k]) - o[k]) / d[k];
    enter = std::max(enter, std::min(t0, t1));
    leave = std::min(leave, std::max(t0, t1));
  }
  return enter <= leave;
}

// Boxes of every scale, far from the origin and near it: each child's decoded box
// contains the box it stands for, and every ray aimed at a point of the box (its
// corners and faces, where rounding decides) that meets it in exact arithmetic
// enters it in the traversal's slab test.
TEST(WideBvh, CompressedBoxesAndTheSlabTestNeverMissWhatTheyBound) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), sym(-1.0f, 1.0f);
  int rays = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const float scale = std::pow(10.0f, sym(rng) * 5.0f);
    const vec3 centre = vec3(sym(rng), sym(rng), sym(rng)) * std::pow(10.0f, unit(rng) * 6.0f);
    std::vector<Aabb> boxes(kBvhWidth);
    for (Aabb& b : boxes) {
      const vec3 lo = centre + scale * vec3(sym(rng), sym(rng), sym(rng));
      // Some boxes flat on an axis, some tiny beside their siblings.
      vec3 size = scale * vec3(unit(rng), unit(rng), unit(rng)) * (unit(rng) < 0.2f ? 1e-4f : 1.0f);
      if (unit(rng) < 0.2f) size[rng() % 3] = 0.0f;
      b.lo = lo;
      b.hi = lo + size;
    }
    const std::vector<WideBvhNode> nodes = one_node(boxes);
    const WideBvhNode& n = nodes[0];
    for (int s = 0; s < n.child_count(); ++s) {
      const Aabb& exact = boxes[leaf_first(n.child[s])];
      ASSERT_TRUE(box_contains(child_bounds(n, s), exact)) << "trial " << trial << " slot " << s;
      for (int corner = 0; corner < 8 + 6; ++corner) {
        // The box's corners, then a point on each face.
        vec3 p;
        for (int k = 0; k < 3; ++k) {
          const float along = corner < 8 ? static_cast<float>((corner >> k) & 1) : unit(rng);
          p[k] = exact.lo[k] + along * (exact.hi[k] - exact.lo[k]);
        }
        if (corner >= 8) p[(corner - 8) % 3] = (corner - 8) < 3 ? exact.lo[(corner - 8) % 3] : exact.hi[(corner - 8) % 3];
        const vec3 o = p + scale * 3.0f * glm::normalize(vec3(sym(rng), sym(rng), sym(rng)));
        const vec3 d = glm::normalize(p - o);
        if (!std::isfinite(d.x) || !meets(o, d, exact)) continue;
        float second;
        uint32_t order = children_in_order(n, o, slab_inverse(d), kRayTMax, second);
        bool entered = false;
        for (; order != 0; order >>= 4) entered |= static_cast<int>(order & 15u) - 1 == s;
        EXPECT_TRUE(entered) << "trial " << trial << " slot " << s << " point " << corner;
        ++rays;
      }
    }
  }
  EXPECT_GT(rays, 300 * kBvhWidth * 7);  // most aimed rays meet their box
}

// Unit boxes along the x axis at shuffled distances: a ray down the axis enters
// them nearest first, stops at tmax, skips those behind it, and `second` bounds
// the second one's entry.
TEST(WideBvh, ChildrenAreVisitedNearestFirst) {
  std::vector<Aabb> boxes(kBvhWidth);
  std::vector<float> starts(kBvhWidth);
  for (int i = 0; i < kBvhWidth; ++i) starts[i] = 3.0f * static_cast<float>(i);
  std::shuffle(starts.begin(), starts.end(), std::mt19937(3));
  for (int i = 0; i < kBvhWidth; ++i) boxes[i] = Aabb{vec3(starts[i], 0, 0), vec3(starts[i] + 1, 1, 1)};
  const std::vector<WideBvhNode> nodes = one_node(boxes);
  const WideBvhNode& n = nodes[0];
  const vec3 o(-1.5f, 0.5f, 0.5f), d(1, 0, 0);
  for (float tmax : {kRayTMax, 10.0f}) {
    float second;
    uint32_t order = children_in_order(n, o, slab_inverse(d), tmax, second);
    std::vector<float> entries;
    for (; order != 0; order >>= 4) entries.push_back(boxes[leaf_first(n.child[(order & 15u) - 1])].lo.x - o.x);
    EXPECT_TRUE(std::is_sorted(entries.begin(), entries.end()));
    // Boxes entered from 1.5 on, every 3: within tmax = 10, those at 1.5, 4.5 and 7.5.
    EXPECT_EQ(entries.size(), tmax == 10.0f ? 3u : static_cast<size_t>(kBvhWidth));
    EXPECT_LE(second, 4.5f);
    EXPECT_GT(second, 4.5f * (1.0f - 1e-5f));
  }
  // From inside the third box, looking down the axis: the first two are behind.
  float second;
  uint32_t order = children_in_order(n, vec3(6.5f, 0.5f, 0.5f), slab_inverse(d), kRayTMax, second);
  int entered = 0;
  for (; order != 0; order >>= 4) ++entered;
  EXPECT_EQ(entered, kBvhWidth - 2);
}

TEST(WideBvh, LeavesBeyondTheLayoutsReachAreRefused) {
  std::vector<BuildPrimitive> prims(4);
  for (int i = 0; i < 4; ++i) prims[i].box = Aabb{vec3(static_cast<float>(i)), vec3(static_cast<float>(i) + 1)};
  for (BuildPrimitive& p : prims) p.centroid = p.box.centre();
  const BvhTree tree = build_bvh(prims);
  std::vector<WideBvhNode> nodes;
  EXPECT_NO_THROW(append_wide(nodes, tree.nodes, static_cast<uint32_t>(kMaxLeafFirst - 4)));
  EXPECT_THROW(append_wide(nodes, tree.nodes, static_cast<uint32_t>(kMaxLeafFirst - 3)), std::length_error);
}

}  // namespace
}  // namespace wt

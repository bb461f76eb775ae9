// Binned-SAH BVH over boxes, in the layout geometry/bvh.hpp traverses.
#include "scene/bvh_build.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

namespace wt {

namespace {

constexpr int kBins = 16;
// The deepest a tree may be (geometry/bvh.hpp sizes the traversal stack by it).
constexpr int kMaxDepth = kMaxBvhDepth;

using Box = Aabb;

// Levels that median splits need to bring `count` primitives down to leaves.
int median_levels(int count, int max_leaf_size) {
  int levels = 0;
  for (int leaves = (count + max_leaf_size - 1) / max_leaf_size; leaves > 1; leaves = (leaves + 1) / 2) ++levels;
  return levels;
}

struct Split {
  int axis = -1;
  int bin = 0;  // primitives in bins < bin go left
  double cost = DBL_MAX;
};

// A primitive as the builder moves it: partitions permute these records in place, so
// every pass over a node's range reads contiguous memory.
struct Item {
  Box bounds;
  vec3 centroid;
  uint32_t prim;
};

// Subtrees of at least this many primitives are built on a thread of their own, down
// to the depth that gives every core one.
constexpr int kParallelMinCount = 1 << 15;

class Builder {
 public:
  // Builds the subtree of items [first, first + count) into `nodes`, its root at `node`.
  Builder(std::vector<Item>& items, std::vector<BvhNode>& nodes, const BvhBuildOptions& options, int parallel_depth)
      : items_(items), nodes_(nodes), options_(options), parallel_depth_(parallel_depth) {}

  void build(int node, int first, int count, int depth) {
    Box box, centroids;
    for (int i = first; i < first + count; ++i) {
      box.grow(items_[i].bounds);
      centroids.grow(items_[i].centroid);
    }
    BvhNode& n = nodes_[node];
    for (int k = 0; k < 3; ++k) {
      n.lo[k] = box.lo[k];
      n.hi[k] = box.hi[k];
    }

    Split split = best_split(first, count, centroids);
    double leaf_cost = count;
    double split_cost = options_.traversal_cost + split.cost / box.area();
    if (count <= options_.max_leaf_size && (split.axis < 0 || leaf_cost <= split_cost || depth == kMaxDepth)) {
      n.left_or_first = first;
      n.count = count;
      return;
    }

    int left_count = split.axis < 0 ? 0 : partition(first, count, centroids, split);
    int larger = std::max(left_count, count - left_count);
    if (split.axis < 0 || depth + 1 + median_levels(larger, options_.max_leaf_size) > kMaxDepth) left_count = median(first, count, centroids);

    int left = static_cast<int>(nodes_.size());
    nodes_[node].left_or_first = left;
    nodes_[node].count = 0;
    nodes_.resize(nodes_.size() + 2);
    if (depth < parallel_depth_ && count - left_count >= kParallelMinCount) {
      // The right subtree into nodes of its own, meanwhile the left one here; then
      // the right one's nodes follow the left one's, as a serial build lays them out.
      std::vector<BvhNode> right_nodes(1);
      right_nodes.reserve(2 * (count - left_count));
      Builder right(items_, right_nodes, options_, parallel_depth_);
      std::thread worker([&] { right.build(0, first + left_count, count - left_count, depth + 1); });
      build(left, first, left_count, depth + 1);
      worker.join();
      append_subtree(left + 1, right_nodes);
    } else {
      build(left, first, left_count, depth + 1);
      build(left + 1, first + left_count, count - left_count, depth + 1);
    }
  }

 private:
  // Places a subtree built on its own: its root at `root`, the rest appended.
  void append_subtree(int root, const std::vector<BvhNode>& sub) {
    const int base = static_cast<int>(nodes_.size()) - 1;  // sub's node i >= 1 goes to base + i
    auto placed = [&](BvhNode n) {
      if (n.count == 0) n.left_or_first += base;
      return n;
    };
    nodes_[root] = placed(sub[0]);
    for (size_t i = 1; i < sub.size(); ++i) nodes_.push_back(placed(sub[i]));
  }

  int bin_of(const Item& item, const Box& centroids, int axis) const {
    float extent = centroids.hi[axis] - centroids.lo[axis];
    int b = static_cast<int>((item.centroid[axis] - centroids.lo[axis]) / extent * kBins);
    return std::min(std::max(b, 0), kBins - 1);
  }

  // Cost is the children's area-weighted primitive counts; no split when the centroids
  // coincide on every axis.
  Split best_split(int first, int count, const Box& centroids) const {
    Split best;
    for (int axis = 0; axis < 3; ++axis) {
      if (!(centroids.hi[axis] > centroids.lo[axis])) continue;
      Box bin_box[kBins];
      int bin_count[kBins] = {};
      for (int i = first; i < first + count; ++i) {
        int b = bin_of(items_[i], centroids, axis);
        bin_box[b].grow(items_[i].bounds);
        ++bin_count[b];
      }
      // right_cost[b]: cost of the bins from b on.
      double right_cost[kBins];
      Box right;
      int right_n = 0;
      for (int b = kBins - 1; b > 0; --b) {
        right.grow(bin_box[b]);
        right_n += bin_count[b];
        right_cost[b] = right_n > 0 ? right.area() * right_n : -1.0;
      }
      Box left;
      int left_n = 0;
      for (int b = 1; b < kBins; ++b) {
        left.grow(bin_box[b - 1]);
        left_n += bin_count[b - 1];
        if (left_n == 0 || right_cost[b] < 0.0) continue;
        double cost = left.area() * left_n + right_cost[b];
        if (cost < best.cost) best = Split{axis, b, cost};
      }
    }
    return best;
  }

  int partition(int first, int count, const Box& centroids, const Split& split) {
    auto begin = items_.begin() + first;
    auto mid = std::partition(begin, begin + count,
                              [&](const Item& item) { return bin_of(item, centroids, split.axis) < split.bin; });
    return static_cast<int>(mid - begin);
  }

  // Halves the range along the widest centroid axis; always makes progress, even
  // when every centroid is the same point.
  int median(int first, int count, const Box& centroids) {
    vec3 extent = centroids.hi - centroids.lo;
    int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    auto begin = items_.begin() + first;
    std::nth_element(begin, begin + count / 2, begin + count,
                     [&](const Item& a, const Item& b) { return a.centroid[axis] < b.centroid[axis]; });
    return count / 2;
  }

  std::vector<Item>& items_;
  std::vector<BvhNode>& nodes_;
  const BvhBuildOptions& options_;
  int parallel_depth_;
};

}  // namespace

BvhTree build_bvh(const std::vector<BuildPrimitive>& prims, const BvhBuildOptions& options) {
  // Node and primitive indices are int32 on the device; median splits of this many
  // primitives must fit within the depth limit.
  const size_t count = prims.size();
  if (count == 0) throw std::length_error("a BVH needs at least one primitive");
  if (count > static_cast<size_t>(INT32_MAX / 2) ||
      median_levels(static_cast<int>(count), options.max_leaf_size) > kMaxDepth) {
    throw std::length_error("too many primitives for the BVH (" + std::to_string(count) + ")");
  }
  std::vector<Item> items(count);
  for (size_t i = 0; i < count; ++i) items[i] = Item{prims[i].box, prims[i].centroid, static_cast<uint32_t>(i)};
  int parallel_depth = 0;
  for (unsigned cores = std::thread::hardware_concurrency(); (1u << parallel_depth) < cores;) ++parallel_depth;
  BvhTree tree;
  tree.nodes.reserve(2 * count);
  tree.nodes.resize(1);
  Builder(items, tree.nodes, options, parallel_depth).build(0, 0, static_cast<int>(count), 0);
  tree.order.resize(count);
  for (size_t i = 0; i < count; ++i) tree.order[i] = items[i].prim;
  return tree;
}

BvhStats bvh_stats(const std::vector<BvhNode>& nodes, const BvhBuildOptions& options) {
  BvhStats stats;
  if (nodes.empty()) return stats;
  auto area = [](const BvhNode& n) { return node_bounds(n).area(); };
  const double root_area = area(nodes[0]);
  std::vector<std::pair<int, int>> todo{{0, 1}};  // (node, depth)
  while (!todo.empty()) {
    auto [i, depth] = todo.back();
    todo.pop_back();
    const BvhNode& n = nodes[i];
    ++stats.nodes;
    stats.depth = std::max(stats.depth, depth);
    const double p = root_area > 0.0 ? area(n) / root_area : 1.0;
    if (n.count > 0) {
      ++stats.leaves;
      stats.sah_cost += p * n.count;
    } else {
      stats.sah_cost += p * options.traversal_cost;
      todo.push_back({n.left_or_first, depth + 1});
      todo.push_back({n.left_or_first + 1, depth + 1});
    }
  }
  return stats;
}

}  // namespace wt

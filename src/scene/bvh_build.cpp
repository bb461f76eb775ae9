// Binned-SAH BVH over boxes, collapsed into the layout geometry/bvh.hpp traverses.
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

namespace {

// Grid value q on one axis of a node, exactly (in double: a float plus an 8-bit
// integer times a power of two).
double decoded(float origin, uint32_t exponent, int q) {
  return static_cast<double>(origin) + q * static_cast<double>(grid_step(exponent));
}

// The float at or below (down) or at or above x.
float round_float(double x, bool down) {
  const float f = static_cast<float>(x);
  if (down) return static_cast<double>(f) > x ? std::nextafter(f, -FLT_MAX) : f;
  return static_cast<double>(f) < x ? std::nextafter(f, FLT_MAX) : f;
}

}  // namespace

Aabb child_bounds(const WideBvhNode& n, int slot) {
  Aabb b;
  for (int k = 0; k < 3; ++k) {
    b.lo[k] = round_float(decoded(n.origin[k], n.exponent(k), static_cast<int>(n.grid_lo(k, slot))), true);
    b.hi[k] = round_float(decoded(n.origin[k], n.exponent(k), static_cast<int>(n.grid_hi(k, slot))), false);
  }
  return b;
}

Aabb wide_bounds(const WideBvhNode& n) {
  Aabb b;
  for (int s = 0; s < n.child_count(); ++s) b.grow(child_bounds(n, s));
  return b;
}

namespace {

// The grid of one axis: the smallest step whose 255 cells reach from `lo` to `hi`.
uint32_t grid_exponent(float lo, float hi) {
  const double extent = static_cast<double>(hi) - static_cast<double>(lo);
  int e = 1;
  if (extent > 0.0) e = std::clamp(static_cast<int>(std::floor(std::log2(extent / 255.0))) + 127, 1, 254);
  while (e < 254 && decoded(lo, static_cast<uint32_t>(e), 255) < hi) ++e;
  return static_cast<uint32_t>(e);
}

class Collapser {
 public:
  Collapser(std::vector<WideBvhNode>& out, const std::vector<BvhNode>& tree, uint32_t first_prim)
      : out_(out), tree_(tree), first_prim_(first_prim) {}

  int32_t collapse(int b) {
    // The children: the binary node's own two, then repeatedly the two of the inner
    // one of largest area in place of it (a leaf root stands as the one child).
    int slots[kBvhWidth];
    int used = 0;
    if (tree_[b].count > 0) {
      slots[used++] = b;
    } else {
      slots[used++] = tree_[b].left_or_first;
      slots[used++] = tree_[b].left_or_first + 1;
    }
    while (used < kBvhWidth) {
      int best = -1;
      double best_area = -1.0;
      for (int s = 0; s < used; ++s) {
        const BvhNode& c = tree_[slots[s]];
        if (c.count == 0 && node_bounds(c).area() > best_area) {
          best_area = node_bounds(c).area();
          best = s;
        }
      }
      if (best < 0) break;
      const int first = tree_[slots[best]].left_or_first;
      slots[best] = first;
      slots[used++] = first + 1;
    }

    const int32_t index = static_cast<int32_t>(out_.size());
    out_.emplace_back();
    WideBvhNode n{};
    n.meta = static_cast<uint32_t>(used) << 24;
    Aabb box;
    for (int s = 0; s < used; ++s) box.grow(node_bounds(tree_[slots[s]]));
    for (int k = 0; k < 3; ++k) {
      n.origin[k] = box.lo[k];
      n.meta |= grid_exponent(box.lo[k], box.hi[k]) << (8 * k);
    }
    for (int s = 0; s < used; ++s) {
      const Aabb c = node_bounds(tree_[slots[s]]);
      for (int k = 0; k < 3; ++k) quantize(n, k, s, c.lo[k], c.hi[k]);
    }
    for (int s = 0; s < used; ++s) {
      const BvhNode& c = tree_[slots[s]];
      if (c.count > 0) {
        const uint64_t first = uint64_t(first_prim_) + static_cast<uint32_t>(c.left_or_first);
        if (first + c.count > uint64_t(kMaxLeafFirst) || c.count > kMaxLeafCount) {
          throw std::length_error("too many primitives for the BVH's leaves (at most " +
                                  std::to_string(kMaxLeafFirst) + ")");
        }
        n.child[s] = leaf_ref(static_cast<int32_t>(first), c.count);
      } else {
        n.child[s] = collapse(slots[s]);
      }
    }
    out_[index] = n;
    return index;
  }

 private:
  // The grid cells of [lo, hi] on axis k, rounded outward so that the decoded box
  // contains it.
  static void quantize(WideBvhNode& n, int k, int slot, float lo, float hi) {
    const float o = n.origin[k];
    const uint32_t e = n.exponent(k);
    const double step = grid_step(e);
    int qlo = std::clamp(static_cast<int>(std::floor((double(lo) - o) / step)), 0, 255);
    while (qlo > 0 && decoded(o, e, qlo) > lo) --qlo;
    int qhi = std::clamp(static_cast<int>(std::ceil((double(hi) - o) / step)), 0, 255);
    while (qhi < 255 && decoded(o, e, qhi) < hi) ++qhi;
    if (decoded(o, e, qlo) > lo || decoded(o, e, qhi) < hi) {
      throw std::logic_error("a BVH child box does not fit its node's grid");
    }
    const int word = kGridWords * k + (slot >> 2), shift = 8 * (slot & 3);
    n.lo[word] |= static_cast<uint32_t>(qlo) << shift;
    n.hi[word] |= static_cast<uint32_t>(qhi) << shift;
  }

  std::vector<WideBvhNode>& out_;
  const std::vector<BvhNode>& tree_;
  uint32_t first_prim_;
};

}  // namespace

int32_t append_wide(std::vector<WideBvhNode>& out, const std::vector<BvhNode>& tree, uint32_t first_prim) {
  return Collapser(out, tree, first_prim).collapse(0);
}

BvhStats bvh_stats(const std::vector<WideBvhNode>& nodes, int32_t root, const BvhBuildOptions& options) {
  BvhStats stats;
  if (nodes.empty()) return stats;
  const double root_area = wide_bounds(nodes[root]).area();
  auto share = [&](const Aabb& b) { return root_area > 0.0 ? b.area() / root_area : 1.0; };
  struct Todo {
    int32_t node;
    int depth;
    double p;  // the node's share of the root's area
  };
  std::vector<Todo> todo{{root, 1, 1.0}};
  while (!todo.empty()) {
    const Todo t = todo.back();
    todo.pop_back();
    const WideBvhNode& n = nodes[t.node];
    ++stats.nodes;
    stats.depth = std::max(stats.depth, t.depth);
    stats.sah_cost += t.p * options.traversal_cost;
    for (int s = 0; s < n.child_count(); ++s) {
      const double p = share(child_bounds(n, s));
      if (is_leaf(n.child[s])) {
        ++stats.leaves;
        stats.sah_cost += p * leaf_count(n.child[s]);
      } else {
        todo.push_back({n.child[s], t.depth + 1, p});
      }
    }
  }
  return stats;
}

}  // namespace wt

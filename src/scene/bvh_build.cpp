// Binned-SAH BVH over the scene's spheres, in the layout bvh.hpp traverses.
#include <algorithm>
#include <cfloat>
#include <cmath>

#include "scene/scene.hpp"

namespace wt {

namespace {

constexpr int kBins = 16;
constexpr int kMaxLeafSize = 4;
// Traversal defers at most one node per level, and the deferred nodes' depths
// strictly increase down the stack, so a tree of depth D needs at most D stack
// entries. Building to three quarters of the stack leaves a margin for later
// changes to the traversal.
constexpr int kMaxDepth = kBvhStackSize * 3 / 4;
// SAH cost of visiting an inner node relative to one sphere test: both are a
// handful of multiply-adds and a compare.
constexpr double kTraversalCost = 1.0;

struct Box {
  vec3 lo{FLT_MAX};
  vec3 hi{-FLT_MAX};

  void grow(const Box& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  void grow(const vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  // In double: areas of scene-sized boxes times sphere counts overflow a float.
  double area() const {
    glm::dvec3 d = glm::dvec3(hi) - glm::dvec3(lo);
    return d.x < 0.0 ? 0.0 : 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
};

// Levels that median splits need to bring `count` spheres down to leaves.
int median_levels(int count) {
  int levels = 0;
  for (int leaves = (count + kMaxLeafSize - 1) / kMaxLeafSize; leaves > 1; leaves = (leaves + 1) / 2) ++levels;
  return levels;
}

struct Split {
  int axis = -1;
  int bin = 0;  // spheres in bins < bin go left
  double cost = DBL_MAX;
};

class Builder {
 public:
  Builder(const std::vector<SphereGeom>& spheres, std::vector<BvhNode>& nodes) : nodes_(nodes) {
    for (const SphereGeom& s : spheres) {
      vec3 c(s.x, s.y, s.z);
      // The slab test and the sphere test round differently; a box a little larger
      // than the sphere keeps a grazing hit from being culled by its own box.
      float pad = 1e-5f * (std::max({std::fabs(s.x), std::fabs(s.y), std::fabs(s.z)}) + s.w);
      Box b;
      b.lo = c - vec3(s.w + pad);
      b.hi = c + vec3(s.w + pad);
      bounds_.push_back(b);
      centroid_.push_back(c);
      order_.push_back(static_cast<uint32_t>(order_.size()));
    }
  }

  void build(int node, int first, int count, int depth) {
    Box box, centroids;
    for (int i = first; i < first + count; ++i) {
      box.grow(bounds_[order_[i]]);
      centroids.grow(centroid_[order_[i]]);
    }
    BvhNode& n = nodes_[node];
    for (int k = 0; k < 3; ++k) {
      n.lo[k] = box.lo[k];
      n.hi[k] = box.hi[k];
    }

    Split split = best_split(first, count, centroids);
    double leaf_cost = count;
    double split_cost = kTraversalCost + split.cost / box.area();
    if (count <= kMaxLeafSize && (split.axis < 0 || leaf_cost <= split_cost || depth == kMaxDepth)) {
      n.left_or_first = first;
      n.count = count;
      return;
    }

    int left_count = split.axis < 0 ? 0 : partition(first, count, centroids, split);
    int larger = std::max(left_count, count - left_count);
    if (split.axis < 0 || depth + 1 + median_levels(larger) > kMaxDepth) left_count = median(first, count, centroids);

    int left = static_cast<int>(nodes_.size());
    nodes_[node].left_or_first = left;
    nodes_[node].count = 0;
    nodes_.resize(nodes_.size() + 2);
    build(left, first, left_count, depth + 1);
    build(left + 1, first + left_count, count - left_count, depth + 1);
  }

  const std::vector<uint32_t>& order() const { return order_; }

 private:
  int bin_of(uint32_t sphere, const Box& centroids, int axis) const {
    float extent = centroids.hi[axis] - centroids.lo[axis];
    int b = static_cast<int>((centroid_[sphere][axis] - centroids.lo[axis]) / extent * kBins);
    return std::min(std::max(b, 0), kBins - 1);
  }

  // Cost is the children's area-weighted sphere counts; no split when the centroids
  // coincide on every axis.
  Split best_split(int first, int count, const Box& centroids) const {
    Split best;
    for (int axis = 0; axis < 3; ++axis) {
      if (!(centroids.hi[axis] > centroids.lo[axis])) continue;
      Box bin_box[kBins];
      int bin_count[kBins] = {};
      for (int i = first; i < first + count; ++i) {
        int b = bin_of(order_[i], centroids, axis);
        bin_box[b].grow(bounds_[order_[i]]);
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
    auto begin = order_.begin() + first;
    auto mid = std::partition(begin, begin + count,
                              [&](uint32_t s) { return bin_of(s, centroids, split.axis) < split.bin; });
    return static_cast<int>(mid - begin);
  }

  // Halves the range along the widest centroid axis; always makes progress, even
  // when every centroid is the same point.
  int median(int first, int count, const Box& centroids) {
    vec3 extent = centroids.hi - centroids.lo;
    int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    auto begin = order_.begin() + first;
    std::nth_element(begin, begin + count / 2, begin + count,
                     [&](uint32_t a, uint32_t b) { return centroid_[a][axis] < centroid_[b][axis]; });
    return count / 2;
  }

  std::vector<BvhNode>& nodes_;
  std::vector<Box> bounds_;
  std::vector<vec3> centroid_;
  std::vector<uint32_t> order_;
};

}  // namespace

void build_bvh(Scene& scene) {
  scene.nodes.clear();
  if (scene.spheres.empty()) return;
  // Node and sphere indices are int32 on the device; median splits of this many
  // spheres fit within the depth limit.
  const size_t count = scene.spheres.size();
  if (count > static_cast<size_t>(INT32_MAX / 2) || median_levels(static_cast<int>(count)) > kMaxDepth) {
    throw SceneError(scene.source + ": /spheres: too many spheres for the BVH (" + std::to_string(count) + ")");
  }

  Builder builder(scene.spheres, scene.nodes);
  scene.nodes.reserve(2 * count);
  scene.nodes.resize(1);
  builder.build(0, 0, static_cast<int>(count), 0);

  std::vector<SphereGeom> spheres(count);
  std::vector<uint32_t> materials(count);
  for (size_t i = 0; i < count; ++i) {
    spheres[i] = scene.spheres[builder.order()[i]];
    materials[i] = scene.sphere_material[builder.order()[i]];
  }
  scene.spheres = std::move(spheres);
  scene.sphere_material = std::move(materials);
}

}  // namespace wt

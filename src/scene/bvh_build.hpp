// The BVH builder: a binned-SAH tree over boxes, in the node layout that
// include/wavetrace/geometry/bvh.hpp traverses. It knows nothing of what the boxes
// bound: spheres, triangles and instances are all built by it.
#pragma once

#include <cfloat>
#include <cstdint>
#include <vector>

#include "wavetrace/geometry/bvh.hpp"

namespace wt {

struct Aabb {
  vec3 lo{FLT_MAX};
  vec3 hi{-FLT_MAX};

  void grow(const Aabb& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  void grow(const vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  vec3 centre() const { return 0.5f * (lo + hi); }
  // In double: areas of scene-sized boxes times primitive counts overflow a float.
  double area() const {
    glm::dvec3 d = glm::dvec3(hi) - glm::dvec3(lo);
    return d.x < 0.0 ? 0.0 : 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
};

inline Aabb node_bounds(const BvhNode& n) {
  Aabb b;
  b.lo = vec3(n.lo[0], n.lo[1], n.lo[2]);
  b.hi = vec3(n.hi[0], n.hi[1], n.hi[2]);
  return b;
}

struct BvhBuildOptions {
  int max_leaf_size = 4;
  // The cost of visiting an inner node relative to one primitive test.
  double traversal_cost = 1.0;
};

// What the builder places: a box and the point that bins it (a sphere's centre,
// a triangle's centroid, a box's centre).
struct BuildPrimitive {
  Aabb box;
  vec3 centroid;
};

struct BvhTree {
  std::vector<BvhNode> nodes;  // root at 0; leaves index into `order`'s positions
  std::vector<uint32_t> order;  // order[i]: the input primitive that leaf position i holds
};

// Builds over `prims` (at least one). Large subtrees are built on threads of their
// own. Throws std::length_error when there are too many primitives for 32-bit
// indices or for the depth the traversal's stack allows.
BvhTree build_bvh(const std::vector<BuildPrimitive>& prims, const BvhBuildOptions& options = {});

// What a tree costs and holds: its SAH cost (the expected number of node visits
// and primitive tests of a ray through the root box, with the options' costs), and
// its shape.
struct BvhStats {
  size_t nodes = 0;
  size_t leaves = 0;
  int depth = 0;
  double sah_cost = 0;
};
BvhStats bvh_stats(const std::vector<BvhNode>& nodes, const BvhBuildOptions& options = {});

}  // namespace wt

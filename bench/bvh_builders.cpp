// Our BVH builder (src/scene/bvh_build.cpp) against Embree's generic BVH builder
// (rtcBuildBVH), on the triangles of mesh files:
//
//     wavetrace-bvh-bench [--runs N] [--rays N] MESH...
//
// For each mesh and builder: the median build time of N runs, the builders taking
// turns within each run (two threads each: Embree's device is made with threads=2,
// ours uses hardware_concurrency, 2 on the machine this was written for),
// the tree's shape and SAH cost from bvh_stats, and, over random rays (origins in
// the mesh's box, directions uniform on the sphere; the same rays for every
// builder), the mean nodes visited and triangles tested by a closest-hit traversal
// like geometry.hpp's. Every tree must give every ray the closest hit of the first
// (ours), within 1e-5 relative; a few rays are also checked against every triangle.
//
// Embree's trees are built into nodes of its allocator through the callbacks and
// then flattened into the project's layout (children adjacent, leaves holding a
// contiguous range of `order`), so bvh_stats and the traversal treat every tree
// alike. With spatial splits (embree-high+sbvh) a triangle may be in several
// leaves: its `order` holds more references than there are triangles, which the
// renderer's layout (a permutation of the triangles) cannot hold without
// duplicating triangles.
#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/bvh_build.hpp"
#include "scene/mesh_load.hpp"
#include "wavetrace/geometry/bvh.hpp"
#include "wavetrace/geometry/triangle.hpp"

using namespace wt;

namespace {

// ---- Embree's builder, into our layout ----

struct ENode {
  bool leaf;
};
struct EInner : ENode {
  ENode* child[2];
  RTCBounds bounds[2];
};
struct ELeaf : ENode {
  uint32_t count;
  uint32_t prim[1];  // `count` of them
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned int child_count, void*) {
  if (child_count != 2) throw std::logic_error("Embree made a node of " + std::to_string(child_count) + " children");
  auto* n = static_cast<EInner*>(rtcThreadLocalAlloc(alloc, sizeof(EInner), 16));
  n->leaf = false;
  return n;
}
void set_children(void* node, void** children, unsigned int, void*) {
  auto* n = static_cast<EInner*>(node);
  n->child[0] = static_cast<ENode*>(children[0]);
  n->child[1] = static_cast<ENode*>(children[1]);
}
void set_bounds(void* node, const RTCBounds** bounds, unsigned int, void*) {
  auto* n = static_cast<EInner*>(node);
  n->bounds[0] = *bounds[0];
  n->bounds[1] = *bounds[1];
}
void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
  auto* l = static_cast<ELeaf*>(rtcThreadLocalAlloc(alloc, sizeof(ELeaf) + count * sizeof(uint32_t), 16));
  l->leaf = true;
  l->count = static_cast<uint32_t>(count);
  for (size_t i = 0; i < count; ++i) l->prim[i] = prims[i].primID;
  return l;
}

// Spatial splits: the parts of the triangle on either side of the plane, each
// bounded by its corners and its edges' crossings of the plane, and clipped to the
// reference's box (already a part of the triangle).
void split_triangle(const RTCBuildPrimitive* prim, unsigned int dim, float pos, RTCBounds* left, RTCBounds* right,
                    void* user) {
  const TriangleGeom& tri = (*static_cast<const std::vector<TriangleGeom>*>(user))[prim->primID];
  Aabb l, r;
  for (int i = 0; i < 3; ++i) {
    const vec3 a = tri.corner(i), b = tri.corner((i + 1) % 3);
    if (a[dim] <= pos) l.grow(a);
    if (a[dim] >= pos) r.grow(a);
    if ((a[dim] < pos && b[dim] > pos) || (a[dim] > pos && b[dim] < pos)) {
      vec3 c = a + (pos - a[dim]) / (b[dim] - a[dim]) * (b - a);
      c[dim] = pos;
      l.grow(c);
      r.grow(c);
    }
  }
  const vec3 lo(prim->lower_x, prim->lower_y, prim->lower_z), hi(prim->upper_x, prim->upper_y, prim->upper_z);
  l.hi[dim] = std::min(l.hi[dim], pos);
  r.lo[dim] = std::max(r.lo[dim], pos);
  l.lo = glm::max(l.lo, lo);
  l.hi = glm::min(l.hi, hi);
  r.lo = glm::max(r.lo, lo);
  r.hi = glm::min(r.hi, hi);
  *left = RTCBounds{l.lo.x, l.lo.y, l.lo.z, 0, l.hi.x, l.hi.y, l.hi.z, 0};
  *right = RTCBounds{r.lo.x, r.lo.y, r.lo.z, 0, r.hi.x, r.hi.y, r.hi.z, 0};
}

void set_node_bounds(BvhNode& n, const RTCBounds& b) {
  n.lo[0] = b.lower_x, n.lo[1] = b.lower_y, n.lo[2] = b.lower_z;
  n.hi[0] = b.upper_x, n.hi[1] = b.upper_y, n.hi[2] = b.upper_z;
}

// Lays out a subtree as build_bvh does: a node's two children adjacent, the left
// child's subtree after them, then the right child's.
void flatten(const ENode* e, int index, BvhTree& tree) {
  if (e->leaf) {
    const auto* l = static_cast<const ELeaf*>(e);
    tree.nodes[index].left_or_first = static_cast<int32_t>(tree.order.size());
    tree.nodes[index].count = static_cast<int32_t>(l->count);
    tree.order.insert(tree.order.end(), l->prim, l->prim + l->count);
    return;
  }
  const auto* n = static_cast<const EInner*>(e);
  const int left = static_cast<int>(tree.nodes.size());
  tree.nodes.resize(tree.nodes.size() + 2);
  tree.nodes[index].left_or_first = left;
  tree.nodes[index].count = 0;
  set_node_bounds(tree.nodes[left], n->bounds[0]);
  set_node_bounds(tree.nodes[left + 1], n->bounds[1]);
  flatten(n->child[0], left, tree);
  flatten(n->child[1], left + 1, tree);
}

struct EmbreeBuilder {
  RTCDevice device;
  RTCBuildQuality quality;
  bool spatial_splits;

  BvhTree build(const std::vector<BuildPrimitive>& prims, const std::vector<TriangleGeom>& tris,
                double* flatten_seconds) const {
    const size_t count = prims.size();
    const size_t capacity = spatial_splits ? 2 * count : count;
    std::vector<RTCBuildPrimitive> refs(capacity);
    Aabb root;
    for (size_t i = 0; i < count; ++i) {
      const Aabb& b = prims[i].box;
      refs[i] = RTCBuildPrimitive{b.lo.x, b.lo.y, b.lo.z, 0u, b.hi.x, b.hi.y, b.hi.z, static_cast<unsigned>(i)};
      root.grow(b);
    }
    RTCBVH bvh = rtcNewBVH(device);
    RTCBuildArguments args = rtcDefaultBuildArguments();
    args.buildQuality = quality;
    args.maxBranchingFactor = 2;
    args.minLeafSize = 1;
    args.maxLeafSize = 4;
    args.traversalCost = 1.0f;  // as BvhBuildOptions: a node visit costs one primitive test
    args.intersectionCost = 1.0f;
    args.bvh = bvh;
    args.primitives = refs.data();
    args.primitiveCount = count;
    args.primitiveArrayCapacity = capacity;
    args.createNode = create_node;
    args.setNodeChildren = set_children;
    args.setNodeBounds = set_bounds;
    args.createLeaf = create_leaf;
    args.splitPrimitive = spatial_splits ? split_triangle : nullptr;
    args.userPtr = const_cast<std::vector<TriangleGeom>*>(&tris);
    auto* top = static_cast<const ENode*>(rtcBuildBVH(&args));
    if (!top) throw std::runtime_error("rtcBuildBVH failed");
    auto start = std::chrono::steady_clock::now();
    BvhTree tree;
    tree.nodes.reserve(2 * count);
    tree.order.reserve(count);
    tree.nodes.resize(1);
    set_node_bounds(tree.nodes[0], RTCBounds{root.lo.x, root.lo.y, root.lo.z, 0, root.hi.x, root.hi.y, root.hi.z, 0});
    flatten(top, 0, tree);
    *flatten_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    rtcReleaseBVH(bvh);
    return tree;
  }
};

// ---- Traversal ----

struct TraceCounts {
  float t = 0;       // the closest hit; tmax for none
  int nodes = 0;     // nodes whose box the ray entered (the root included)
  int triangles = 0;  // triangle tests
};

constexpr float kTMax = 1e30f;

// Closest hit as geometry.hpp's intersect_closest walks one bottom level: the
// nearer child first, the farther one deferred with its entry distance. The stack
// here is deep enough for any tree, so that a tree deeper than the renderer's
// stack still gives the right answer (its depth is reported).
TraceCounts trace(const BvhTree& tree, const std::vector<TriangleGeom>& tris, const vec3& o, const vec3& d) {
  TraceCounts c;
  c.t = kTMax;
  const vec3 inv(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
  const TriangleRay tr = triangle_ray(d);
  if (box_entry(tree.nodes[0], o, inv, c.t) > c.t) return c;
  int stack[256];
  float stack_t[256];
  int top = 0, node = 0;
  for (;;) {
    ++c.nodes;
    const BvhNode& n = tree.nodes[node];
    if (n.count > 0) {
      for (int i = n.left_or_first; i < n.left_or_first + n.count; ++i) {
        float t, b1, b2;
        ++c.triangles;
        if (intersect_triangle(tris[tree.order[i]], o, tr, c.t, t, b1, b2)) c.t = t;
      }
    } else {
      int a = n.left_or_first, b = a + 1;
      float ta = box_entry(tree.nodes[a], o, inv, c.t), tb = box_entry(tree.nodes[b], o, inv, c.t);
      if (ta > tb) std::swap(ta, tb), std::swap(a, b);
      if (ta <= c.t) {
        if (tb <= c.t) stack[top] = b, stack_t[top++] = tb;
        node = a;
        continue;
      }
    }
    bool found = false;
    while (top > 0) {
      --top;
      if (stack_t[top] <= c.t) {
        node = stack[top];
        found = true;
        break;
      }
    }
    if (!found) break;
  }
  return c;
}

float brute_force(const std::vector<TriangleGeom>& tris, const vec3& o, const vec3& d) {
  const TriangleRay tr = triangle_ray(d);
  float best = kTMax;
  for (const TriangleGeom& tri : tris) {
    float t, b1, b2;
    if (intersect_triangle(tri, o, tr, best, t, b1, b2)) best = t;
  }
  return best;
}

bool same_hit(float a, float b) {
  if (a >= kTMax || b >= kTMax) return a == b;
  return std::fabs(a - b) <= 1e-5f * std::max(a, b);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 5, ray_count = 100000;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) {
      runs = std::atoi(argv[++i]);
    } else if (a == "--rays" && i + 1 < argc) {
      ray_count = std::atoi(argv[++i]);
    } else {
      files.push_back(a);
    }
  }
  if (files.empty()) {
    std::fprintf(stderr, "usage: wavetrace-bvh-bench [--runs N] [--rays N] MESH...\n");
    return 2;
  }

  RTCDevice device = rtcNewDevice("threads=2");
  if (!device) {
    std::fprintf(stderr, "rtcNewDevice failed\n");
    return 1;
  }
  rtcSetDeviceErrorFunction(
      device, [](void*, RTCError, const char* what) { std::fprintf(stderr, "embree: %s\n", what); }, nullptr);
  const EmbreeBuilder embree_medium{device, RTC_BUILD_QUALITY_MEDIUM, false};
  const EmbreeBuilder embree_high{device, RTC_BUILD_QUALITY_HIGH, false};
  const EmbreeBuilder embree_sbvh{device, RTC_BUILD_QUALITY_HIGH, true};

  std::printf("| mesh | builder | triangles | build s | nodes | leaves | depth | SAH cost | nodes/ray | tris/ray | refs | wrong hits |\n");
  std::printf("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  int failures = 0;
  for (const std::string& file : files) {
    const TriangleMesh mesh = load_mesh(file);
    std::vector<TriangleGeom> tris(mesh.triangles.size());
    std::vector<BuildPrimitive> prims(tris.size());
    Aabb box;
    for (size_t i = 0; i < tris.size(); ++i) {
      float* corner[3] = {tris[i].p0, tris[i].p1, tris[i].p2};
      for (int k = 0; k < 3; ++k) {
        const vec3 p = mesh.positions[mesh.triangles[i][k]];
        corner[k][0] = p.x, corner[k][1] = p.y, corner[k][2] = p.z;
        prims[i].box.grow(p);
      }
      tris[i].alpha = 0;
      tris[i].pad1 = tris[i].pad2 = 0.0f;
      prims[i].centroid = prims[i].box.centre();  // as scene_bvh.cpp's triangle_primitive
      box.grow(prims[i].box);
    }
    std::string name = file.substr(file.find_last_of('/') + 1);

    // The same rays for every builder.
    std::mt19937 rng(1234);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::normal_distribution<float> normal;
    std::vector<vec3> origins(ray_count), dirs(ray_count);
    for (int i = 0; i < ray_count; ++i) {
      origins[i] = box.lo + vec3(unit(rng), unit(rng), unit(rng)) * (box.hi - box.lo);
      vec3 d;
      do d = vec3(normal(rng), normal(rng), normal(rng));
      while (glm::length(d) < 1e-3f);
      dirs[i] = glm::normalize(d);
    }
    std::vector<float> reference;

    struct Entry {
      const char* name;
      std::function<BvhTree(double*)> build;
    };
    std::vector<Entry> builders = {
        {"ours", [&](double* f) { *f = 0; return build_bvh(prims); }},
        {"embree-medium", [&](double* f) { return embree_medium.build(prims, tris, f); }},
        {"embree-high", [&](double* f) { return embree_high.build(prims, tris, f); }},
        {"embree-high+sbvh", [&](double* f) { return embree_sbvh.build(prims, tris, f); }},
    };
    // Runs interleave the builders, so that load from elsewhere on the machine
    // falls on all of them alike.
    const size_t nb = builders.size();
    std::vector<std::vector<double>> seconds(nb), flatten_seconds(nb);
    std::vector<BvhTree> trees(nb);
    for (int r = 0; r < runs; ++r) {
      for (size_t k = 0; k < nb; ++k) {
        double f = 0;
        auto start = std::chrono::steady_clock::now();
        trees[k] = builders[k].build(&f);
        seconds[k].push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        flatten_seconds[k].push_back(f);
      }
    }
    for (size_t k = 0; k < nb; ++k) {
      const Entry& b = builders[k];
      const BvhTree& tree = trees[k];
      const BvhStats stats = bvh_stats(tree.nodes);
      double nodes = 0, tested = 0;
      int wrong = 0;
      const bool first = reference.empty();
      for (int i = 0; i < ray_count; ++i) {
        TraceCounts c = trace(tree, tris, origins[i], dirs[i]);
        nodes += c.nodes;
        tested += c.triangles;
        if (first) {
          reference.push_back(c.t);
        } else if (!same_hit(c.t, reference[i])) {
          if (wrong < 3) std::fprintf(stderr, "%s %s ray %d: t %.9g, ours %.9g\n", name.c_str(), b.name, i, c.t, reference[i]);
          ++wrong;
        }
      }
      if (first) {  // our traversal against every triangle, for a few rays
        for (int i = 0; i < std::min(ray_count, 64); ++i) {
          float t = brute_force(tris, origins[i], dirs[i]);
          if (!same_hit(t, reference[i])) {
            std::fprintf(stderr, "%s ours ray %d: t %.9g, brute force %.9g\n", name.c_str(), i, reference[i], t);
            ++wrong;
          }
        }
      }
      failures += wrong;
      char flat[64] = "";
      if (median(flatten_seconds[k]) > 0) std::snprintf(flat, sizeof flat, " (flatten %.3f)", median(flatten_seconds[k]));
      std::printf("| %s | %s | %zu | %.3f%s | %zu | %zu | %d | %.2f | %.1f | %.1f | %zu | %d |\n", name.c_str(), b.name,
                  tris.size(), median(seconds[k]), flat, stats.nodes, stats.leaves, stats.depth, stats.sah_cost,
                  nodes / ray_count, tested / ray_count, tree.order.size(), wrong);
      std::fflush(stdout);
    }
  }
  rtcReleaseDevice(device);
  return failures == 0 ? 0 : 1;
}

// The geometry module's interface to the rest of the renderer: the closest hit of a
// ray, and the surface and material of a hit, whatever the primitive kind. A new
// kind of primitive is a header beside sphere.hpp and triangle.hpp, a case in each
// switch here, and its bounds in the host's scene builder; no kernel changes.
//
// The scene accessor `g` (SceneView, or the constant-memory scene) provides
// node_count(), node(i), instance(i), sphere(i), sphere_material(i), triangle(i),
// triangle_shading(i), triangle_material(i), normal(i) and uv(i).
#pragma once

#include <type_traits>

#include "wavetrace/geometry/alpha.hpp"
#include "wavetrace/geometry/bvh.hpp"
#include "wavetrace/geometry/instance.hpp"
#include "wavetrace/geometry/sphere.hpp"
#include "wavetrace/geometry/triangle.hpp"

namespace wt {

// The stack entry that marks the return from an instance's BVH to the top level.
constexpr int kReturnToWorld = -1;

// Sets of primitive kinds, one bit each. A kernel compiled for the kinds a scene
// holds carries no code, and no registers, for the others: the traversal's live
// state for triangles would otherwise cost sphere-only scenes occupancy. Every
// choice gives the same hits.
constexpr uint32_t kind_bit(PrimitiveKind k) { return 1u << static_cast<uint32_t>(k); }
constexpr uint32_t kSpheresOnly = kind_bit(PrimitiveKind::Sphere);
constexpr uint32_t kAllKinds = kind_bit(PrimitiveKind::Sphere) | kind_bit(PrimitiveKind::Triangle);

// Not a primitive kind: a kernel compiled with light sampling (path.hpp). Scenes
// without emitters, and renders with it off, run kernels without its code and
// registers.
constexpr uint32_t kLightSampling = 1u << 31;

// Not a primitive kind either: a kernel compiled with the microfacet BSDFs
// (conductor, glass, plastic: bsdf.hpp) and the texture features beyond the study's
// (mip-mapped lookups, textured emission, normal maps). Scenes of the study's
// materials and lookups alone run kernels without their code, which would cost the
// megakernel 5% on seed57 for the BSDFs, and half its speed with the textures, in
// registers and instructions it never runs.
constexpr uint32_t kMicrofacet = 1u << 30;
// Not a primitive kind either: a kernel compiled with the features of authored
// assets past the microfacet BSDFs: alpha-tested triangles (glTF's MASK and BLEND)
// in the traversal, and principled's clear coat, transmission and volume in the
// shading. A scene selects it only when it holds one of them (Scene::kernel_kinds),
// and then always with kMicrofacet: compiled into every microfacet kernel, the
// alpha test and the layers slowed materials.json's megakernel (which has neither)
// by 18%, in spills of registers its paths never use.
constexpr uint32_t kLayersAndAlpha = 1u << 29;
constexpr uint32_t kAlphaTested = kLayersAndAlpha;

// Whether a kernel compiled for `kinds` serves spheres alone.
constexpr bool spheres_only(uint32_t kinds) {
  return (kinds & ~(kLightSampling | kMicrofacet | kLayersAndAlpha)) == kSpheresOnly;
}

// The one choice of kernel by a scene's kinds and its feature bits (host side):
// calls f with the set a kernel is compiled for, as a std::integral_constant:
// spheres alone or all kinds; with light sampling or without; with the study's
// materials alone, the microfacet BSDFs, or those with the layers and alpha. A
// kernel that never samples lights or shades (intersect) says Lights = false and
// Microfacet = false, and is compiled four times (primitives, alpha or not), not
// twelve. A scene's layers-and-alpha bit comes with its microfacet bit, so kernels
// with both template flags never compile layers without the microfacet BSDFs.
template <bool Lights = true, bool Microfacet = true, bool Layers = true, class F>
inline void with_kinds(uint32_t scene_kinds, F&& f) {
  constexpr uint32_t kLights = Lights ? kLightSampling : 0u, kFacets = Microfacet ? kMicrofacet : 0u;
  constexpr uint32_t kLayers = Layers ? kLayersAndAlpha : 0u;
  const bool lights = Lights && (scene_kinds & kLightSampling) != 0;
  const bool layers = Layers && (scene_kinds & kLayersAndAlpha) != 0;
  const bool facets = Microfacet && (scene_kinds & (kMicrofacet | kLayersAndAlpha)) != 0;
  auto with_flags = [&](auto primitives) {
    constexpr uint32_t p = decltype(primitives)::value;
    auto with_lights = [&](auto features) {
      constexpr uint32_t q = p | decltype(features)::value;
      if (lights) {
        f(std::integral_constant<uint32_t, q | kLights>{});
      } else {
        f(std::integral_constant<uint32_t, q>{});
      }
    };
    if (layers) {
      with_lights(std::integral_constant<uint32_t, kFacets | kLayers>{});
    } else if (facets) {
      with_lights(std::integral_constant<uint32_t, kFacets>{});
    } else {
      with_lights(std::integral_constant<uint32_t, 0u>{});
    }
  };
  if (spheres_only(scene_kinds)) {
    with_flags(std::integral_constant<uint32_t, kSpheresOnly>{});
  } else {
    with_flags(std::integral_constant<uint32_t, kAllKinds>{});
  }
}

// Tests the `count` primitives from `first` of an instance of `kind`, narrowing `hit`.
template <uint32_t Kinds, class Geometry>
WT_HD WT_INLINE void intersect_leaf(const Geometry& g, PrimitiveKind kind, int instance, int first, int count,
                                    const Ray& ray, const TriangleRay& tr, Hit& hit) {
  for (int prim = first; prim < first + count; ++prim) {
    float t, b1 = 0.0f, b2 = 0.0f;
    bool found = false;
    switch (kind) {
      case PrimitiveKind::Sphere: {
        const SphereGeom s = g.sphere(prim);
        found = intersect_sphere(ray, vec3(s.x, s.y, s.z), s.w, kSphereTMin, hit.t, t);
        break;
      }
      case PrimitiveKind::Triangle:
        if (Kinds & kind_bit(PrimitiveKind::Triangle)) {
          const TriangleGeom tri = g.triangle(prim);
          found = intersect_triangle(tri, ray.origin, tr, hit.t, t, b1, b2);
          // (The object-space ray: the same for every kernel.)
          if ((Kinds & kAlphaTested) && found && tri.alpha != 0u) {
            found = alpha_lets_hit(g, tri.alpha, instance, prim, b1, b2, ray);
          }
        }
        break;
    }
    if (found) hit = Hit{t, instance, prim, b1, b2};
  }
}

// The closest hit along `world` before tmax. The top-level BVH's leaves are single
// instances; entering one moves the ray into the instance's object space (where t
// measures the same distances: the direction is transformed, not renormalised) and
// pushes the mark of the way back.
//
// AnyHit: return the first hit found (not the closest): enough to know that the
// segment to tmax is blocked, which is what a shadow ray asks.
template <uint32_t Kinds = kAllKinds | kAlphaTested, bool AnyHit = false, class Geometry>
WT_HD Hit intersect_closest(const Geometry& g, const Ray& world, float tmax) {
  Hit hit{tmax, -1, -1, 0.0f, 0.0f};
  if (g.node_count() == 0) return hit;
  // Only triangle instances are ever transformed (spheres stand untransformed), and
  // only triangles need the slab test's round-up (spheres' boxes are padded).
  constexpr bool kTriangles = (Kinds & kind_bit(PrimitiveKind::Triangle)) != 0;
  Ray ray = world;
  vec3 inv = slab_inverse(world.dir);
  TriangleRay tr{};
  int instance = -1;
  PrimitiveKind kind = PrimitiveKind::Sphere;
  // Spheres alone stand in one instance: the top level is a single leaf, and the
  // stack holds the return mark and one tree's deferred nodes.
  constexpr int kStack = kTriangles ? kBvhStackSize : kMaxBvhDepth + 1;
  int stack[kStack];
  float stack_t[kStack];
  int top = 0;
  // The node in hand: its record came with its sibling's when their parent was
  // visited, so a step down costs one fetch (the two children), not two.
  BvhNode n = g.node(0);
  for (;;) {
    if (n.count > 0 && instance < 0) {
      instance = n.left_or_first;
      const Instance& in = g.instance(instance);
      kind = in.kind;
      if (kTriangles && !in.identity) {
        ray.origin = in.object_from_world.point(world.origin);
        ray.dir = in.object_from_world.vector(world.dir);
        inv = slab_inverse(ray.dir);
      }
      if (kTriangles && kind == PrimitiveKind::Triangle) tr = triangle_ray(ray.dir);
      if (top < kStack) {
        stack[top] = kReturnToWorld;
        stack_t[top++] = 0.0f;
      }
      n = g.node(in.root);
      continue;
    }
    if (n.count > 0) {
      intersect_leaf<Kinds>(g, kind, instance, n.left_or_first, n.count, ray, tr, hit);
      if (AnyHit && hit.prim >= 0) return hit;
    } else {
      const int a = n.left_or_first;
      const BvhNode na = g.node(a), nb = g.node(a + 1);
      const float ta = box_entry<kTriangles>(na, ray.origin, inv, hit.t);
      const float tb = box_entry<kTriangles>(nb, ray.origin, inv, hit.t);
      const bool a_first = ta <= tb;
      const float t_near = a_first ? ta : tb, t_far = a_first ? tb : ta;
      if (t_near <= hit.t) {
        if (t_far <= hit.t && top < kStack) {
          stack[top] = a_first ? a + 1 : a;
          stack_t[top++] = t_far;
        }
        n = a_first ? na : nb;
        continue;
      }
    }
    // Pop, skipping nodes whose boxes the closest hit so far already passed.
    bool found = false;
    while (top > 0) {
      --top;
      if (stack[top] == kReturnToWorld) {
        if (kTriangles) {
          ray = world;
          inv = slab_inverse(world.dir);
        }
        instance = -1;
        continue;
      }
      if (stack_t[top] <= hit.t) {
        n = g.node(stack[top]);
        found = true;
        break;
      }
    }
    if (!found) break;
  }
  return hit;
}

// The material a hit shades with: the instance's override, or the primitive's own.
template <uint32_t Kinds = kAllKinds, class Geometry>
WT_HD WT_INLINE uint32_t material_index(const Geometry& g, const Hit& hit) {
  if (spheres_only(Kinds)) return g.sphere_material(hit.prim);  // spheres take no override
  const Instance& in = g.instance(hit.instance);
  if (in.material >= 0) return static_cast<uint32_t>(in.material);
  switch (in.kind) {
    case PrimitiveKind::Sphere:
      return g.sphere_material(hit.prim);
    case PrimitiveKind::Triangle:
      return g.triangle_material(hit.prim);
  }
  return 0;
}

// A triangle's surface: the point from the barycentric weights (more precise than
// the ray's t) with its error bound carried into world space, the geometric normal,
// and the shading normal and UVs where the mesh has them. The geometric normal is
// turned to the shading normal's side, so that "outward" is what the mesh's normals
// say it is whatever the winding.
// Tangents: with the tangent frame's dp/du, dp/dv and handedness (what normal maps and
// anisotropy need: kernels with kMicrofacet), or without (dpdu the first edge).
template <bool Tangents = true, class Geometry>
WT_HD WT_INLINE SurfacePoint triangle_surface(const Geometry& g, const Instance& in, const Ray& ray, const Hit& hit) {
  const TriangleGeom tri = g.triangle(hit.prim);
  SurfacePoint sp;
  vec3 error;
  const vec3 p = triangle_point(tri, hit.b1, hit.b2, error);
  const vec3 ng = glm::cross(tri.corner(1) - tri.corner(0), tri.corner(2) - tri.corner(0));
  if (in.identity) {
    sp.p = p;
    sp.ng = glm::normalize(ng);
  } else {
    const Affine& m = in.world_from_object;
    sp.p = m.point(p);
    error = (1.0f + rounding_gamma(3)) * m.abs_vector(error) +
            rounding_gamma(3) * (m.abs_vector(glm::abs(p)) + m.abs_translation());
    sp.ng = glm::normalize(in.object_from_world.transposed_vector(ng));
  }
  sp.local = p;
  const TriangleShading sh = g.triangle_shading(hit.prim);
  const float b0 = 1.0f - hit.b1 - hit.b2;
  sp.n = sp.ng;
  if (sh.flags & kTriangleHasNormals) {
    vec3 n = b0 * g.normal(sh.vertex[0]) + hit.b1 * g.normal(sh.vertex[1]) + hit.b2 * g.normal(sh.vertex[2]);
    if (!in.identity) n = in.object_from_world.transposed_vector(n);
    const float len2 = glm::dot(n, n);
    if (len2 > 0.0f) {
      sp.n = n * (1.0f / sqrtf(len2));
      if (glm::dot(sp.n, sp.ng) < 0.0f) sp.ng = -sp.ng;
    }
  }
  const vec3 e1 = tri.corner(1) - tri.corner(0), e2 = tri.corner(2) - tri.corner(0);
  vec3 dpdu = e1, dpdv = e2;
  if (sh.flags & kTriangleHasUvs) {
    const vec2 t0 = g.uv(sh.vertex[0]), t1 = g.uv(sh.vertex[1]), t2 = g.uv(sh.vertex[2]);
    sp.uv = b0 * t0 + hit.b1 * t1 + hit.b2 * t2;
    // dp/du and dp/dv from p(u, v) over the triangle: solve the UV deltas of the two
    // edges; and the UV density that picks a texture's mip level, sqrt(UV area /
    // world area). (Both only where kernels read them: Tangents.)
    if constexpr (Tangents) {
      const vec2 d1 = t1 - t0, d2 = t2 - t0;
      const float det = d1.x * d2.y - d1.y * d2.x;  // twice the UV area, signed
      const vec3 area = in.identity ? ng
                                    : glm::cross(in.world_from_object.vector(e1), in.world_from_object.vector(e2));
      const float area2 = glm::dot(area, area);
      sp.uv_density = area2 > 0.0f ? sqrtf(fabsf(det) / sqrtf(area2)) : 0.0f;
      if (det != 0.0f) uv_derivatives(e1, e2, d1, d2, det, dpdu, dpdv);
    }
  } else {
    sp.uv = vec2(hit.b1, hit.b2);
  }
  sp.tangent_sign = 1.0f;
  if constexpr (Tangents) {
    // The mesh's per-vertex tangents where it has them (a file's, or built from
    // the UVs as MikkTSpace builds them: build_tangents), interpolated; their
    // handedness is the face's, mirrored again by a mirroring instance.
    float vertex_sign = 0.0f;
    if (sh.flags & kTriangleHasTangents) {
      const uint32_t s = (sh.flags & kTriangleTangentFlipped) ? 1u : 0u;
      const vec3 t = b0 * g.tangent(2u * sh.vertex[0] + s) + hit.b1 * g.tangent(2u * sh.vertex[1] + s) +
                     hit.b2 * g.tangent(2u * sh.vertex[2] + s);
      if (glm::dot(t, t) > 0.0f) {
        dpdu = t;
        vertex_sign = s ? -1.0f : 1.0f;
        if (!in.identity && affine_determinant(in.world_from_object) < 0.0f) vertex_sign = -vertex_sign;
      }
    }
    if (!in.identity) {
      dpdu = in.world_from_object.vector(dpdu);
      dpdv = in.world_from_object.vector(dpdv);
    }
    sp.tangent_sign = vertex_sign != 0.0f ? vertex_sign : uv_handedness(sp.n, dpdu, dpdv);
  }
  sp.dpdu = dpdu;
  sp.has_uv = true;
  sp.front = glm::dot(ray.dir, sp.ng) < 0.0f;
  // The point's error along the normal, and the rounding of adding the offset to it
  // (half an ulp of each coordinate, bounded by 2^-23 |p| with margin).
  sp.offset = glm::dot(glm::abs(sp.ng), error + 1.1920929e-7f * glm::abs(sp.p));
  return sp;
}

// The surface at a hit of `ray` (in world space).
template <uint32_t Kinds = kAllKinds, class Geometry>
WT_HD WT_INLINE SurfacePoint surface_at(const Geometry& g, const Ray& ray, const Hit& hit) {
  if (spheres_only(Kinds)) return sphere_surface(g.sphere(hit.prim), ray, hit.t);
  const Instance& in = g.instance(hit.instance);
  switch (in.kind) {
    case PrimitiveKind::Sphere:
      return sphere_surface(g.sphere(hit.prim), ray, hit.t);
    case PrimitiveKind::Triangle:
      return triangle_surface<(Kinds & kMicrofacet) != 0>(g, in, ray, hit);
  }
  return sphere_surface(g.sphere(hit.prim), ray, hit.t);
}

// A triangle of an instance, in world space.
WT_HD WT_INLINE void world_triangle(const TriangleGeom& t, const Instance& in, vec3& a, vec3& b, vec3& c) {
  a = t.corner(0);
  b = t.corner(1);
  c = t.corner(2);
  if (!in.identity) {
    a = in.world_from_object.point(a);
    b = in.world_from_object.point(b);
    c = in.world_from_object.point(c);
  }
}

}  // namespace wt

#pragma once

#include "wavetrace/config.hpp"

namespace wt {

struct Ray {
  vec3 origin;
  vec3 dir;  // unit length everywhere in the renderer

  WT_HD vec3 at(float t) const { return origin + t * dir; }
};

// The closest intersection found along a ray: which primitive of which instance,
// and where on it (the barycentric weights of corners 1 and 2 of a triangle).
struct Hit {
  float t;
  int32_t instance;  // < 0: a miss
  int32_t prim;      // an index into the arrays of the instance's primitive kind
  float b1, b2;

  WT_HD bool missed() const { return instance < 0; }
};

}  // namespace wt

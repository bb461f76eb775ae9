#pragma once

#include "wavetrace/config.hpp"

namespace wt {

struct Ray {
  vec3 origin;
  vec3 dir;  // unit length everywhere in the renderer

  WT_HD vec3 at(float t) const { return origin + t * dir; }
};

// The closest intersection found along a ray; sphere < 0 means a miss.
struct Hit {
  float t;
  int32_t sphere;
};

}  // namespace wt

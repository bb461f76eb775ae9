// Common definitions for code compiled both by the host compiler and by nvcc.
#pragma once

#include <cstdint>

#if defined(__CUDACC__)
#define WT_HD __host__ __device__
#define WT_INLINE __forceinline__
#else
#define WT_HD
#define WT_INLINE inline
#endif

// GLM's defaulted special members trigger nvcc diagnostic 20012 ("__host__ annotation
// ignored on a defaulted function"). It is harmless, so it is silenced for the GLM
// headers alone and restored for everything after them.
#if defined(__CUDACC__)
#pragma nv_diagnostic push
#pragma nv_diag_suppress 20012
#endif
#define GLM_FORCE_XYZW_ONLY
#include <glm/glm.hpp>
#if defined(__CUDACC__)
#pragma nv_diagnostic pop
#endif

namespace wt {

using glm::vec3;
using glm::vec2;
using glm::vec4;

constexpr float kPi = 3.14159265358979323846f;

}  // namespace wt

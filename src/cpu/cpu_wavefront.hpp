#pragma once

#include "render/renderer.hpp"

namespace wt::cpu {

// The wavefront on host threads: the same per-item stage functions as the GPU's,
// with the standard library's sort and copy_if in place of CUB's.
RenderResult render_wavefront(const SceneView& scene, const RenderOptions& options);

}  // namespace wt::cpu

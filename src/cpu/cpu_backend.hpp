// The CPU backend: the megakernel and the wavefront on host threads.
#pragma once

#include "render/render_types.hpp"
#include "scene/scene.hpp"

namespace wt::cpu {

// Renders on host threads; the result holds pixel sums (render/renderer.hpp divides).
RenderResult render(const Scene& scene, const RenderOptions& options);

}  // namespace wt::cpu

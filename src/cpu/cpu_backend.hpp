#pragma once

#include "render/renderer.hpp"

namespace wt::cpu {

RenderResult render(const Scene& scene, const RenderOptions& options);

}  // namespace wt::cpu

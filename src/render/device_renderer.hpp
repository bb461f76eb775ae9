// What a backend gives the split (dispatch/split.hpp) for each device of a render
// over several: a leaf, so that the backends make renderers without knowing the
// split that drives them.
#pragma once

#include <cstddef>
#include <functional>
#include <utility>

#include "render/render_types.hpp"

namespace wt {

// What renders one device's chunks: made on that device's own thread (where it may
// upload the scene), then called on it with each chunk's options. `render` returns
// the chunk's pixel sums (Radiance::SumOfSamples) and its counts. A device that can
// keep sums of its own (a GPU, in its memory) also has `render_kept`, which adds the
// chunk's sums to them and returns its counts alone, `collect`, which brings them
// back once at the end, and may have `prepare`, which sets up both the kept sums and
// the host memory they come back to before the render's clock starts.
using ChunkRenderer = std::function<RenderResult(const RenderOptions& chunk)>;
// A device's sums on the host: `size` floats, owned by the device's renderer and
// valid until it is destroyed.
struct FilmSums {
  const float* data = nullptr;
  size_t size = 0;
};
struct DeviceRenderer {
  DeviceRenderer(ChunkRenderer r, ChunkRenderer kept = {}, std::function<FilmSums()> c = {},
                 std::function<void(const RenderOptions&)> p = {})
      : render(std::move(r)), render_kept(std::move(kept)), collect(std::move(c)), prepare(std::move(p)) {}
  ChunkRenderer render;
  ChunkRenderer render_kept;                        // may be empty
  std::function<FilmSums()> collect;               // with render_kept
  std::function<void(const RenderOptions&)> prepare;  // with render_kept; may be empty
};
// Device `i` (of the render's devices)'s renderer, called on that device's thread.
using MakeChunkRenderer = std::function<DeviceRenderer(size_t device)>;

}  // namespace wt

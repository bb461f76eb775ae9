// One render over several devices (the GPUs of a host, or host "devices" of the CPU
// backend): its samples are cut into chunks (the passes the render would make on one
// device), handed to the devices as they free up, so that a faster or less busy
// device takes more of them. Each device keeps its chunks' sums and the devices'
// sums are added in device order; where after_pass must see the film after every
// chunk, the chunks are folded into the film in their order instead. The wavefront
// kernels, where no after_pass watches, share the render's paths instead: each
// device renders all the samples but traces only the blocks of paths it takes from
// one PathFeed, so that its wave refills across blocks and drains once, at the end,
// rather than once a chunk. The counter-based random numbers make a path's value
// independent of where it runs, so the image is the one-device image up to the
// order of float additions.
//
// The dispatcher (dispatch/renderer.cpp) calls it with the backend's renderer of
// each device (render/device_renderer.hpp); no backend calls it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "render/passes.hpp"

#include "render/device_renderer.hpp"
#include "render/render_types.hpp"

namespace wt {

// Chunks a device gets at least, on average: enough for a faster device to take more.
constexpr int kChunksPerDevice = 4;
// At least as many chunks as the CUDA megakernel makes passes on one device: for two
// devices the chunks are its passes (progress then moves as often as on one device).
constexpr int kMinChunks = 10;

// Renders `options` over the devices `labels` names (one worker thread each). The
// result's shares say what each device did; its seconds run from when every device
// has its scene, its warm-up renders and the memory its sums need, to the film that
// adds every device's sums (as one device's seconds end with its sums in its memory,
// before the film comes back; freeing each device's memory comes after). A device
// that fails stops the others after their current chunk, and the render throws its
// error, named after the device; no partial result is returned.
RenderResult render_split(const RenderOptions& options, const std::vector<std::string>& labels,
                          const MakeChunkRenderer& make);

// [first, first + count) cut into one range for each weight, in order, each of a size
// in proportion to its weight (rounded so that the ranges tile it exactly).
std::vector<SamplePass> weighted_ranges(int32_t first, int32_t count, const std::vector<double>& weights);

// The pixels of `cut`, a range of positions in `listed` (adaptive sampling's pixels
// still going), or of every pixel where none are listed (positions are pixels then).
std::vector<uint32_t> pixel_run(const std::vector<uint32_t>* listed, const SamplePass& cut);

// The devices of one adaptive render (render/adaptive.hpp), kept ready across its
// rounds: each on a thread of its own, with the renderer `make` made there (its
// scene uploaded once). Each round cuts the pixels it names (options.active_pixels,
// or every pixel) into one run of consecutive pixels for each device, in proportion
// to the devices' speeds in the round before (equal at first), renders the runs at
// once and returns the sums of every pixel (Radiance::SumOfSamples) with each
// device's share. A pixel's samples are all rendered by one device, in the order one
// device renders them, so that the image is the one-device image whatever the cut.
// A device that fails fails the round, with its error named after the device.
class PixelSplit {
 public:
  PixelSplit(const RenderOptions& options, const std::vector<std::string>& labels, const MakeChunkRenderer& make);
  ~PixelSplit();
  PixelSplit(const PixelSplit&) = delete;
  PixelSplit& operator=(const PixelSplit&) = delete;
  RenderResult render(const RenderOptions& round);

 private:
  struct Workers;
  std::unique_ptr<Workers> workers_;
};

}  // namespace wt

// A render's image finished on the device it was rendered on (cuda_backend.hpp's
// render_image, which dispatch's render_to_device calls): each pixel's mean made there,
// so that an image handed over in device memory (the Python module's device="cuda")
// never crosses to the host, and one brought back crosses once, into page-locked memory
// kept for the next.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>

namespace wt::cuda {

// Each pixel's mean as RGBA (4 floats a pixel, alpha 1, row 0 the top), rendered on
// CUDA device `device`, in memory the image owns (freed, or given back to its pool,
// when the last owner lets go): that device's memory, or page-locked host memory
// where the caller asked for it (ImageMemory); and how many pixels hold a value that
// is not finite.
struct DeviceImage {
  std::shared_ptr<float> rgba;
  int device = 0;
  uint64_t nonfinite_pixels = 0;
};

// Memory for the `floats` values of a DeviceImage, which the device writes: page-locked
// host memory (PinnedImages) for an image wanted on the host.
using ImageMemory = std::function<std::shared_ptr<float>(size_t floats)>;

// The film's sums of `samples` samples per pixel (3 floats a pixel, on the current
// device) as the image of their means: each sum times 1 / samples in single
// precision, as take_mean (dispatch/renderer.hpp) makes them on the host, so that
// the two agree bit for bit; and a pixel is counted as count_nonfinite_pixels
// (app/job.hpp) counts it. Written into `image.rgba` where the caller gave memory
// there (pixels x 4 floats): device memory, or page-locked host memory (PinnedImages),
// which the kernel writes across the bus, so that an image wanted on the host
// crosses once with no copy of its own; else into device memory it allocates.
void finish_image(const float* film, size_t pixels, int32_t samples, DeviceImage& image);

// Page-locked host memory for images brought back from a device, which the device
// writes at full speed. Allocating it costs milliseconds (a share of a short render),
// so a block whose last owner lets go is kept for the next image of its size: the
// `keep` blocks let go last are kept, older ones freed.
class PinnedImages {
 public:
  explicit PinnedImages(size_t keep = 2);
  // Memory for `floats` values: a kept block of that size, or a new one.
  std::shared_ptr<float> take(size_t floats);
  // The blocks allocated so far (kept ones reused are not counted again).
  int64_t allocations() const;

 private:
  struct Pool;
  std::shared_ptr<Pool> pool_;
};

}  // namespace wt::cuda

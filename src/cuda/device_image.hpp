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
// The image's memory may still be being written (ImageFinisher): wait() before
// reading it. It is not let go before it is written.
struct ImageWriting;
struct DeviceImage {
  std::shared_ptr<float> rgba;
  int device = 0;
  uint64_t nonfinite_pixels = 0;
  // The writing of rgba, queued on the device and not yet waited for; null once
  // waited for (or where nothing was queued).
  std::shared_ptr<ImageWriting> writing;
  // Returns once rgba holds the image; throws DeviceError naming the stage where
  // the device failed.
  void wait();
};

// Memory for the `floats` values of a DeviceImage, which the device writes: page-locked
// host memory (ImageBlocks::Memory::PageLocked) for an image wanted on the host.
using ImageMemory = std::function<std::shared_ptr<float>(size_t floats)>;

// The film's sums of `samples` samples per pixel (3 floats a pixel, on the current
// device) as the image of their means: each sum times 1 / samples in single
// precision, as take_mean (dispatch/renderer.hpp) makes them on the host, so that
// the two agree bit for bit; and a pixel is counted as count_nonfinite_pixels
// (app/job.hpp) counts it. Written into `image.rgba` (pixels x 4 floats): device
// memory, or mapped page-locked host memory, which the kernel writes across the bus,
// so that an image wanted on the host crosses once with no copy of its own. The
// count is known when finish() returns: it is made on a stream of its own, from the
// film in device memory, beside the writing, which is queued on the default stream
// (image.writing), so that neither waits for the other and the caller's own work
// (the stats, the array) goes on while a 1080p image crosses the bus, about 0.6 ms:
// image.wait() before the image is read. The film is the default stream's work:
// finish() orders both after what is queued there.
// An ImageFinisher is made on the device it finishes images of, and keeps what it
// needs from one image to the next (the count's memory, its stream and event: each
// made and freed per image costs the image's caller a share of a short render).
class ImageFinisher {
 public:
  ImageFinisher();
  ~ImageFinisher();
  ImageFinisher(const ImageFinisher&) = delete;
  ImageFinisher& operator=(const ImageFinisher&) = delete;
  void finish(const float* film, size_t pixels, int32_t samples, DeviceImage& image);

 private:
  struct Kept;
  std::unique_ptr<Kept> kept_;
};

// Memory for images, kept from one image to the next. Making a block costs a share of
// a short render (page-locked host memory, milliseconds; device memory, an allocation
// and, when it is freed, a wait for the device), so a block whose last owner lets go
// is kept for the next image of its size: the `keep` blocks let go last are kept,
// older ones freed. The blocks outlive the ImageBlocks that made them.
class ImageBlocks {
 public:
  enum class Memory {
    PageLocked,  // mapped page-locked host memory, usable from every device
    Device,      // memory of the device current when the ImageBlocks is made
  };
  explicit ImageBlocks(Memory memory, size_t keep = 2);
  // Memory for `floats` values: a kept block of that size, or a new one. A kept
  // device block is handed out once the device has done the work queued so far: a
  // consumer that let it go (torch, through DLPack) may have queued work that reads
  // it, on a stream of its own.
  std::shared_ptr<float> take(size_t floats);
  // The blocks made so far (kept ones handed out again are not counted again).
  int64_t allocations() const;

 private:
  struct Pool;
  std::shared_ptr<Pool> pool_;
};

}  // namespace wt::cuda

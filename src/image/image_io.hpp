// Writing rendered images: PNG (8-bit), PFM (linear float) or OpenEXR (linear RGBA,
// half or float), chosen by extension, always through a temporary file renamed into
// place, so a failed or interrupted write never leaves a partial image under the
// requested name.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>


namespace wt {

enum class Encoding { Srgb, Gamma2 };
// The pixel type of an OpenEXR image's channels.
enum class ExrPixels { Half, Float };

// How an image of this path's format holds a pixel that is not finite, in words: a
// PNG clamps (NaN to 0, an infinity to 255), PFM and OpenEXR keep the value.
const char* nonfinite_pixels_written(const std::string& path);

// Throws OutputError naming the path when it cannot be written (unknown extension,
// missing or unwritable folder). Run before rendering, so a bad path costs nothing.
void check_output_path(const std::string& path);

// The folder part of that check alone, for files of any kind.
void check_output_folder(const std::string& path);

// A file written in full to a temporary file beside its path (every write checked,
// then flushed to the disk and closed, so a full disk is found here and not later)
// and not yet under its name. commit() renames it into place; destroyed uncommitted,
// it removes the temporary file. A default one holds nothing and commits nothing.
class StagedFile {
 public:
  StagedFile() = default;
  ~StagedFile();
  StagedFile(StagedFile&& o) noexcept;
  StagedFile& operator=(StagedFile&& o) noexcept;
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;

  // Throws OutputWriteError naming the path (the temporary file removed).
  void commit();

 private:
  friend class FileWriter;
  void discard() noexcept;
  std::string path_, tmp_;  // tmp_ empty: nothing staged
};

// A further image written into an OpenEXR file beside the render's R, G and B (an
// AOV): its channels are "<name>.<channel>", and `values` holds width * height *
// channels.size() floats, row 0 = top.
struct ImageLayer {
  std::string name;
  std::vector<std::string> channels;
  const std::vector<float>* values;
};

// rgb: linear radiance, width * height * 3, row 0 = top. The encoding applies to PNG;
// PFM and OpenEXR keep linear values, and `exr` is the pixel type of an OpenEXR image
// (its alpha is 1), which also holds `layers` (only an OpenEXR image takes them).
// Throws OutputWriteError when the write fails.
StagedFile stage_image(const std::string& path, int width, int height, const std::vector<float>& rgb,
                       Encoding encoding, ExrPixels exr = ExrPixels::Half, const std::vector<ImageLayer>& layers = {});
// A PFM of 1 (greyscale) or 3 channels: width * height * channels floats, row 0 = top.
StagedFile stage_pfm_image(const std::string& path, int width, int height, const std::vector<float>& values,
                           int channels);
// Any bytes (a stats file's text, a checkpoint).
StagedFile stage_file(const std::string& path, const std::string& bytes);

// Stage and commit at once.
void write_image(const std::string& path, int width, int height, const std::vector<float>& rgb, Encoding encoding,
                 ExrPixels exr = ExrPixels::Half);
void write_file(const std::string& path, const std::string& bytes);

}  // namespace wt

// Writing rendered images: PNG (8-bit) or PFM (linear float), chosen by extension,
// always through a temporary file renamed into place, so a failed or interrupted
// write never leaves a partial image under the requested name.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace wt {

struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

enum class Encoding { Srgb, Gamma2 };

// Throws OutputError naming the path when it cannot be written (unknown extension,
// missing or unwritable folder). Run before rendering, so a bad path costs nothing.
void check_output_path(const std::string& path);

// The folder part of that check alone, for files of any kind.
void check_output_folder(const std::string& path);

// rgb: linear radiance, width * height * 3, row 0 = top. The encoding applies to PNG;
// PFM keeps linear values.
void write_image(const std::string& path, int width, int height, const std::vector<float>& rgb, Encoding encoding);

// Writes text to path atomically (temporary file, then rename).
void write_text_file(const std::string& path, const std::string& text);

}  // namespace wt

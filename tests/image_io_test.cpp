// PNG encoding round trip: the project's writer encodes, stb decodes, and each
// 8-bit value is the one the transfer curve gives, at its pixel.
#include <gtest/gtest.h>
#include <stb/stb_image.h>
#include <unistd.h>

#include <filesystem>
#include <vector>

#include "image/image_io.hpp"

namespace wt {
namespace {

namespace fs = std::filesystem;

std::vector<unsigned char> round_trip(const std::vector<float>& rgb, int width, int height, Encoding encoding) {
  const std::string path =
      (fs::temp_directory_path() / ("wavetrace_png_" + std::to_string(::getpid()) + ".png")).string();
  write_image(path, width, height, rgb, encoding);
  int w = 0, h = 0, channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &channels, 3);
  fs::remove(path);
  EXPECT_NE(data, nullptr) << stbi_failure_reason();
  if (!data) return {};
  EXPECT_EQ(w, width);
  EXPECT_EQ(h, height);
  EXPECT_EQ(channels, 3);
  std::vector<unsigned char> bytes(data, data + static_cast<size_t>(w) * h * 3);
  stbi_image_free(data);
  return bytes;
}

TEST(PngRoundTrip, SrgbValuesLandAtTheirPixelsAndChannels) {
  // 3 x 2 pixels, row 0 on top; the expected values are round(255 * sRGB(v)),
  // worked out by hand from the sRGB curve (clamped to [0, 1]).
  const std::vector<float> rgb = {
      0.0f, 1.0f, 0.5f,      0.18f, 0.001f, 0.05f,  0.8f, 2.0f, -1.0f,  // top row
      0.5f, 0.5f, 0.5f,      1.0f, 0.0f, 0.0f,      0.0f, 0.0f, 1.0f,   // bottom row
  };
  const std::vector<unsigned char> expected = {
      0, 255, 188,    118, 3, 63,    231, 255, 0,
      188, 188, 188,  255, 0, 0,     0, 0, 255,
  };
  EXPECT_EQ(round_trip(rgb, 3, 2, Encoding::Srgb), expected);
}

TEST(PngRoundTrip, Gamma2IsTheSquareRoot) {
  const std::vector<float> rgb = {0.25f, 0.64f, 0.09f, 1.0f, 0.0f, 4.0f};
  const std::vector<unsigned char> expected = {128, 204, 77, 255, 0, 255};  // round(255 sqrt(v)), halves up
  EXPECT_EQ(round_trip(rgb, 1, 2, Encoding::Gamma2), expected);
}

}  // namespace
}  // namespace wt

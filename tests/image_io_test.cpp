// PNG encoding round trip: the project's writer encodes, stb decodes, and each
// 8-bit value is the one the transfer curve gives, at its pixel. OpenEXR round trip:
// OpenEXR's reader gets the linear values back, half-rounded or exact, at their
// pixels. Writes that fail part way (a full disk) leave no file and no temporary file
// behind.
#include <gtest/gtest.h>
#include <stb/stb_image.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <vector>

#include "exr_support.hpp"
#include "errors/errors.hpp"
#include "image/image_io.hpp"
#include "test_support.hpp"
#include "wavetrace/film.hpp"

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

// An image large enough that its transfer curve is applied in parts on several
// threads: every value lands where it belongs, as the curve gives it on one.
TEST(PngRoundTrip, ALargeImageConvertedInPartsHoldsEveryValue) {
  const int w = 1021, h = 517;  // 1.58 M values: several parts, the last one short
  std::vector<float> rgb(static_cast<size_t>(w) * h * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<float>((i * 2654435761u) % 1000) / 900.0f;
  const std::vector<unsigned char> back = round_trip(rgb, w, h, Encoding::Srgb);
  ASSERT_EQ(back.size(), rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) {
    ASSERT_EQ(back[i], static_cast<unsigned char>(std::lround(encode_srgb(rgb[i]) * 255.0f))) << i;
  }
}

TEST(PngRoundTrip, Gamma2IsTheSquareRoot) {
  const std::vector<float> rgb = {0.25f, 0.64f, 0.09f, 1.0f, 0.0f, 4.0f};
  const std::vector<unsigned char> expected = {128, 204, 77, 255, 0, 255};  // round(255 sqrt(v)), halves up
  EXPECT_EQ(round_trip(rgb, 1, 2, Encoding::Gamma2), expected);
}

// 12 pixels (4 x 3 or 3 x 4), no two alike and no pixel grey, so that a flipped,
// mirrored or transposed image, or channels out of order, read back wrong. Values
// that half floats round (0.1, 1/3, 1000.7, 0.7), one past their range (70000:
// infinity), zero, negatives and ones below their normal range (1e-5).
std::vector<float> asymmetric_image() {
  std::vector<float> rgb(12 * 3);
  const float values[] = {0.1f, 1.0f / 3.0f, 1000.7f, 70000.0f, 0.0f, -0.25f, 1e-5f, 2.5f, 0.7f};
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = values[i % 9] * static_cast<float>(1 + i / 9);
  return rgb;
}

class ExrRoundTrip : public testing::Test {
 protected:

  // Writes the image with `pixels` and reads it back, checking what every EXR written
  // holds: its size, channels A, B, G, R (OpenEXR's order) of the one type, alpha 1.
  test::ExrImage round_trip(const std::vector<float>& rgb, int width, int height, ExrPixels pixels,
                            Imf::PixelType type) {
    const std::string out = (dir_ / "out.exr").string();
    write_image(out, width, height, rgb, Encoding::Srgb, pixels);
    test::ExrImage image = test::read_exr(out);
    EXPECT_EQ(image.width, width);
    EXPECT_EQ(image.height, height);
    EXPECT_EQ(image.channels, (std::vector<std::string>{"A", "B", "G", "R"}));
    EXPECT_EQ(image.types, std::vector<Imf::PixelType>(4, type));
    for (size_t i = 3; i < image.rgba.size(); i += 4) EXPECT_EQ(image.rgba[i], 1.0f) << "alpha of pixel " << i / 4;
    return image;
  }

  // The image's RGB at (x, y), row 0 on top, and what was written there.
  static void expect_pixels(const test::ExrImage& image, const std::vector<float>& expected, int width, int height) {
    ASSERT_EQ(image.rgba.size(), static_cast<size_t>(width) * height * 4);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        for (int c = 0; c < 3; ++c) {
          EXPECT_EQ(image.rgba[(static_cast<size_t>(y) * width + x) * 4 + c],
                    expected[(static_cast<size_t>(y) * width + x) * 3 + c])
              << "x " << x << " y " << y << " channel " << c;
        }
      }
    }
  }

  test::TestFolder folder_;
  const fs::path dir_ = folder_.root();
};

TEST_F(ExrRoundTrip, HalfIsTheDefaultAndHoldsEachValueHalfRounded) {
  const std::vector<float> rgb = asymmetric_image();
  std::vector<float> expected(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) expected[i] = test::half_rounded(rgb[i]);
  const std::string out = (dir_ / "default.exr").string();
  write_image(out, 4, 3, rgb, Encoding::Srgb);  // no pixel type given: half
  EXPECT_EQ(test::read_exr(out).types, std::vector<Imf::PixelType>(4, Imf::HALF));
  expect_pixels(round_trip(rgb, 4, 3, ExrPixels::Half, Imf::HALF), expected, 4, 3);
}

TEST_F(ExrRoundTrip, FloatHoldsEachValueExactly) {
  const std::vector<float> rgb = asymmetric_image();
  expect_pixels(round_trip(rgb, 4, 3, ExrPixels::Float, Imf::FLOAT), rgb, 4, 3);
}

TEST_F(ExrRoundTrip, TallImagesKeepTheirOrientationToo) {
  const std::vector<float> rgb = asymmetric_image();  // now 3 wide, 4 tall
  expect_pixels(round_trip(rgb, 3, 4, ExrPixels::Float, Imf::FLOAT), rgb, 3, 4);
}

TEST(OutputPath, ExrIsAnOutputFormatAndUnknownExtensionsAreNot) {
  test::TestFolder folder;
  const std::string dir = folder.root().string();
  EXPECT_NO_THROW(check_output_path(dir + "/a.exr"));
  EXPECT_NO_THROW(check_output_path(dir + "/a.EXR"));
  try {
    check_output_path(dir + "/a.tiff");
    ADD_FAILURE() << "a .tiff output was accepted";
  } catch (const OutputError& e) {
    EXPECT_EQ(std::string(e.what()), dir + "/a.tiff: unknown output format '.tiff' (use .png, .pfm or .exr)");
  }
  EXPECT_THROW(check_output_path(dir + "/no-such-folder/a.exr"), OutputError);
}

// The write run in a child process whose files may not grow past `limit` bytes (a
// full disk: test::limit_file_size). Returns the OutputWriteError's message, or what
// happened instead.
std::string write_error_with_file_size_limit(unsigned long long limit, const std::function<void()>& write) {
  return test::in_child_process([&]() -> std::string {
    if (!test::limit_file_size(limit)) return "setrlimit failed";
    try {
      write();
    } catch (const OutputWriteError& e) {
      return e.what();
    } catch (const std::exception& e) {
      return std::string("not an OutputWriteError: ") + e.what();
    }
    return "no error";
  });
}

class FullDisk : public testing::Test {
 protected:

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
    return names;
  }
  static std::string efbig(const std::string& path) { return path + ": cannot write (" + std::strerror(EFBIG) + ")"; }

  test::TestFolder folder_;
  const fs::path dir_ = folder_.root();
};

// 64 x 64 pixels of noise: a 12 KiB PNG (noise does not compress), a 48 KiB PFM.
std::vector<float> noise() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> rgb(64 * 64 * 3);
  for (float& v : rgb) v = u(rng);
  return rgb;
}

TEST_F(FullDisk, PngWriteFailsNamingTheFileAndLeavesNothing) {
  const std::string out = path("out.png");
  EXPECT_EQ(write_error_with_file_size_limit(4096, [&] { write_image(out, 64, 64, noise(), Encoding::Srgb); }),
            efbig(out));
  EXPECT_EQ(files(), std::vector<std::string>{});  // neither the image nor its temporary file
}

TEST_F(FullDisk, PfmWriteFailsNamingTheFileAndLeavesNothing) {
  const std::string out = path("out.pfm");
  EXPECT_EQ(write_error_with_file_size_limit(20000, [&] { write_image(out, 64, 64, noise(), Encoding::Srgb); }),
            efbig(out));
  EXPECT_EQ(files(), std::vector<std::string>{});
}

TEST_F(FullDisk, ExrWriteFailsNamingTheFileAndLeavesNothing) {
  for (const ExrPixels pixels : {ExrPixels::Half, ExrPixels::Float}) {
    const std::string out = path("out.exr");
    EXPECT_EQ(write_error_with_file_size_limit(4096, [&] { write_image(out, 64, 64, noise(), Encoding::Srgb, pixels); }),
              efbig(out));
    EXPECT_EQ(files(), std::vector<std::string>{});
    // Under the same limit, an image that fits is written.
    EXPECT_EQ(write_error_with_file_size_limit(4096, [&] { write_image(out, 4, 4, noise(), Encoding::Srgb, pixels); }),
              "no error");
    EXPECT_EQ(files(), std::vector<std::string>{"out.exr"});
    fs::remove(out);
  }
}

// OpenEXR refusing an image (here one with no pixels, which no render has) is an
// OutputWriteError too: one line, the file and the library's reason.
TEST_F(FullDisk, ExrWriteTheLibraryRefusesNamesTheFileAndLeavesNothing) {
  const std::string out = path("empty.exr");
  try {
    write_image(out, 0, 4, {}, Encoding::Srgb);
    ADD_FAILURE() << "an image of width 0 was written";
  } catch (const OutputWriteError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(out + ": cannot write (", 0), 0u) << message;
    EXPECT_GT(message.size(), out.size() + std::string(": cannot write ()").size()) << message;  // a reason
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  EXPECT_EQ(files(), std::vector<std::string>{});
}

TEST_F(FullDisk, TextWriteFailsNamingTheFileAndLeavesNothing) {
  const std::string out = path("stats.json");
  EXPECT_EQ(write_error_with_file_size_limit(100, [&] { write_file(out, std::string(1000, 'x')); }), efbig(out));
  EXPECT_EQ(files(), std::vector<std::string>{});
}

TEST_F(FullDisk, AFailedWriteLeavesAnEarlierFileAsItWas) {
  const std::string out = path("out.pfm");
  write_image(out, 2, 1, {1, 2, 3, 4, 5, 6}, Encoding::Srgb);
  std::ifstream before_file(out, std::ios::binary);
  const std::string before((std::istreambuf_iterator<char>(before_file)), {});
  EXPECT_EQ(write_error_with_file_size_limit(20000, [&] { write_image(out, 64, 64, noise(), Encoding::Srgb); }),
            efbig(out));
  EXPECT_EQ(files(), std::vector<std::string>{"out.pfm"});
  std::ifstream after_file(out, std::ios::binary);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(after_file)), {}), before);
}

TEST_F(FullDisk, WritesThatFitSucceedUnderTheSameLimit) {
  // The limit itself is not what fails the writes above: the same limit, a file that fits.
  const std::string out = path("out.pfm");
  EXPECT_EQ(write_error_with_file_size_limit(20000, [&] { write_image(out, 4, 4, noise(), Encoding::Srgb); }),
            "no error");
  EXPECT_EQ(files(), std::vector<std::string>{"out.pfm"});
}

}  // namespace
}  // namespace wt

// Reading an OpenEXR image back through OpenEXR's own reader, for the tests of the
// .exr output (image_io_test, job_test): what the file's header says and its pixels.
#pragma once

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <gtest/gtest.h>
#include <half.h>

#include <string>
#include <vector>

namespace wt::test {

struct ExrImage {
  int width = 0, height = 0;
  std::vector<std::string> channels;  // names, in the file's order
  std::vector<Imf::PixelType> types;  // the type of each of them
  std::vector<float> rgba;            // width * height * 4, row 0 = the data window's top
};

// A channel the file lacks reads as this, which no written value is.
constexpr float kMissingChannel = -7.0f;

// A failure is added to the test where the file cannot be read or its data window
// does not start at (0, 0) or differs from its display window.
inline ExrImage read_exr(const std::string& path) {
  ExrImage image;
  try {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    const Imath::Box2i data = header.dataWindow();
    EXPECT_EQ(data.min, Imath::V2i(0, 0)) << path;
    EXPECT_EQ(data.max, header.displayWindow().max) << path;
    if (data.min != Imath::V2i(0, 0)) return image;
    image.width = data.max.x + 1;
    image.height = data.max.y + 1;
    for (auto c = header.channels().begin(); c != header.channels().end(); ++c) {
      image.channels.push_back(c.name());
      image.types.push_back(c.channel().type);
    }
    image.rgba.assign(static_cast<size_t>(image.width) * image.height * 4, 0.0f);
    Imf::FrameBuffer frame;
    const char* const names[] = {"R", "G", "B", "A"};
    for (size_t c = 0; c < 4; ++c) {
      frame.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(image.rgba.data() + c), sizeof(float) * 4,
                                        sizeof(float) * 4 * static_cast<size_t>(image.width), 1, 1, kMissingChannel));
    }
    file.setFrameBuffer(frame);
    file.readPixels(0, data.max.y);
  } catch (const std::exception& e) {
    ADD_FAILURE() << path << ": " << e.what();
  }
  return image;
}

// What a float becomes in a half-float channel, read back as a float.
inline float half_rounded(float v) { return static_cast<float>(half(v)); }

}  // namespace wt::test

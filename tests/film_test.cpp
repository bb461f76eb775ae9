// The output curves: gamma 2 and sRGB (encode and decode), their known values,
// clamping, monotonicity and round trips.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "wavetrace/film.hpp"

namespace wt {
namespace {

TEST(Film, Gamma2IsTheClampedSquareRoot) {
  EXPECT_EQ(encode_gamma2(0.0f), 0.0f);
  EXPECT_EQ(encode_gamma2(0.25f), 0.5f);
  EXPECT_EQ(encode_gamma2(1.0f), 1.0f);
  EXPECT_NEAR(encode_gamma2(0.5f), std::sqrt(0.5), 1e-7);
  EXPECT_NEAR(encode_gamma2(0.01f), 0.1, 1e-7);
  // Out of range radiance clamps (HDR values saturate; negative noise is black).
  EXPECT_EQ(encode_gamma2(-0.3f), 0.0f);
  EXPECT_EQ(encode_gamma2(4.0f), 1.0f);
  EXPECT_EQ(encode_gamma2(std::numeric_limits<float>::infinity()), 1.0f);
  EXPECT_EQ(encode_gamma2(-std::numeric_limits<float>::infinity()), 0.0f);
}

TEST(Film, SrgbEncodeKnownValues) {
  // IEC 61966-2-1: 12.92 x below 0.0031308, 1.055 x^(1/2.4) - 0.055 above.
  EXPECT_EQ(encode_srgb(0.0f), 0.0f);
  EXPECT_NEAR(encode_srgb(1.0f), 1.0f, 1e-7f);
  EXPECT_NEAR(encode_srgb(0.001f), 0.01292f, 1e-8f);  // linear segment
  EXPECT_NEAR(encode_srgb(0.18f), 0.46135612, 1e-6);  // 18% grey
  EXPECT_NEAR(encode_srgb(0.5f), 0.73535698, 1e-6);
  EXPECT_NEAR(encode_srgb(0.0031308f), 0.04045, 1e-6);  // the knee
  // The two segments meet at the knee (the standard's constants make the curve
  // continuous to about 1e-7).
  const float knee = 0.0031308f;
  EXPECT_NEAR(encode_srgb(std::nextafter(knee, 0.0f)), encode_srgb(std::nextafter(knee, 1.0f)), 1e-6f);
}

TEST(Film, SrgbEncodeClampsToTheUnitRange) {
  EXPECT_EQ(encode_srgb(-1.0f), 0.0f);
  EXPECT_EQ(encode_srgb(-1e-6f), 0.0f);
  EXPECT_NEAR(encode_srgb(1.5f), 1.0f, 1e-7f);
  EXPECT_NEAR(encode_srgb(1e6f), 1.0f, 1e-7f);
  EXPECT_NEAR(encode_srgb(std::numeric_limits<float>::infinity()), 1.0f, 1e-7f);
  EXPECT_LE(encode_srgb(1e6f), 1.0f);
}

TEST(Film, SrgbDecodeKnownValues) {
  EXPECT_EQ(decode_srgb(0.0f), 0.0f);
  EXPECT_NEAR(decode_srgb(1.0f), 1.0f, 1e-6f);
  EXPECT_NEAR(decode_srgb(0.5f), 0.21404114, 1e-6);
  EXPECT_NEAR(decode_srgb(0.04045f), 0.0031308, 1e-7);
  EXPECT_NEAR(decode_srgb(0.02f), 0.02 / 12.92, 1e-9);
  // 8-bit code 128 (0.50196): 0.21586.
  EXPECT_NEAR(decode_srgb(128.0f / 255.0f), 0.21586050, 1e-6);
}

TEST(Film, SrgbCurvesAreMonotonicAndRoundTrip) {
  float prev_e = -1.0f, prev_d = -1.0f;
  for (int i = 0; i <= 100000; ++i) {
    float x = float(i) / 100000.0f;
    float e = encode_srgb(x), d = decode_srgb(x);
    ASSERT_GE(e, prev_e) << x;
    ASSERT_GE(d, prev_d) << x;
    prev_e = e;
    prev_d = d;
    // Round trips in both directions, to float precision of the pow involved.
    EXPECT_NEAR(decode_srgb(e), x, 2e-6f + 4e-6f * x) << x;
    EXPECT_NEAR(encode_srgb(d), x, 2e-6f + 4e-6f * x) << x;
  }
  // Every 8-bit code survives decode then encode.
  for (int c = 0; c <= 255; ++c) {
    float v = float(c) / 255.0f;
    EXPECT_EQ(int(std::lround(encode_srgb(decode_srgb(v)) * 255.0f)), c);
  }
}

}  // namespace
}  // namespace wt

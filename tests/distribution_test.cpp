// Importance sampling of the environment (include/wavetrace/distribution.hpp,
// src/scene/environment_distribution.*): the 1D sampler draws what its CDF says,
// the 2D density and the density per solid angle integrate to 1, sampled directions
// follow the density, the density of a direction is the one its sample reported,
// a sun gets its share, black texels keep a positive density, and the turn of the
// sky is respected.
//
// Uniforms come from the project's Rng with fixed keys, so every statistical test
// here is reproducible; its threshold is stated where it is used.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "scene/scene.hpp"
#include "wavetrace/rng.hpp"
#include "wavetrace/sampling.hpp"

namespace wt {
namespace {

constexpr double kPiD = 3.14159265358979323846;

Image make_image(int w, int h, const std::function<vec3(int, int)>& colour) {
  Image im;
  im.path = "test";
  im.width = w;
  im.height = h;
  im.texels.resize(static_cast<size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const vec3 c = colour(x, y);
      float* t = &im.texels[4 * (static_cast<size_t>(y) * w + x)];
      t[0] = c.x;
      t[1] = c.y;
      t[2] = c.z;
      t[3] = 1.0f;
    }
  return im;
}

// Written here from the definition (Rec. 709 Y, negative and non-finite as 0), not
// taken from the builder, so the tests check the builder's weights too.
double luminance_of(const Image& im, int x, int y) {
  const float* t = &im.texels[4 * (static_cast<size_t>(y) * im.width + x)];
  const double l = 0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2];
  return std::isfinite(l) && l > 0.0 ? l : 0.0;
}

double row_sin(int y, int h) { return std::sin(kPiD * (y + 0.5) / h); }

// The floor the builder promises: 1/1000 of the mean luminance per solid angle.
double expected_floor(const Image& im) {
  double weighted = 0.0, total = 0.0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      weighted += luminance_of(im, x, y) * row_sin(y, im.height);
      total += row_sin(y, im.height);
    }
  return weighted > 0.0 ? 1e-3 * weighted / total : 1.0;
}

// Each texel's probability: max(luminance, floor) x its solid angle, normalised.
std::vector<double> expected_probabilities(const Image& im) {
  const double floor = expected_floor(im);
  std::vector<double> p(static_cast<size_t>(im.width) * im.height);
  double sum = 0.0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x)
      sum += p[static_cast<size_t>(y) * im.width + x] = std::max(luminance_of(im, x, y), floor) * row_sin(y, im.height);
  for (double& v : p) v /= sum;
  return p;
}

Sky environment_sky(double turn_degrees) {
  Sky sky{SkyKind::Environment, vec3(0.0f), vec3(0.0f)};
  sky.image = 0;
  sky.turn_cos = static_cast<float>(std::cos(turn_degrees * kPiD / 180.0));
  sky.turn_sin = static_cast<float>(std::sin(turn_degrees * kPiD / 180.0));
  return sky;
}

// Two uniforms for sample i of stream `seed`.
void uniforms(uint32_t seed, int i, float& a, float& b) {
  const Rng rng = Rng::at(seed, static_cast<uint32_t>(i), 0, 0);
  a = rng.uniform(0);
  b = rng.uniform(1);
}

struct Texel {
  int x, y;
  bool operator==(const Texel& o) const { return x == o.x && y == o.y; }
};

// The texel the sky's lookup reads (the nearest centre: the cell of sample_image).
Texel texel_of(const Sky& sky, const vec3& d, int w, int h) {
  const vec2 uv = sky.environment_uv(d);
  const float u = uv.x - std::floor(uv.x);
  return Texel{std::min(static_cast<int>(u * w), w - 1), std::min(static_cast<int>(uv.y * h), h - 1)};
}

// Whether (u, v) lies within 1e-4 of a cell's width or height of a cell edge: there
// the float round trip uv -> direction -> uv (errors of about 1e-7 in u and v) may
// cross into the neighbour.
bool near_cell_edge(const vec2& uv, int w, int h) {
  const auto near = [](double t) { return std::fabs(t - std::round(t)) < 1e-4; };
  return near(double(uv.x) * w) || near(double(uv.y) * h);
}

// An image with every feature the sampler must handle: smooth variation, a bright
// spot, a black patch (12 texels, kept by the floor), and colours whose luminance
// differs from their mean (pure green and pure blue columns).
Image varied_image() {
  return make_image(32, 16, [](int x, int y) {
    if (x >= 4 && x < 8 && y >= 3 && y < 6) return vec3(0.0f);
    if (x == 20 && y == 6) return vec3(40.0f);
    const float base = 1.0f + 0.8f * std::sin(0.5f * x) * std::cos(0.9f * y);
    if (x % 5 == 0) return vec3(0.0f, base, 0.0f);
    if (x % 7 == 0) return vec3(0.0f, 0.0f, base);
    return vec3(base);
  });
}

// ---------------------------------------------------------------------------------
// The 1D distribution.

// Weights 1, 3, 2, 2: every CDF value (k/8) is exact in float, so the cells, the
// places within them and the densities are exact too.
TEST(Distribution1D, SamplesAKnownCdf) {
  const std::vector<float> cdf = piecewise_constant_cdf({1.0, 3.0, 2.0, 2.0});
  ASSERT_EQ(cdf, (std::vector<float>{0.0f, 0.125f, 0.5f, 0.75f, 1.0f}));
  const PiecewiseConstant1D d{cdf.data(), 4};
  const float pdfs[] = {0.5f, 1.5f, 1.0f, 1.0f};  // 4 cells x their probability
  struct Case {
    float u, x;
    int index;
  };
  for (const Case& c : {Case{0.0f, 0.0f, 0}, Case{0.0625f, 0.125f, 0}, Case{0.125f, 0.25f, 1},
                        Case{0.3125f, 0.375f, 1}, Case{0.5f, 0.5f, 2}, Case{0.625f, 0.625f, 2},
                        Case{0.75f, 0.75f, 3}, Case{0.875f, 0.875f, 3}}) {
    const Sample1D s = d.sample(c.u);
    EXPECT_EQ(s.index, c.index) << c.u;
    EXPECT_EQ(s.x, c.x) << c.u;
    EXPECT_EQ(s.pdf, pdfs[c.index]) << c.u;
    EXPECT_EQ(d.pdf(s.x), s.pdf) << c.u;
  }
  const Sample1D last = d.sample(kOneMinusEpsilon);
  EXPECT_EQ(last.index, 3);
  EXPECT_LT(last.x, 1.0f);
  // The map from u to x is increasing, and each x lies in the cell it reports.
  float previous = -1.0f;
  for (int i = 0; i < 4096; ++i) {
    const Sample1D s = d.sample(i / 4096.0f);
    EXPECT_GE(s.x, previous) << i;
    EXPECT_EQ(d.cell_of(s.x), s.index) << i;
    previous = s.x;
  }
}

// A cell whose weight is below float resolution beside a huge one still gets a
// positive width (one float step), can be drawn (u = its lower CDF value lands in
// it) and has a positive density; the probability moved to such cells is at most
// one float step below 1 (2^-24) per cell.
TEST(Distribution1D, TinyCellsNextToHugeOnesKeepAPositiveWidth) {
  const int n = 1000;
  std::vector<double> weights(n, 1.0);
  weights[1] = 1e12;
  const std::vector<float> cdf = piecewise_constant_cdf(weights);
  ASSERT_EQ(cdf.size(), size_t(n + 1));
  EXPECT_EQ(cdf.front(), 0.0f);
  EXPECT_EQ(cdf.back(), 1.0f);
  const PiecewiseConstant1D d{cdf.data(), n};
  double total = 0.0;
  for (int i = 0; i < n; ++i) {
    ASSERT_LT(cdf[i], cdf[i + 1]) << i;
    EXPECT_GT(d.cell_pdf(i), 0.0f) << i;
    EXPECT_EQ(d.sample(cdf[i]).index, i) << i;
    total += double(cdf[i + 1]) - double(cdf[i]);
  }
  EXPECT_NEAR(total, 1.0, 1e-12);
  EXPECT_NEAR(double(cdf[2]) - double(cdf[1]), 1e12 / (1e12 + n - 1), n * std::ldexp(1.0, -24));
}

TEST(Distribution1D, RefusesWeightsWithoutAPositiveSum) {
  EXPECT_THROW(piecewise_constant_cdf({}), std::invalid_argument);
  EXPECT_THROW(piecewise_constant_cdf({0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(piecewise_constant_cdf({1.0, -1.0}), std::invalid_argument);
  EXPECT_THROW(piecewise_constant_cdf({1.0, std::nan("")}), std::invalid_argument);
}

// ---------------------------------------------------------------------------------
// The 2D distribution.

// The density is constant on each cell, so a midpoint sum over a grid of 10 x 10
// points per cell is its exact integral up to rounding: the widths of the float CDF
// cells sum to 1 exactly, and each float density is within a few 1e-7 relatively.
// Tolerance 1e-5.
TEST(Distribution2D, PdfIntegratesToOne) {
  const EnvironmentDistribution table = build_environment_distribution(varied_image());
  const PiecewiseConstant2D d = table.view();
  const int nu = 10 * d.columns, nv = 10 * d.rows;
  double sum = 0.0;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) sum += d.pdf(static_cast<float>((i + 0.5) / nu), static_cast<float>((j + 0.5) / nv));
  EXPECT_NEAR(sum / (double(nu) * nv), 1.0, 1e-5);
}

// The sample's (u, v) lies in the cell it names, and pdf(u, v) is its density.
TEST(Distribution2D, SampleReportsItsCellAndDensity) {
  const EnvironmentDistribution table = build_environment_distribution(varied_image());
  const PiecewiseConstant2D d = table.view();
  for (int i = 0; i < 20000; ++i) {
    float a, b;
    uniforms(7, i, a, b);
    const Sample2D s = d.sample(a, b);
    ASSERT_GE(s.u, 0.0f);
    ASSERT_LT(s.u, 1.0f);
    ASSERT_GE(s.v, 0.0f);
    ASSERT_LT(s.v, 1.0f);
    EXPECT_EQ(d.marginal().cell_of(s.v), s.row) << i;
    EXPECT_EQ(d.conditional(s.row).cell_of(s.u), s.column) << i;
    EXPECT_EQ(d.pdf(s.u, s.v), s.pdf) << i;
  }
}

// ---------------------------------------------------------------------------------
// The environment.

// The table: one cell per texel, each with the probability expected_probabilities
// gives (written from the definition here). Tolerance: each float CDF bound is within
// half a float step (2^-25 below 1) of its double value, so a cell's probability is
// off by at most 2^-24 (in the row) plus its row's share of the marginal's 2^-24;
// 1e-6 absolute covers both for this 32 x 16 image.
TEST(EnvironmentDistribution, EachTexelGetsLuminanceTimesSolidAngle) {
  const Image im = varied_image();
  const EnvironmentDistribution table = build_environment_distribution(im);
  ASSERT_EQ(table.columns, 32);
  ASSERT_EQ(table.rows, 16);
  ASSERT_EQ(table.marginal_cdf.size(), size_t(17));
  ASSERT_EQ(table.conditional_cdf.size(), size_t(16 * 33));
  EXPECT_DOUBLE_EQ(table.luminance_floor, expected_floor(im));
  const std::vector<double> p = expected_probabilities(im);
  const PiecewiseConstant2D d = table.view();
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x)
      EXPECT_NEAR(d.cell_pdf(x, y) / (32.0 * 16.0), p[size_t(y) * 32 + x], 1e-6) << x << ", " << y;
}

// The density per solid angle integrates to 1 over the sphere: 4 pi x its mean over
// N = 10^6 uniform directions. Tolerance: 4 standard errors of that mean, estimated
// from the same samples (two-sided 6.3e-5 for a normal mean; the seeds are fixed). The density grows as
// 1 / sin theta in the top and bottom rows, so its variance under uniform directions
// grows with log N; at this N the sample estimate is what the spread is. The
// standard error is also held below 0.5%, so the test can tell.
TEST(EnvironmentSampling, PdfIntegratesToOneOverTheSphere) {
  const EnvironmentDistribution table = build_environment_distribution(varied_image());
  const Sky sky = environment_sky(37.0);
  const int n = 1000000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    float a, b;
    uniforms(11, i, a, b);
    const double f = 4.0 * kPiD * environment_pdf(sky, table.view(), unit_sphere_point(a, b));
    sum += f;
    sum2 += f * f;
  }
  const double mean = sum / n;
  const double standard_error = std::sqrt((sum2 / n - mean * mean) / (n - 1));
  EXPECT_LT(standard_error, 5e-3);
  EXPECT_NEAR(mean, 1.0, 4.0 * standard_error) << "standard error " << standard_error;
}

// Pearson's chi-square over the texel grid: 200k directions drawn, each binned by
// the texel the sky's lookup reads for it (so the direction, not the sampler's own
// report, is tested), against the probabilities written from the definition. Bins
// expected to get fewer than 5 samples (the 12 black texels, 0.4 to 0.5 each, and 5
// dim blue ones in the rows by the poles) are pooled into one, leaving 496 bins
// (df = 495).
// Critical value 659.21, the chi-square(495) upper-tail 1e-6 point (computed with
// mpmath): a correct sampler fails with probability 1e-6. Tried on broken samplers:
// the sin theta factor dropped from the weights scored 1.5e5, the columns drawn from
// the next row's CDF 2.4e5, theta taken as pi v^2 5.2e6.
TEST(EnvironmentSampling, SampledDirectionsFollowTheDensity) {
  const Image im = varied_image();
  const EnvironmentDistribution table = build_environment_distribution(im);
  const Sky sky = environment_sky(0.0);
  const std::vector<double> p = expected_probabilities(im);
  const int n = 200000;
  std::vector<long> counts(p.size(), 0);
  for (int i = 0; i < n; ++i) {
    float a, b;
    uniforms(13, i, a, b);
    const EnvironmentSample s = sample_environment(sky, table.view(), a, b);
    const Texel t = texel_of(sky, s.direction, im.width, im.height);
    ++counts[size_t(t.y) * im.width + t.x];
  }
  double chi2 = 0.0, pooled_expected = 0.0;
  long pooled_count = 0;
  int bins = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const double expected = n * p[i];
    if (expected < 5.0) {
      pooled_expected += expected;
      pooled_count += counts[i];
      continue;
    }
    chi2 += (counts[i] - expected) * (counts[i] - expected) / expected;
    ++bins;
  }
  ASSERT_GE(pooled_expected, 5.0);
  chi2 += (pooled_count - pooled_expected) * (pooled_count - pooled_expected) / pooled_expected;
  ++bins;
  ASSERT_EQ(bins, 496) << "the critical value below is for df = 495";
  EXPECT_LT(chi2, 659.21);  // 468.7 with these streams
}

// environment_pdf(direction) is the pdf sample_environment reported with it, up to
// the float round trip of sin theta (sin(pi v) against |(x, z)|: a few float steps,
// tolerance 1e-5 relatively), wherever the lookup reads the texel the sample was drawn
// in. Where it reads a neighbour, the sample must lie on a cell edge (within 1e-4 of
// a cell): that is the float round trip of (u, v), and such samples must be rare
// (at most 1 in 10^4; about 10^-6 expected).
TEST(EnvironmentSampling, PdfOfTheDirectionIsThePdfOfItsSample) {
  const Image im = varied_image();
  const EnvironmentDistribution table = build_environment_distribution(im);
  const Sky sky = environment_sky(-123.0);
  const int n = 100000;
  int across_an_edge = 0;
  for (int i = 0; i < n; ++i) {
    float a, b;
    uniforms(17, i, a, b);
    const EnvironmentSample s = sample_environment(sky, table.view(), a, b);
    ASSERT_GT(s.pdf, 0.0f) << i;
    const float pdf = environment_pdf(sky, table.view(), s.direction);
    if (texel_of(sky, s.direction, im.width, im.height) == Texel{s.column, s.row}) {
      EXPECT_NEAR(pdf, s.pdf, 1e-5f * s.pdf) << i;
    } else {
      ++across_an_edge;
      EXPECT_TRUE(near_cell_edge(s.uv, im.width, im.height)) << i << ": " << s.uv.x << ", " << s.uv.y;
    }
  }
  EXPECT_LE(across_an_edge, n / 10000);
}

// A sun: one texel 10^4 times brighter than the rest (luminance 500 against 0.05,
// above the floor). It holds the fraction p = 500 sin(theta_sun) / (500
// sin(theta_sun) + 0.05 x the other texels' sum of sin theta) of the samples (about
// 0.89); tolerance 4 binomial standard deviations over 100k samples (two-sided
// 6.3e-5; the seeds are fixed). Per solid angle, the density at the sun's centre is 10^4 times the
// density at every dim texel's centre. Relative tolerance 2e-3: a cell's width in a
// float CDF is off by up to 2^-24 (6e-8), and the smallest widths here are a dim
// cell of the sun's row (1e-4 of the row: up to 6e-4 off) and a row by a pole
// (3e-4 of the marginal: up to 2e-4 off); measured, 4.7e-4 at worst.
TEST(EnvironmentSampling, BrightSunGetsItsShareOfSamples) {
  const int w = 64, h = 32, sun_x = 40, sun_y = 12;
  const Image im = make_image(w, h, [&](int x, int y) { return vec3(x == sun_x && y == sun_y ? 500.0f : 0.05f); });
  const EnvironmentDistribution table = build_environment_distribution(im);
  ASSERT_LT(table.luminance_floor, 0.05);
  const Sky sky = environment_sky(0.0);
  double others = 0.0;
  for (int y = 0; y < h; ++y) others += w * row_sin(y, h);
  others -= row_sin(sun_y, h);
  const double sun = luminance_of(im, sun_x, sun_y) * row_sin(sun_y, h);
  const double p = sun / (sun + luminance_of(im, 0, 0) * others);
  const int n = 100000;
  int hits = 0;
  for (int i = 0; i < n; ++i) {
    float a, b;
    uniforms(19, i, a, b);
    hits += texel_of(sky, sample_environment(sky, table.view(), a, b).direction, w, h) == Texel{sun_x, sun_y};
  }
  EXPECT_NEAR(double(hits) / n, p, 4.0 * std::sqrt(p * (1.0 - p) / n)) << "expected fraction " << p;

  const auto centre = [&](int x, int y) {
    const double phi = 2.0 * kPiD * (x + 0.5) / w, theta = kPiD * (y + 0.5) / h;
    return vec3(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)), float(-std::sin(theta) * std::cos(phi)));
  };
  const double at_sun = environment_pdf(sky, table.view(), centre(sun_x, sun_y));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (!(x == sun_x && y == sun_y)) {
        EXPECT_NEAR(at_sun / environment_pdf(sky, table.view(), centre(x, y)), 1e4, 1e4 * 2e-3) << x << ", " << y;
      }
}

// Black texels (zero, negative, NaN and infinite luminance) keep the floor: their
// density per solid angle at their centre is floor / luminance times that of a lit
// texel of the same row. Tolerance 2e-3 relatively: a black cell is about 1e-4 of its
// row, and its float CDF bounds are within 2^-25 each, so its width is off by up to
// 5e-4 relatively.
TEST(EnvironmentSampling, BlackTexelsKeepTheFloor) {
  const int w = 8, h = 4;
  const float inf = std::numeric_limits<float>::infinity();
  const Image im = make_image(w, h, [&](int x, int y) {
    if (y == 1 && x == 2) return vec3(0.0f);
    if (y == 1 && x == 3) return vec3(-1.0f);
    if (y == 2 && x == 5) return vec3(std::nanf(""));
    if (y == 2 && x == 6) return vec3(inf, 0.0f, 0.0f);
    return vec3(1.0f);
  });
  const EnvironmentDistribution table = build_environment_distribution(im);
  const double floor = expected_floor(im);
  EXPECT_DOUBLE_EQ(table.luminance_floor, floor);
  const PiecewiseConstant2D d = table.view();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) EXPECT_GT(d.cell_pdf(x, y), 0.0f) << x << ", " << y;
  // Cell densities over (u, v) of one row compare as the texels' floored luminances.
  const double lit = luminance_of(im, 0, 1);
  for (const Texel t : {Texel{2, 1}, Texel{3, 1}, Texel{5, 2}, Texel{6, 2}})
    EXPECT_NEAR(d.cell_pdf(t.x, t.y) / d.cell_pdf(0, t.y), floor / lit, 2e-3 * floor / lit) << t.x << ", " << t.y;
}

// An image with no light at all is sampled uniformly per solid angle: at every
// texel's centre the density is H / (2 pi^2 sum_y sin theta_y) (the midpoint sum of
// 1 / 4 pi). Tolerance 1e-5 relatively (float CDF of equal cells).
TEST(EnvironmentSampling, BlackImageIsSampledUniformly) {
  const int w = 16, h = 8;
  const Image im = make_image(w, h, [](int, int) { return vec3(0.0f); });
  const EnvironmentDistribution table = build_environment_distribution(im);
  const Sky sky = environment_sky(0.0);
  double sines = 0.0;
  for (int y = 0; y < h; ++y) sines += row_sin(y, h);
  const double expected = h / (2.0 * kPiD * kPiD * sines);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double phi = 2.0 * kPiD * (x + 0.5) / w, theta = kPiD * (y + 0.5) / h;
      const vec3 d(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)), float(-std::sin(theta) * std::cos(phi)));
      EXPECT_NEAR(environment_pdf(sky, table.view(), d), expected, 1e-5 * expected) << x << ", " << y;
    }
}

// Sampled under a turned sky, a direction is looked up (Sky::environment_uv, which
// turns it back) in the texel it was drawn in, except on a cell edge (as above), and
// the turn moves the direction (the same uniforms without it give another one).
TEST(EnvironmentSampling, TurnedSkyLooksUpTheTexelItDrew) {
  const Image im = varied_image();
  const EnvironmentDistribution table = build_environment_distribution(im);
  for (double degrees : {70.0, 200.0, -45.0}) {
    const Sky turned = environment_sky(degrees), still = environment_sky(0.0);
    const int n = 20000;
    int across_an_edge = 0, moved = 0;
    for (int i = 0; i < n; ++i) {
      float a, b;
      uniforms(23, i, a, b);
      const EnvironmentSample s = sample_environment(turned, table.view(), a, b);
      if (!(texel_of(turned, s.direction, im.width, im.height) == Texel{s.column, s.row})) {
        ++across_an_edge;
        EXPECT_TRUE(near_cell_edge(s.uv, im.width, im.height)) << degrees << ", " << i;
      }
      moved += glm::length(s.direction - sample_environment(still, table.view(), a, b).direction) > 1e-3f;
    }
    EXPECT_LE(across_an_edge, n / 10000) << degrees;
    EXPECT_GT(moved, n * 9 / 10) << degrees;
  }
}

// At the poles exactly, sin theta is 0 and the density per solid angle has no finite
// value: the sample is reported as none (pdf 0), and the direction gets density 0.
TEST(EnvironmentSampling, ThePolesHaveNoDensity) {
  const EnvironmentDistribution table = build_environment_distribution(varied_image());
  const Sky sky = environment_sky(30.0);
  const EnvironmentSample s = sample_environment(sky, table.view(), 0.0f, 0.3f);
  EXPECT_EQ(s.pdf, 0.0f);
  EXPECT_EQ(s.uv.y, 0.0f);
  EXPECT_EQ(environment_pdf(sky, table.view(), vec3(0.0f, 1.0f, 0.0f)), 0.0f);
  EXPECT_EQ(environment_pdf(sky, table.view(), vec3(0.0f, -1.0f, 0.0f)), 0.0f);
  // The last uniform below 1 stays off the other pole.
  EXPECT_GT(sample_environment(sky, table.view(), kOneMinusEpsilon, 0.3f).pdf, 0.0f);
}

// Only a LatLong environment gets a table; the other mappings (and an empty table)
// are neither sampled nor given a density.
TEST(EnvironmentDistribution, OnlyALatLongEnvironmentHasATable) {
  Scene scene;
  scene.images.push_back(make_image(8, 4, [](int x, int) { return vec3(float(x)); }));
  EXPECT_TRUE(build_environment_distribution(scene).empty());  // the default gradient sky
  scene.sky = environment_sky(0.0);
  const EnvironmentDistribution table = build_environment_distribution(scene);
  EXPECT_FALSE(table.empty());
  EXPECT_EQ(table.columns, 8);
  EXPECT_EQ(table.rows, 4);
  for (EnvironmentMapping m : {EnvironmentMapping::Angular, EnvironmentMapping::MirrorBall}) {
    scene.sky.mapping = m;
    EXPECT_TRUE(build_environment_distribution(scene).empty());
    EXPECT_EQ(sample_environment(scene.sky, table.view(), 0.5f, 0.5f).pdf, 0.0f);
    EXPECT_EQ(environment_pdf(scene.sky, table.view(), vec3(1.0f, 0.0f, 0.0f)), 0.0f);
  }
  const EnvironmentDistribution none;
  EXPECT_EQ(sample_environment(environment_sky(0.0), none.view(), 0.5f, 0.5f).pdf, 0.0f);
  EXPECT_EQ(environment_pdf(environment_sky(0.0), none.view(), vec3(1.0f, 0.0f, 0.0f)), 0.0f);
  Image broken = scene.images[0];
  broken.texels.pop_back();
  EXPECT_THROW(build_environment_distribution(broken), std::invalid_argument);
}

}  // namespace
}  // namespace wt

// The counter-based Rng: range, uniformity, independence across every part of the
// key (seed, pixel, sample, bounce, dimension), determinism.
//
// Statistical thresholds: chi-square tests reject at an upper-tail probability of
// 1e-6 (critical values of the chi-square distribution computed with mpmath);
// correlation tests reject |r| > 5.5 / sqrt(N), which a truly independent stream
// exceeds with probability 3.8e-8 (r is ~ N(0, 1/N) for large N). All streams are
// fixed, so a pass or fail is reproducible; the probabilities say how unlikely a
// failure would be for a generator that really were uniform and independent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "wavetrace/rng.hpp"

namespace wt {
namespace {

// Upper-tail 1e-6 critical values of chi-square with df degrees of freedom.
constexpr double kChi2Crit999 = 1226.05;
constexpr double kChi2Crit255 = 377.08;

double chi_square_uniform(const std::vector<long>& counts, long total) {
  const double expected = double(total) / double(counts.size());
  double chi2 = 0.0;
  for (long c : counts) chi2 += (c - expected) * (c - expected) / expected;
  return chi2;
}

// Pearson correlation of N pairs drawn by `pair(i)`.
double correlation(int n, const std::function<std::pair<double, double>(int)>& pair) {
  double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  for (int i = 0; i < n; ++i) {
    auto [x, y] = pair(i);
    sx += x;
    sy += y;
    sxx += x * x;
    syy += y * y;
    sxy += x * y;
  }
  double cov = sxy / n - (sx / n) * (sy / n);
  double vx = sxx / n - (sx / n) * (sx / n), vy = syy / n - (sy / n) * (sy / n);
  return cov / std::sqrt(vx * vy);
}

constexpr int kCorrN = 1 << 20;
const double kCorrBound = 5.5 / std::sqrt(double(kCorrN));  // 5.4e-3

// The inverse of hash_u32, so that a key with a chosen output can be built.
uint32_t unhash_u32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x43021123u;  // inverse of 0x846ca68b mod 2^32
  x ^= x >> 15 ^ x >> 30;
  x *= 0x1d69e2a5u;  // inverse of 0x7feb352d mod 2^32
  x ^= x >> 16;
  return x;
}

TEST(Rng, UniformStaysInHalfOpenUnitInterval) {
  float lo = 1.0f, hi = 0.0f;
  for (uint32_t p = 0; p < 200000; ++p) {
    Rng rng = Rng::at(1, p, p % 7, p % 3);
    for (uint32_t d = 0; d < 10; ++d) {
      float u = rng.uniform(d);
      ASSERT_GE(u, 0.0f);
      ASSERT_LT(u, 1.0f);
      lo = std::fmin(lo, u);
      hi = std::fmax(hi, u);
    }
  }
  // 2M draws cover the interval (the extremes are within 1e-5 of its ends with
  // probability 1 - 2 e^-20).
  EXPECT_LT(lo, 1e-5f);
  EXPECT_GT(hi, 1.0f - 1e-5f);

  // The largest possible hash maps strictly below 1, the smallest to exactly 0:
  // keys built through the inverse hash reach them.
  for (uint32_t x : {0u, 1u, 0xdeadbeefu, 0xffffffffu}) ASSERT_EQ(unhash_u32(hash_u32(x)), x);
  const uint32_t dim = kDimScatterA;
  Rng top{unhash_u32(0xffffffffu) ^ hash_u32(dim + 0x68bc21ebu)};
  ASSERT_EQ(top.bits(dim), 0xffffffffu);
  EXPECT_LT(top.uniform(dim), 1.0f);
  EXPECT_EQ(top.uniform(dim), 1.0f - std::ldexp(1.0f, -24));
  Rng bottom{unhash_u32(0u) ^ hash_u32(dim + 0x68bc21ebu)};
  EXPECT_EQ(bottom.uniform(dim), 0.0f);
}

TEST(Rng, UniformPassesChiSquareOverBins) {
  // 1000 bins, 1M draws (1000 expected per bin), df = 999, over pixels (the way a
  // frame consumes them) for each of three dimensions.
  for (uint32_t dim : {uint32_t(kDimPixelX), uint32_t(kDimScatterA), uint32_t(kDimRoulette)}) {
    std::vector<long> counts(1000, 0);
    const long n = 1000000;
    for (long i = 0; i < n; ++i) {
      float u = Rng::at(7, uint32_t(i), 3, 1).uniform(dim);
      counts[size_t(u * 1000.0f)]++;
    }
    EXPECT_LT(chi_square_uniform(counts, n), kChi2Crit999) << "dim " << dim;
  }
  // And over samples of one pixel (the way one pixel consumes them).
  std::vector<long> counts(1000, 0);
  const long n = 1000000;
  for (long i = 0; i < n; ++i) counts[size_t(Rng::at(7, 12345, uint32_t(i), 0).uniform(kDimLensX) * 1000.0f)]++;
  EXPECT_LT(chi_square_uniform(counts, n), kChi2Crit999);
}

TEST(Rng, NeighbouringKeysAreUncorrelated) {
  const uint32_t dim = kDimScatterA;
  // Neighbouring pixels.
  double r = correlation(kCorrN, [&](int i) {
    return std::make_pair(double(Rng::at(1, i, 0, 0).uniform(dim)), double(Rng::at(1, i + 1, 0, 0).uniform(dim)));
  });
  EXPECT_LT(std::fabs(r), kCorrBound) << "pixels";
  // Neighbouring samples of one pixel.
  r = correlation(kCorrN, [&](int i) {
    return std::make_pair(double(Rng::at(1, 99, i, 0).uniform(dim)), double(Rng::at(1, 99, i + 1, 0).uniform(dim)));
  });
  EXPECT_LT(std::fabs(r), kCorrBound) << "samples";
  // Neighbouring bounces of one path (bounce varies over 0..29 as in a render,
  // the path varies with i).
  r = correlation(kCorrN, [&](int i) {
    uint32_t b = uint32_t(i % 29);
    return std::make_pair(double(Rng::at(1, i / 29, 0, b).uniform(dim)),
                          double(Rng::at(1, i / 29, 0, b + 1).uniform(dim)));
  });
  EXPECT_LT(std::fabs(r), kCorrBound) << "bounces";
  // Neighbouring seeds.
  r = correlation(kCorrN, [&](int i) {
    return std::make_pair(double(Rng::at(1, i, 0, 0).uniform(dim)), double(Rng::at(2, i, 0, 0).uniform(dim)));
  });
  EXPECT_LT(std::fabs(r), kCorrBound) << "seeds";
  // Key components that share a value must not cancel out: (pixel p, sample s) and
  // (pixel s, sample p) are different paths.
  r = correlation(kCorrN, [&](int i) {
    uint32_t p = uint32_t(i), s = uint32_t(i % 1000);
    return std::make_pair(double(Rng::at(1, p, s, 0).uniform(dim)), double(Rng::at(1, s, p, 0).uniform(dim)));
  });
  EXPECT_LT(std::fabs(r), kCorrBound) << "pixel/sample swapped";
}

TEST(Rng, NeighbouringDimensionsAreUncorrelated) {
  for (uint32_t d = 0; d < kDimRoulette; ++d) {
    double r = correlation(kCorrN, [&](int i) {
      Rng rng = Rng::at(3, i, 5, 2);
      return std::make_pair(double(rng.uniform(d)), double(rng.uniform(d + 1)));
    });
    EXPECT_LT(std::fabs(r), kCorrBound) << "dims " << d << ", " << d + 1;
  }
}

TEST(Rng, DimensionPairsFillTheUnitSquareUniformly) {
  // A 16 x 16 grid over (uniform(a), uniform(b)) of one key, 1M points (3906 per
  // cell), df = 255: catches dependence that a correlation misses (for example
  // points on a few lines). The pairs the samplers consume together, and the same
  // dimension at neighbouring pixels.
  struct Pair {
    uint32_t a, b;
  };
  for (Pair pr : {Pair{kDimPixelX, kDimPixelY}, Pair{kDimLensX, kDimLensY}, Pair{kDimScatterA, kDimScatterB},
                  Pair{kDimFuzzA, kDimFuzzB}, Pair{kDimLayer, kDimRoulette}}) {
    std::vector<long> counts(256, 0);
    const long n = 1000000;
    for (long i = 0; i < n; ++i) {
      Rng rng = Rng::at(11, uint32_t(i), 2, 4);
      counts[size_t(rng.uniform(pr.a) * 16.0f) * 16 + size_t(rng.uniform(pr.b) * 16.0f)]++;
    }
    EXPECT_LT(chi_square_uniform(counts, n), kChi2Crit255) << "dims " << pr.a << ", " << pr.b;
  }
  std::vector<long> counts(256, 0);
  const long n = 1000000;
  for (long i = 0; i < n; ++i) {
    float x = Rng::at(11, uint32_t(i), 0, 0).uniform(kDimScatterA);
    float y = Rng::at(11, uint32_t(i + 1), 0, 0).uniform(kDimScatterA);
    counts[size_t(x * 16.0f) * 16 + size_t(y * 16.0f)]++;
  }
  EXPECT_LT(chi_square_uniform(counts, n), kChi2Crit255) << "neighbouring pixels";
}

TEST(Rng, SameKeyGivesSameValues) {
  for (uint32_t i = 0; i < 1000; ++i) {
    Rng a = Rng::at(42, i * 7919u, i % 13, i % 5);
    Rng b = Rng::at(42, i * 7919u, i % 13, i % 5);
    ASSERT_EQ(a.key, b.key);
    for (uint32_t d = 0; d <= kDimRoulette; ++d) ASSERT_EQ(a.uniform(d), b.uniform(d));
  }
}

TEST(Rng, DifferentSeedsGiveDifferentStreams) {
  // Over 10000 paths, the fraction of equal first draws across two seeds must be
  // tiny (24-bit values: an equal pair has probability 6e-8 each).
  for (uint32_t seed : {0u, 1u, 2u, 12345u}) {
    int equal = 0;
    for (uint32_t p = 0; p < 10000; ++p) {
      if (Rng::at(seed, p, 0, 0).uniform(kDimPixelX) == Rng::at(seed + 1, p, 0, 0).uniform(kDimPixelX)) ++equal;
    }
    EXPECT_LE(equal, 2) << "seed " << seed;
  }
  // Distinct keys over a whole small frame (64 x 64 pixels x 16 samples x 4 bounces):
  // the key is a 32-bit hash, so a handful of birthday collisions is possible
  // (expected 262144^2 / 2^33 = 8); many more would mean the key derivation drops
  // information.
  std::vector<uint32_t> keys;
  for (uint32_t p = 0; p < 4096; ++p)
    for (uint32_t s = 0; s < 16; ++s)
      for (uint32_t b = 0; b < 4; ++b) keys.push_back(Rng::at(1, p, s, b).key);
  std::sort(keys.begin(), keys.end());
  long dup = 0;
  for (size_t i = 1; i < keys.size(); ++i) dup += keys[i] == keys[i - 1];
  // Poisson(8): P(>= 30) < 1e-8.
  EXPECT_LT(dup, 30);
}

}  // namespace
}  // namespace wt

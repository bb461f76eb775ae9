// The wave's queues and memory on their own: the push (warp-aggregated on the GPU,
// one atomic per item on the host), the layout of a wave in one block, and the
// choice of the wave size.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "cpu/cpu_wavefront.hpp"
#include "cpu/executor.hpp"
#include "cuda/cuda_wavefront.hpp"
#include "cuda/executor.cuh"
#include "queues/push.hpp"
#include "queues/wave.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

// Items whose index is not a multiple of 3 push their index.
struct PushEveryThirdMissing {
  uint32_t* count;
  uint32_t* out;
  WT_HD void operator()(uint32_t i) const {
    const bool want = i % 3 != 0;
    const uint32_t slot = push_slot(count, want);
    if (want) out[slot] = i;
  }
};

// The pushes of n items: each wanting item gets its own slot, the slots are
// 0..wanting-1 with none skipped, and the count says how many.
void expect_dense_pushes(uint32_t n, uint32_t count, std::vector<uint32_t> out) {
  const uint32_t wanting = n - (n + 2) / 3;
  ASSERT_EQ(count, wanting);
  out.resize(count);
  std::sort(out.begin(), out.end());
  std::vector<uint32_t> expect;
  for (uint32_t i = 0; i < n; ++i) {
    if (i % 3 != 0) expect.push_back(i);
  }
  EXPECT_EQ(out, expect);
}

TEST(Push, HostThreadsGetDistinctConsecutiveSlots) {
  const uint32_t n = 100003;
  std::vector<uint32_t> out(n, ~0u);
  uint32_t count = 0;
  cpu::Executor ex(0);
  ex.launch(Stage{0, "push"}, n, PushEveryThirdMissing{&count, out.data()});
  expect_dense_pushes(n, count, out);
}

TEST(Push, GpuWarpsGetDistinctConsecutiveSlots) {
  WT_REQUIRE_CUDA();
  // Not a multiple of the warp or block size: the last warp is partial.
  const uint32_t n = 100003;
  cuda::DeviceBuffer<uint32_t> count(1, "test"), out(n, "test");
  count.zero("test");
  out.zero("test");
  cuda::Executor ex;
  ex.launch(Stage{0, "push"}, n, PushEveryThirdMissing{count.get(), out.get()});
  expect_dense_pushes(n, count.download("test")[0], out.download("test"));
}

// ---------- the wave's layout ----------

// A pass's paths visit every pixel once a sample, in tiles of 8 x 4: whole tiles
// inside the image, narrower or lower ones at its right and bottom edges.
TEST(PathPixel, EverySampleVisitsEveryPixelOnceInTilesOfEightByFour) {
  for (auto [w, h] : {std::pair<uint32_t, uint32_t>{16, 8}, {21, 11}, {1, 1}, {7, 3}, {1920, 1080}, {9, 5}}) {
    const uint32_t pixels = w * h;
    std::vector<int> seen(pixels, 0);
    for (uint32_t path = 0; path < pixels; ++path) {
      const uint32_t p = path_pixel(path, w, h);
      ASSERT_LT(p, pixels) << w << "x" << h << " path " << path;
      ++seen[p];
      // The next sample's path lands on the same pixel.
      ASSERT_EQ(path_pixel(path + pixels, w, h), p);
    }
    for (uint32_t p = 0; p < pixels; ++p) ASSERT_EQ(seen[p], 1) << w << "x" << h << " pixel " << p;
  }
  // 16 x 8: the first warp's 32 paths are the top-left 8 x 4 tile, row by row.
  for (uint32_t path = 0; path < 32; ++path) EXPECT_EQ(path_pixel(path, 16, 8), (path / 8) * 16 + path % 8) << path;
  // The next tile is to its right; the tile row below starts at path 64.
  EXPECT_EQ(path_pixel(32, 16, 8), 8u);
  EXPECT_EQ(path_pixel(64, 16, 8), 4u * 16);
  // 9 x 5: the right edge's tiles are 1 wide, the bottom band 1 high.
  EXPECT_EQ(path_pixel(32, 9, 5), 8u);
  EXPECT_EQ(path_pixel(33, 9, 5), 9u + 8);
  EXPECT_EQ(path_pixel(36, 9, 5), 4u * 9);
  EXPECT_EQ(path_pixel(44, 9, 5), 4u * 9 + 8);
}

TEST(WaveLayout, EveryArrayIsAlignedDisjointAndInsideTheBlock) {
  const size_t capacity = 1000, temp = 777;
  size_t bytes = 0;
  unsigned char* const base = reinterpret_cast<unsigned char*>(uintptr_t(1) << 20);  // only addresses are compared
  const WaveView w = lay_out_wave(base, capacity, temp, &bytes);
  EXPECT_EQ(bytes, wave_bytes(capacity, temp));
  struct Range {
    const void* p;
    size_t bytes;
  };
  std::vector<Range> ranges;
  for (const PathQueue& q : w.queue) {
#define WT_TEST_RANGE(T, array, member) ranges.push_back({q.array, capacity * sizeof(T)});
    WT_PATH_FIELDS(WT_TEST_RANGE)
#undef WT_TEST_RANGE
  }
#define WT_TEST_RANGE(T, array, member) ranges.push_back({w.hits.array, capacity * sizeof(T)});
  WT_HIT_FIELDS(WT_TEST_RANGE)
#undef WT_TEST_RANGE
#define WT_TEST_RANGE(T, array, member) ranges.push_back({w.shadows.array, capacity * sizeof(T)});
  WT_SHADOW_FIELDS(WT_TEST_RANGE)
#undef WT_TEST_RANGE
  ranges.push_back({w.entries, capacity * sizeof(uint32_t)});
  ranges.push_back({w.selected, capacity * sizeof(uint32_t)});
  ranges.push_back({w.counters, sizeof(WaveCounters)});
  ranges.push_back({w.temp, temp});
  EXPECT_EQ(ranges.size(), 2 * 12 + 5 + 11 + 4u);
  std::sort(ranges.begin(), ranges.end(), [](const Range& a, const Range& b) { return a.p < b.p; });
  for (size_t i = 0; i < ranges.size(); ++i) {
    const auto at = static_cast<const unsigned char*>(ranges[i].p);
    EXPECT_EQ(reinterpret_cast<uintptr_t>(at) % Arena::kAlign, 0u) << i;
    EXPECT_GE(at, base);
    EXPECT_LE(at + ranges[i].bytes, base + bytes) << i;
    if (i > 0) EXPECT_GE(at, static_cast<const unsigned char*>(ranges[i - 1].p) + ranges[i - 1].bytes) << i;
  }
}

TEST(WaveLayout, BytesGrowByTheDeclaredFieldsPerSlot) {
  // Two path queues, the hit queue, the shadow queue, and the entries and selected
  // arrays; the fixed part (counters, temporaries, alignment) does not grow with the
  // slots.
  const size_t per_slot = 2 * PathQueue::kBytesPerSlot + HitQueue::kBytesPerSlot + ShadowQueue::kBytesPerSlot +
                          2 * sizeof(uint32_t);
  EXPECT_EQ(PathQueue::kBytesPerSlot, 10 * sizeof(float) + 2 * sizeof(uint32_t));
  EXPECT_EQ(HitQueue::kBytesPerSlot, 3 * sizeof(float) + 2 * sizeof(int32_t));
  EXPECT_EQ(ShadowQueue::kBytesPerSlot, 10 * sizeof(float) + sizeof(uint32_t));
  const size_t a = wave_bytes(1 << 16, 4096), b = wave_bytes(1 << 17, 4096);
  EXPECT_EQ(b - a, (size_t(1) << 16) * per_slot);
  EXPECT_GE(a, (size_t(1) << 16) * per_slot + sizeof(WaveCounters) + 4096);
}

TEST(WaveLayout, GpuWaveBytesHoldCubsTemporaries) {
  WT_REQUIRE_CUDA();  // CUB sizes its temporaries for the device it finds
  const size_t capacity = 1 << 20;
  EXPECT_EQ(cuda::wavefront_bytes(capacity), wave_bytes(capacity, cuda::Executor::temp_bytes(capacity)));
  EXPECT_GT(cuda::Executor::temp_bytes(capacity), 0u);
  EXPECT_EQ(cpu::Executor::temp_bytes(capacity), 0u);
}

// ---------- the wave size ----------

TEST(WaveSize, ARequestIsHonouredUpToThePaths) {
  const WaveBudget budget{1 << 24, 1 << 20, 100};
  EXPECT_EQ(choose_wave_size(5000, 1000000, budget), 5000);
  EXPECT_EQ(choose_wave_size(5000, 3000, budget), 3000);
}

TEST(WaveSize, TheDefaultIsCappedByTheMemoryBudgetButNotBelowTheMinimum) {
  EXPECT_EQ(choose_wave_size(0, int64_t(1) << 30, WaveBudget{1 << 24, 0, 100}), 1 << 24);
  // 100 MB at 100 bytes a slot: a million slots.
  EXPECT_EQ(choose_wave_size(0, int64_t(1) << 30, WaveBudget{1 << 24, 100000000, 100}), 1000000);
  EXPECT_EQ(choose_wave_size(0, int64_t(1) << 30, WaveBudget{1 << 24, 1000, 100}), kMinWaveSlots);
  // Never more slots than paths, even below the minimum.
  EXPECT_EQ(choose_wave_size(0, 500, WaveBudget{1 << 24, 1000, 100}), 500);
  EXPECT_EQ(choose_wave_size(0, 500, WaveBudget{1 << 24, 0, 100}), 500);
}

TEST(WaveSize, EachBackendChoosesFromItsOwnBudget) {
  const RenderParams big{3840, 2160, 64, 8, 4, 1};
  const RenderParams small{16, 16, 2, 8, 4, 1};
  EXPECT_EQ(cpu::choose_wave_size(0, big), 1 << 18);
  EXPECT_EQ(cpu::choose_wave_size(0, small), 512);
  if (!test::cuda_available()) GTEST_SKIP() << "no CUDA device: the GPU's budget needs CUB's sizes for it";
  EXPECT_EQ(cuda::choose_wave_size(0, big, size_t(80) << 30), 1 << 24);
  // A quarter of 1 GiB free holds fewer than 16 Mi slots: the wave shrinks to fit it.
  const int64_t fit = cuda::choose_wave_size(0, big, size_t(1) << 30);
  EXPECT_LT(fit, 1 << 24);
  EXPECT_LE(cuda::wavefront_bytes(fit), (size_t(1) << 30) / 4);
  EXPECT_GT(cuda::wavefront_bytes(fit * 2), (size_t(1) << 30) / 4);
}

}  // namespace
}  // namespace wt

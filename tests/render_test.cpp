// Whole renders on every backend and kernel: the white furnace, determinism, and
// agreement between kernels and between backends for the same seed.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "cuda/cuda_backend.hpp"
#include "dispatch/renderer.hpp"
#include "errors/errors.hpp"
#include "megakernel/megakernel.hpp"
#include "render/passes.hpp"
#include "stages/wavefront.hpp"
#include "render_support.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

using test::all_variants;
using test::mean;
using test::mean_abs_diff;
using test::options_for;
using test::Variant;
using test::variant_name;

// A Lambertian sphere of albedo 1 under a uniform sky of radiance 1: every path
// carries throughput 1 until it escapes, so every pixel's expected value is 1.
Scene furnace_scene() {
  return parse_scene(R"({
    "camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0], "vfov": 40},
    "sky": {"type": "uniform", "radiance": [1, 1, 1]},
    "materials": [{"name": "white", "type": "lambertian", "albedo": [1, 1, 1]}],
    "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "white"}]
  })",
                     "furnace.json");
}



class EveryKernel : public testing::TestWithParam<Variant> {
 protected:
  void SetUp() override {
    if (GetParam().backend == Backend::Cuda) WT_REQUIRE_CUDA();
  }
};

TEST_P(EveryKernel, FurnaceIsOneEverywhereWithoutRoulette) {
  RenderOptions o = options_for(GetParam().backend, GetParam().kernel, 24, 16, 4, 8, 100, 7);
  o.params.nee = 0;  // exact for path tracing; with light sampling in expectation (light_sampling_render_test)
  RenderResult r = render(furnace_scene(), o);
  // A path that escapes at once adds 1; one that hits adds 1 * 1 after one bounce
  // (a convex sphere cannot be hit twice). Only float rounding separates pixels from 1.
  for (float v : r.rgb) ASSERT_NEAR(v, 1.0f, 1e-5f);
  EXPECT_EQ(r.radiance, Radiance::MeanOfSamples);
  EXPECT_EQ(r.samples, 4);
  EXPECT_EQ(r.paths, 24u * 16u * 4u);
  EXPECT_GE(r.rays, r.paths);
  EXPECT_LE(r.rays, 2 * r.paths);
}

TEST_P(EveryKernel, FurnaceMeanIsOneWithRoulette) {
  // Roulette from the first bounce: paths survive with p = 0.95 and carry 1/0.95.
  // Each pixel is a mean of 16 paths; the image mean over 48*32 pixels has a
  // standard deviation under 0.002, and 0.01 is five of those.
  RenderOptions o = options_for(GetParam().backend, GetParam().kernel, 48, 32, 16, 8, 0, 3);
  RenderResult r = render(furnace_scene(), o);
  EXPECT_NEAR(mean(r.rgb), 1.0, 0.01);
}

TEST_P(EveryKernel, SameSeedSameImageOtherSeedOtherImage) {
  Scene scene = load_scene(test::repo_path("scenes/quick.json"));
  RenderOptions o = options_for(GetParam().backend, GetParam().kernel, 64, 36, 4, 8, 3, 11);
  RenderResult a = render(scene, o);
  RenderResult b = render(scene, o);
  o.params.seed = 12;
  RenderResult c = render(scene, o);
  // Float atomics in the wavefront add a pixel's samples in any order: equal to
  // rounding, not bit for bit. The megakernel sums in order and is bit-exact.
  const bool ordered = GetParam().kernel == Kernel::Megakernel || GetParam().kernel == Kernel::MegakernelConstant;
  if (ordered) {
    EXPECT_EQ(a.rgb, b.rgb);
  } else {
    EXPECT_LT(mean_abs_diff(a.rgb, b.rgb), 1e-6);
  }
  EXPECT_EQ(a.rays, b.rays);
  EXPECT_GT(mean_abs_diff(a.rgb, c.rgb), 1e-2);
}

// Float sums of the same samples grouped or ordered differently (passes, the
// wavefront's film atomics) agree to a few ulps of the largest pixel value.
void expect_same_image(const std::vector<float>& a, const std::vector<float>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) ASSERT_NEAR(a[i], b[i], 1e-5f * std::max(1.0f, std::fabs(a[i]))) << i;
}

// A render split into passes by the path limit (lowered here: 2^32 paths split a
// big render the same way) traces the same paths and gives the same image.
TEST_P(EveryKernel, PassesOverThePathLimitTraceTheSamePaths) {
  const Scene scene = load_scene(test::repo_path("scenes/quick.json"));
  RenderOptions whole = options_for(GetParam().backend, GetParam().kernel, 24, 16, 12, 8, 3, 5);
  const RenderResult a = render(scene, whole);
  RenderOptions split = whole;
  split.max_paths_per_pass = 24 * 16 * 5;  // at most 5 samples of every pixel in a pass
  std::vector<int32_t> done;
  split.after_pass = [&](int32_t samples, const FilmReader&) {
    done.push_back(samples);
    return true;
  };
  const RenderResult b = render(scene, split);
  ASSERT_GE(done.size(), 3u);
  EXPECT_EQ(done.back(), 12);
  for (size_t i = 1; i < done.size(); ++i) EXPECT_LE(done[i] - done[i - 1], 5);
  EXPECT_EQ(b.samples, 12);
  EXPECT_FALSE(b.interrupted);
  EXPECT_EQ(b.paths, 24u * 16u * 12u);
  EXPECT_EQ(b.rays, a.rays);
  expect_same_image(a.rgb, b.rgb);
}

// Stopped after a pass, then started again from the film's sums at that sample:
// the same paths, the same image as the render that ran through.
TEST_P(EveryKernel, AStoppedRenderResumedFromItsFilmEqualsTheWholeRender) {
  const Scene scene = load_scene(test::repo_path("scenes/quick.json"));
  // 64 x 64 pixels: with a wave of 1024 slots, the wavefront's passes of at least
  // four waves' paths are one sample, so the four samples asked for a pass hold.
  RenderOptions whole = options_for(GetParam().backend, GetParam().kernel, 64, 64, 12, 8, 3, 5);
  whole.wave_size = 1024;
  whole.samples_per_pass = 4;
  const RenderResult a = render(scene, whole);

  RenderOptions first = whole;
  std::vector<float> sums;
  first.after_pass = [&](int32_t samples, const FilmReader& film) {
    if (samples < 8) return true;
    sums = film();
    return false;
  };
  const RenderResult stopped = render(scene, first);
  EXPECT_TRUE(stopped.interrupted);
  EXPECT_EQ(stopped.samples, 8);
  ASSERT_EQ(sums.size(), a.rgb.size());

  RenderOptions rest = whole;
  rest.first_sample = 8;
  rest.initial_film = &sums;
  const RenderResult resumed = render(scene, rest);
  EXPECT_FALSE(resumed.interrupted);
  EXPECT_EQ(resumed.samples, 12);
  EXPECT_EQ(stopped.paths + resumed.paths, a.paths);
  EXPECT_EQ(stopped.rays + resumed.rays, a.rays);
  expect_same_image(a.rgb, resumed.rgb);
}

// Told its progress, a render tells shares that rise to 1 and rays that rise to its
// own count (the CUDA megakernel reads those of the passes before each pass without
// holding that pass back), and renders the image and the rays it renders untold.
TEST_P(EveryKernel, ProgressRisesToTheWholeAndLeavesTheImageAsItIs) {
  const Scene scene = load_scene(test::repo_path("scenes/quick.json"));
  const RenderOptions quiet = options_for(GetParam().backend, GetParam().kernel, 64, 36, 20, 8, 3, 11);
  const RenderResult a = render(scene, quiet);
  RenderOptions told = quiet;
  std::vector<std::pair<double, uint64_t>> calls;
  told.progress = [&](double done, uint64_t rays, double) { calls.emplace_back(done, rays); };
  const RenderResult b = render(scene, told);
  // Every kernel tells as it goes but the CPU megakernel, which tells at most every
  // 250 ms: a render this short tells only its end there.
  const bool as_it_goes = GetParam().backend == Backend::Cuda || is_wavefront(GetParam().kernel);
  ASSERT_GE(calls.size(), as_it_goes ? 2u : 1u);
  for (size_t i = 0; i < calls.size(); ++i) {
    EXPECT_GE(calls[i].first, 0.0) << i;
    EXPECT_LE(calls[i].first, 1.0) << i;
    EXPECT_LE(calls[i].second, b.rays) << i;
    if (i > 0) {
      EXPECT_GE(calls[i].first, calls[i - 1].first) << i;
      EXPECT_GE(calls[i].second, calls[i - 1].second) << i;
    }
  }
  if (as_it_goes) {
    EXPECT_GT(calls.front().second, 0u);
    EXPECT_LT(calls.front().second, b.rays);
  }
  EXPECT_EQ(calls.back().first, 1.0);
  EXPECT_EQ(calls.back().second, b.rays);
  EXPECT_EQ(a.rays, b.rays);
  expect_same_image(a.rgb, b.rgb);
}

TEST(SamplePasses, AreEvenAndCoverTheSamplesOnce) {
  const auto passes = plan_passes(100, 3, 25, 4, 0, kMaxPathsPerPass);
  ASSERT_EQ(passes.size(), 4u);
  int32_t at = 3;
  for (const SamplePass& p : passes) {
    EXPECT_EQ(p.first, at);
    EXPECT_TRUE(p.count == 6 || p.count == 7);
    at += p.count;
  }
  EXPECT_EQ(at, 28);
}

TEST(SamplePasses, HoldAtMostThePathLimitAndTheSamplesAsked) {
  // 3840 x 2160 x 4096 spp is 34 G paths: at most 2^32 - 1 in a pass.
  const uint64_t pixels = 3840ull * 2160;
  const auto big = plan_passes(pixels, 0, 4096, 1, 0, kMaxPathsPerPass);
  EXPECT_EQ(big.size(), 8u);
  for (const SamplePass& p : big) EXPECT_LE(pixels * p.count, kMaxPathsPerPass);
  const auto asked = plan_passes(10, 0, 100, 1, 7, kMaxPathsPerPass);
  EXPECT_EQ(asked.size(), 15u);
  for (const SamplePass& p : asked) EXPECT_LE(p.count, 7);
  // Never fewer samples than passes: at most one pass a sample.
  EXPECT_EQ(plan_passes(10, 0, 3, 10, 0, kMaxPathsPerPass).size(), 3u);
}

TEST(RenderSettings, BigRendersPassTheChecks) {
  RenderParams p{3840, 2160, 4096, 30, 30, 1};
  EXPECT_NO_THROW(validate_params(p));
}


INSTANTIATE_TEST_SUITE_P(Render, EveryKernel, testing::ValuesIn(all_variants()), variant_name);

// Two renders that trace the same paths agree to rounding; where rounding flips a
// decision (a Fresnel choice, a roulette draw) one path differs, so the bound is
// on the mean. Two different seeds differ by ~3e-2 on this scene; the bounds
// below are a small fraction of that.
constexpr double kSameBackendBound = 1e-4;
constexpr double kCrossBackendBound = 3e-3;

RenderResult render_quick(Backend b, Kernel k) {
  Scene scene = load_scene(test::repo_path("scenes/quick.json"));
  return render(scene, options_for(b, k, 96, 54, 8, 8, 3, 5));
}

TEST(KernelAgreement, CpuWavefrontMatchesCpuMegakernel) {
  RenderResult mk = render_quick(Backend::Cpu, Kernel::Megakernel);
  for (Kernel k : {Kernel::Wavefront, Kernel::WavefrontSorted, Kernel::WavefrontUnsorted}) {
    RenderResult wf = render_quick(Backend::Cpu, k);
    EXPECT_LT(mean_abs_diff(mk.rgb, wf.rgb), kSameBackendBound) << kernel_name(k);
    EXPECT_EQ(mk.rays, wf.rays) << kernel_name(k);
  }
}

// The sort policy (stages/wavefront.hpp): forced modes always and never sort; the
// adaptive one sorts a bounce whose hits hold at least kSortMinKeys sort keys, or two
// with a microfacet kind's among them.
TEST(SortPolicy, SortsOnlyBouncesWithManyKindsOfShading) {
  EXPECT_TRUE(sorts_bounce(Kernel::WavefrontSorted, 0u));
  EXPECT_FALSE(sorts_bounce(Kernel::WavefrontUnsorted, 0xffffffffu));
  EXPECT_FALSE(sorts_bounce(Kernel::Wavefront, (1u << (kSortMinKeys - 1)) - 1u));
  EXPECT_TRUE(sorts_bounce(Kernel::Wavefront, (1u << kSortMinKeys) - 1u));
  EXPECT_TRUE(sorts_bounce(Kernel::Wavefront, 0x55555u)) << "ten keys, not adjacent";
  EXPECT_FALSE(sorts_bounce(Kernel::Wavefront, 0x80000001u)) << "two keys, far apart";
  const uint32_t conductor = 1u << material_sort_key(MaterialKind::Conductor, -1);
  const uint32_t lambertian = 1u << material_sort_key(MaterialKind::Lambertian, -1);
  EXPECT_TRUE(sorts_bounce(Kernel::Wavefront, conductor | lambertian)) << "a microfacet kind among two keys";
  EXPECT_FALSE(sorts_bounce(Kernel::Wavefront, conductor)) << "one key alone";
}

// In whole renders, on both backends' wavefront: quick.json's hits hold eight sort
// keys (five materials kinds, four texture kinds) and its first bounces are sorted;
// rtiow-cover's three never are; the forced modes sort every bounce or none. The
// bounce counts are the same in every mode: sorting reorders, it does not change
// which paths are traced.
// The wavefront on `b` sorts the bounces whose hits hold many sort keys (quick.json)
// and not those with few (rtiow-cover.json); the sorted and unsorted kernels sort
// every bounce and none.
void expect_sort_policy(Backend b) {
  const Scene quick = load_scene(test::repo_path("scenes/quick.json"));
  const Scene rtiow = load_scene(test::repo_path("scenes/rtiow-cover.json"));
  const RenderResult q = render(quick, options_for(b, Kernel::Wavefront, 96, 54, 2, 8, 3, 5));
  EXPECT_GT(q.bounces_sorted, 0u) << backend_name(b);
  const RenderResult r = render(rtiow, options_for(b, Kernel::Wavefront, 64, 36, 2, 8, 3, 5));
  EXPECT_GT(r.bounces_shaded, 0u) << backend_name(b);
  EXPECT_EQ(r.bounces_sorted, 0u) << backend_name(b);
  const RenderResult sorted = render(rtiow, options_for(b, Kernel::WavefrontSorted, 64, 36, 2, 8, 3, 5));
  EXPECT_EQ(sorted.bounces_sorted, sorted.bounces_shaded) << backend_name(b);
  EXPECT_EQ(sorted.bounces_shaded, r.bounces_shaded) << backend_name(b);
  const RenderResult unsorted = render(quick, options_for(b, Kernel::WavefrontUnsorted, 96, 54, 2, 8, 3, 5));
  EXPECT_EQ(unsorted.bounces_sorted, 0u) << backend_name(b);
  EXPECT_EQ(unsorted.bounces_shaded, q.bounces_shaded) << backend_name(b);
}

TEST(SortPolicy, TheCpuWavefrontSortsWhereTheHitsHoldManyKeys) { expect_sort_policy(Backend::Cpu); }

// Its CUDA half skips, saying so, where there is no device (it used to drop out silently).
TEST(SortPolicy, TheCudaWavefrontSortsWhereTheHitsHoldManyKeys) {
  WT_REQUIRE_CUDA();
  expect_sort_policy(Backend::Cuda);
}

TEST(KernelAgreement, CudaKernelsMatchCudaMegakernel) {
  WT_REQUIRE_CUDA();
  RenderResult mk = render_quick(Backend::Cuda, Kernel::Megakernel);
  for (Kernel k : {Kernel::MegakernelConstant, Kernel::Wavefront, Kernel::WavefrontSorted, Kernel::WavefrontUnsorted}) {
    RenderResult other = render_quick(Backend::Cuda, k);
    EXPECT_LT(mean_abs_diff(mk.rgb, other.rgb), kSameBackendBound) << kernel_name(k);
    // Ray counts may differ only where rounding changed a path's length.
    EXPECT_NEAR(static_cast<double>(other.rays), static_cast<double>(mk.rays), 1e-4 * mk.rays) << kernel_name(k);
  }
}

// A small image's megakernel runs batches of samples, one thread a pixel and sample,
// and folds them into the film in sample order: the image is the one-thread-a-pixel
// launch's bit for bit, however the samples fall into batches (one pass of 24
// samples; batches of 5 leave a short one), with the same rays counted. Both
// megakernels, on the materials scene (every BSDF, textures, lights).
TEST(KernelAgreement, CudaMegakernelBatchesChangeNoBit) {
  WT_REQUIRE_CUDA();
  const Scene scene = load_scene(test::repo_path("scenes/cornell-materials.json"));
  for (Kernel k : {Kernel::Megakernel, Kernel::MegakernelConstant}) {
    SCOPED_TRACE(kernel_name(k));
    RenderOptions o = options_for(Backend::Cuda, k, 48, 32, 24, 8, 3, 9);
    o.samples_per_pass = 24;
    o.megakernel_batch = 1;
    const RenderResult one = render(scene, o);
    for (int batch : {5, 24, 0}) {
      o.megakernel_batch = batch;
      const RenderResult batched = render(scene, o);
      ASSERT_EQ(batched.rgb.size(), one.rgb.size());
      size_t differ = 0;
      for (size_t i = 0; i < one.rgb.size(); ++i) differ += batched.rgb[i] != one.rgb[i];
      EXPECT_EQ(differ, 0u) << "batch " << batch;
      EXPECT_EQ(batched.rays, one.rays) << "batch " << batch;
      EXPECT_EQ(batched.shadow_rays, one.shadow_rays) << "batch " << batch;
    }
  }
}

// The batch a megakernel launch takes: about four full waves of threads of the device
// (132 SMs: an H100), within the pass's samples; one thread a pixel at 1080p.
TEST(KernelAgreement, TheMegakernelsBatchFillsTheDevice) {
  EXPECT_EQ(cuda::megakernel_batch(1920 * 1080, 132, 100), 1);
  EXPECT_EQ(cuda::megakernel_batch(512 * 384, 132, 100), 6);
  EXPECT_EQ(cuda::megakernel_batch(256 * 256, 132, 100), 17);
  EXPECT_EQ(cuda::megakernel_batch(256 * 256, 132, 4), 4);
}

TEST(BackendAgreement, CudaMatchesCpuForEachKernel) {
  WT_REQUIRE_CUDA();
  for (Kernel k : {Kernel::Megakernel, Kernel::Wavefront}) {
    RenderResult cpu = render_quick(Backend::Cpu, k);
    RenderResult gpu = render_quick(Backend::Cuda, k);
    EXPECT_LT(mean_abs_diff(cpu.rgb, gpu.rgb), kCrossBackendBound) << kernel_name(k);
    EXPECT_NEAR(static_cast<double>(gpu.rays), static_cast<double>(cpu.rays), 2e-3 * cpu.rays) << kernel_name(k);
  }
}

TEST(RenderSettings, RejectsZeroSamples) {
  RenderOptions o = options_for(Backend::Cpu, Kernel::Megakernel, 8, 8, 0, 4, 4, 1);
  EXPECT_THROW(render(furnace_scene(), o), InputError);
}

TEST(RenderSettings, ConstantMegakernelNeedsCuda) {
  RenderOptions o = options_for(Backend::Cpu, Kernel::MegakernelConstant, 8, 8, 1, 4, 4, 1);
  EXPECT_THROW(render(furnace_scene(), o), InputError);
}

TEST(RenderSettings, SceneBeyondConstantMemoryIsRefusedByTheConstantMegakernel) {
  WT_REQUIRE_CUDA();
  // 4000 spheres need 80 KB for their geometry alone: more than constant memory holds.
  std::string spheres;
  for (int i = 0; i < 4000; ++i) {
    spheres += std::string(i ? "," : "") + "{\"center\": [" + std::to_string(i % 64) + ", " + std::to_string(i / 64) +
               ", 0], \"radius\": 0.4, \"material\": \"m\"}";
  }
  Scene scene = parse_scene(R"({"camera": {"look_from": [32, 32, 80], "look_at": [32, 32, 0]},
    "materials": [{"name": "m", "type": "lambertian"}], "spheres": [)" + spheres + "]}",
                            "big.json");
  RenderOptions o = options_for(Backend::Cuda, Kernel::MegakernelConstant, 16, 16, 1, 4, 4, 1);
  try {
    render(scene, o);
    FAIL() << "a scene of 4000 spheres was put in constant memory";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("big.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(std::to_string(cuda::constant_scene_capacity())), std::string::npos)
        << e.what();
  }
  o.kernel = Kernel::Megakernel;  // the global-memory kernel takes it
  EXPECT_NO_THROW(render(scene, o));
}

TEST(RenderSettings, RenderThatCannotFitDeviceMemoryIsRefusedWithSizes) {
  RenderParams p{16384, 16384, 1, 4, 4, 1};
  const size_t need = cuda::render_state_bytes(p, Kernel::Megakernel, 0);
  EXPECT_EQ(need, size_t(16384) * 16384 * 3 * sizeof(float));
  try {
    cuda::require_device_memory(p, need, size_t(1) << 30, "Test GPU");
    FAIL() << "a 3 GiB film was accepted on a device with 1 GiB free";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("16384 x 16384"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("Test GPU"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(cuda::require_device_memory(p, need, size_t(8) << 30, "Test GPU"));
}

}  // namespace
}  // namespace wt

// Whole renders on every backend and kernel: the white furnace, determinism, and
// agreement between kernels and between backends for the same seed.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "cuda/cuda_backend.hpp"
#include "megakernel/megakernel.hpp"
#include "render/renderer.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

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

RenderOptions options_for(Backend b, Kernel k, int w, int h, int spp, int depth, int roulette, uint32_t seed) {
  RenderOptions o;
  o.backend = b;
  o.kernel = k;
  o.params = RenderParams{w, h, spp, depth, roulette, seed};
  o.wave_size = 4096;  // several waves even for small images: regeneration is exercised
  return o;
}

double mean(const std::vector<float>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / v.size(); }

double mean_abs_diff(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += std::fabs(static_cast<double>(a[i]) - b[i]);
  return s / a.size();
}

struct Variant {
  Backend backend;
  Kernel kernel;
};

void PrintTo(const Variant& v, std::ostream* os) { *os << backend_name(v.backend) << "/" << kernel_name(v.kernel); }

std::string variant_name(const testing::TestParamInfo<Variant>& info) {
  std::string n = std::string(backend_name(info.param.backend)) + "_" + kernel_name(info.param.kernel);
  for (char& c : n) c = c == '-' ? '_' : c;
  return n;
}

class EveryKernel : public testing::TestWithParam<Variant> {
 protected:
  void SetUp() override {
    if (GetParam().backend == Backend::Cuda) WT_REQUIRE_CUDA();
  }
};

TEST_P(EveryKernel, FurnaceIsOneEverywhereWithoutRoulette) {
  RenderOptions o = options_for(GetParam().backend, GetParam().kernel, 24, 16, 4, 8, 100, 7);
  RenderResult r = render(furnace_scene(), o);
  // A path that escapes at once adds 1; one that hits adds 1 * 1 after one bounce
  // (a convex sphere cannot be hit twice). Only float rounding separates pixels from 1.
  for (float v : r.rgb) ASSERT_NEAR(v, 1.0f, 1e-5f);
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

std::vector<Variant> all_variants() {
  return {{Backend::Cpu, Kernel::Megakernel},           {Backend::Cpu, Kernel::Wavefront},
          {Backend::Cpu, Kernel::WavefrontUnsorted},    {Backend::Cuda, Kernel::Megakernel},
          {Backend::Cuda, Kernel::MegakernelConstant},  {Backend::Cuda, Kernel::Wavefront},
          {Backend::Cuda, Kernel::WavefrontUnsorted}};
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
  for (Kernel k : {Kernel::Wavefront, Kernel::WavefrontUnsorted}) {
    RenderResult wf = render_quick(Backend::Cpu, k);
    EXPECT_LT(mean_abs_diff(mk.rgb, wf.rgb), kSameBackendBound) << kernel_name(k);
    EXPECT_EQ(mk.rays, wf.rays) << kernel_name(k);
  }
}

TEST(KernelAgreement, CudaKernelsMatchCudaMegakernel) {
  WT_REQUIRE_CUDA();
  RenderResult mk = render_quick(Backend::Cuda, Kernel::Megakernel);
  for (Kernel k : {Kernel::MegakernelConstant, Kernel::Wavefront, Kernel::WavefrontUnsorted}) {
    RenderResult other = render_quick(Backend::Cuda, k);
    EXPECT_LT(mean_abs_diff(mk.rgb, other.rgb), kSameBackendBound) << kernel_name(k);
    // Ray counts may differ only where rounding changed a path's length.
    EXPECT_NEAR(static_cast<double>(other.rays), static_cast<double>(mk.rays), 1e-4 * mk.rays) << kernel_name(k);
  }
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
  EXPECT_THROW(render(furnace_scene(), o), SceneError);
}

TEST(RenderSettings, ConstantMegakernelNeedsCuda) {
  RenderOptions o = options_for(Backend::Cpu, Kernel::MegakernelConstant, 8, 8, 1, 4, 4, 1);
  EXPECT_THROW(render(furnace_scene(), o), SceneError);
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
  } catch (const SceneError& e) {
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
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("16384 x 16384"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("Test GPU"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(cuda::require_device_memory(p, need, size_t(8) << 30, "Test GPU"));
}

}  // namespace
}  // namespace wt

// Every kernel on every backend renders the shipped scenes bit for bit as the
// renderer did when these images were made (tests/data/golden/, by the command
// line: 96x54, 2 spp, depth 8, roulette from 3, seed 11, wave of 1024 slots, no
// light sampling). At 2 spp a pixel's sum does not depend on the order of its two
// additions, so the wavefront's film atomics give exact images too. (With light
// sampling a path adds several terms, which the wavefront adds to the film one by
// one in any order: light_sampling_render_test holds those images to rounding.) A change to the machinery that
// moves one bit of one pixel fails here; a change to the light transport must
// re-make these images and say why.
#include <gtest/gtest.h>

#include <cstring>

#include "dispatch/renderer.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

struct Golden {
  const char* scene;
  Backend backend;
  Kernel kernel;
};

void PrintTo(const Golden& g, std::ostream* os) {
  *os << g.scene << "/" << backend_name(g.backend) << "/" << kernel_name(g.kernel);
}

class GoldenImage : public testing::TestWithParam<Golden> {};

TEST_P(GoldenImage, IsBitIdentical) {
  const Golden& g = GetParam();
  if (g.backend == Backend::Cuda) WT_REQUIRE_CUDA();
  const int w = 96, h = 54;
  RenderOptions o;
  o.backend = g.backend;
  o.kernel = g.kernel;
  o.params = RenderParams{w, h, 2, 8, 3, 11};
  o.params.nee = 0;
  o.wave_size = 1024;
  const RenderResult r = render(load_scene(test::repo_path(std::string("scenes/") + g.scene + ".json")), o);
  const std::vector<float> expect = test::read_pfm(
      test::repo_path(std::string("tests/data/golden/") + g.scene + "_" + backend_name(g.backend) + ".pfm"), w, h);
  ASSERT_EQ(r.rgb.size(), expect.size());
  size_t differing = 0;
  double worst = 0;
  for (size_t i = 0; i < expect.size(); ++i) {
    if (std::memcmp(&r.rgb[i], &expect[i], sizeof(float)) != 0) {
      ++differing;
      worst = std::max(worst, std::fabs(static_cast<double>(r.rgb[i]) - expect[i]));
    }
  }
  EXPECT_EQ(differing, 0u) << "values differ, the largest by " << worst;
}

std::vector<Golden> every_golden() {
  std::vector<Golden> out;
  for (const char* scene : {"seed57", "rtiow-cover", "divergent"}) {
    for (Kernel k : {Kernel::Megakernel, Kernel::Wavefront, Kernel::WavefrontSorted, Kernel::WavefrontUnsorted}) {
      out.push_back({scene, Backend::Cpu, k});
    }
    for (Kernel k : {Kernel::Megakernel, Kernel::MegakernelConstant, Kernel::Wavefront, Kernel::WavefrontSorted, Kernel::WavefrontUnsorted}) {
      out.push_back({scene, Backend::Cuda, k});
    }
  }
  return out;
}

std::string golden_name(const testing::TestParamInfo<Golden>& info) {
  std::string n = std::string(info.param.scene) + "_" + backend_name(info.param.backend) + "_" +
                  kernel_name(info.param.kernel);
  for (char& c : n) c = (c == '-') ? '_' : c;
  return n;
}

INSTANTIATE_TEST_SUITE_P(EveryKernel, GoldenImage, testing::ValuesIn(every_golden()), golden_name);

}  // namespace
}  // namespace wt

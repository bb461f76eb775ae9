// Whole renders of triangle meshes on every backend and kernel: the white furnace
// on closed meshes, and the Cornell box (triangles only) agreeing between kernels
// and backends.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numeric>

#include "mesh_support.hpp"
#include "dispatch/renderer.hpp"
#include "render_support.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

using test::all_variants;
using test::mean;
using test::options_for;
using test::Variant;
using test::variant_name;




// ---- The furnace ----

class MeshFurnace : public testing::TestWithParam<Variant> {
 protected:
  void SetUp() override {
    if (GetParam().backend == Backend::Cuda) WT_REQUIRE_CUDA();
  }

  // A closed mesh of Lambertian albedo 1 under a uniform sky of radiance 1,
  // filling most of the frame.
  Scene furnace(const test::MeshData& mesh, const std::string& placing) const {
    const std::string obj = (folder_.root() / "closed.obj").string();
    test::write_obj(obj, mesh);
    return parse_scene(R"({
      "camera": {"look_from": [0, 0, 4], "look_at": [0, 0, 0], "vfov": 40},
      "sky": {"type": "uniform", "radiance": [1, 1, 1]},
      "materials": [{"name": "white", "type": "lambertian", "albedo": [1, 1, 1]}],
      "meshes": [{"name": "closed", "file": "closed.obj", "material": "white"}],
      "instances": [{"mesh": "closed")" + placing +
                           R"(}]
    })",
                       (folder_.root() / "furnace.json").string());
  }

  // Every path carries throughput 1 until it escapes, so every pixel is 1 up to
  // float rounding (1e-5, as render_test's sphere furnace). The mesh is convex: a
  // path that hits it bounces off and escapes, so it traces at most two rays; a
  // third would be a secondary ray hitting the surface it left.
  void expect_furnace(const Scene& scene) {
    RenderOptions o = options_for(GetParam().backend, GetParam().kernel, 24, 16, 4, 8, 100, 7);
    o.params.nee = 0;  // exact for path tracing; with light sampling in expectation (light_sampling_render_test)
    const RenderResult r = render(scene, o);
    ASSERT_EQ(r.rgb.size(), 24u * 16u * 3u);
    for (size_t i = 0; i < r.rgb.size(); ++i) ASSERT_NEAR(r.rgb[i], 1.0f, 1e-5f) << "value " << i;
    EXPECT_EQ(r.paths, 24u * 16u * 4u);
    EXPECT_GT(r.rays, r.paths + r.paths / 4) << "the mesh should fill a good part of the frame";
    EXPECT_LE(r.rays, 2 * r.paths) << "a secondary ray hit the convex mesh it left";
  }

  test::TestFolder folder_;
};

// Subdivided twice (320 triangles), so that megakernel-constant holds it too; three
// times (1280) needs 87 KB, more than constant memory, and that kernel refuses.
TEST_P(MeshFurnace, ClosedIcosphereIsOneEverywhere) { expect_furnace(furnace(test::icosphere(2), "")); }

// A cube turned to show three faces, its edges and a corner, scaled unevenly.
TEST_P(MeshFurnace, TurnedCubeIsOneEverywhere) {
  expect_furnace(furnace(test::cube(), R"(, "rotate": [35, 45, 10], "scale": [0.9, 0.8, 1.0])"));
}

INSTANTIATE_TEST_SUITE_P(Render, MeshFurnace, testing::ValuesIn(all_variants()), variant_name);

// ---- The Cornell box ----

RenderResult render_cornell(Backend b, Kernel k, int spp, uint32_t seed = 5, int nee = 1) {
  static const Scene scene = load_scene(test::repo_path("scenes/cornell-box.json"));
  RenderOptions o = options_for(b, k, 64, 64, spp, 8, 3, seed);
  o.params.nee = nee;
  return render(scene, o);
}

// At 2 samples a pixel's sum does not depend on the order of its two additions
// (tests/golden_test.cpp), so the CPU's wavefront kernels, which trace the same
// paths with the same arithmetic as the megakernel, must give the same bits without
// light sampling. (When written they did at 8 samples too; 2 is what the golden
// images rely on.) With light sampling see light_sampling_render_test.
TEST(CornellBox, CpuWavefrontIsBitIdenticalToCpuMegakernel) {
  const RenderResult mk = render_cornell(Backend::Cpu, Kernel::Megakernel, 2, 5, 0);
  EXPECT_GT(mean(mk.rgb), 0.01) << "the box should be lit";
  for (Kernel k : {Kernel::Wavefront, Kernel::WavefrontSorted, Kernel::WavefrontUnsorted}) {
    const RenderResult wf = render_cornell(Backend::Cpu, k, 2, 5, 0);
    ASSERT_EQ(wf.rgb.size(), mk.rgb.size());
    size_t differing = 0;
    double worst = 0;
    for (size_t i = 0; i < mk.rgb.size(); ++i) {
      if (std::memcmp(&mk.rgb[i], &wf.rgb[i], sizeof(float)) != 0) {
        ++differing;
        worst = std::max(worst, std::fabs(static_cast<double>(mk.rgb[i]) - wf.rgb[i]));
      }
    }
    EXPECT_EQ(differing, 0u) << kernel_name(k) << ": values differ, the largest by " << worst;
    EXPECT_EQ(wf.rays, mk.rays) << kernel_name(k);
  }
}

// CUDA against the CPU megakernel, same seed (render_support.hpp says how the
// bounds are set). When written, seeds 6, 7 and 8 against seed 5 gave mean absolute
// differences of 0.103 to 0.111 and image means 1% to 7% apart (the mean's own
// spread is about 3.6% at 64x64x8, the light being small and bright): a tenth of
// the paths diverged would move the mean by about 1.6% (one sigma).
TEST(CornellBox, EveryCudaKernelAgreesWithTheCpuMegakernel) {
  WT_REQUIRE_CUDA();
  test::expect_cuda_agrees_with_cpu([](Backend b, Kernel k, uint32_t seed) { return render_cornell(b, k, 8, seed); }, 5);
}

}  // namespace
}  // namespace wt

// Each wavefront stage on its own, on the CPU (the per-item functions and the
// standard-library compact and sort) and on the GPU (the launches), on fixed inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>

#include "cpu/cpu_stages.hpp"
#include "cuda/device_scene.hpp"
#include "stages/stages.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

// Two overlapping spheres on the z axis and a mirror off to the side.
Scene stage_scene() {
  return parse_scene(R"({
    "camera": {"look_from": [0, 0, 10], "look_at": [0, 0, 0], "vfov": 30},
    "sky": {"type": "gradient", "horizon": [1, 1, 1], "zenith": [0.5, 0.7, 1.0]},
    "materials": [
      {"name": "red", "type": "lambertian", "albedo": [0.8, 0.2, 0.2]},
      {"name": "glass", "type": "dielectric", "ior": 1.5},
      {"name": "mirror", "type": "metal", "albedo": [0.9, 0.8, 0.7], "fuzz": 0}
    ],
    "spheres": [
      {"center": [0, 0, 0], "radius": 1, "material": "red"},
      {"center": [0, 0, 1.5], "radius": 1, "material": "glass"},
      {"center": [5, 0, 0], "radius": 1, "material": "mirror"}
    ]
  })",
                     "stages.json");
}

// Index (after the BVH reordering) of the sphere centred at c.
int sphere_at(const Scene& s, vec3 c) {
  for (size_t i = 0; i < s.spheres.size(); ++i) {
    if (s.spheres[i].x == c.x && s.spheres[i].y == c.y && s.spheres[i].z == c.z) return static_cast<int>(i);
  }
  return -1;
}

const RenderParams kParams{7, 5, 3, 8, 100, 9};  // 105 paths
constexpr uint32_t kTotal = 7 * 5 * 3;

struct HostQueue {
  explicit HostQueue(size_t n) : mem(n * PathQueue::kBytesPerSlot / sizeof(float)), q(PathQueue::over(mem.data(), n)) {}
  std::vector<float> mem;
  PathQueue q;
};

// ---------- generate ----------

TEST(GenerateStage, FillsFreeSlotsWithConsecutivePathsMatchingTheCamera) {
  Scene scene = stage_scene();
  std::vector<ImageView> images;
  SceneView view = host_view(scene, images);
  view.camera = Camera::make(scene.camera, kParams.width, kParams.height);
  HostQueue hq(16);
  // 5 paths survive in slots 0..4; slots 5..15 start paths 40..50.
  for (uint32_t slot = 5; slot < live_paths(5, 40, kTotal, 16); ++slot) generate_one(slot, 5, 40, view, kParams, hq.q);
  for (uint32_t slot = 5; slot < 16; ++slot) {
    PathState s = hq.q.load(slot);
    EXPECT_EQ(s.path, 40 + slot - 5);
    EXPECT_EQ(s.bounce, 0u);
    Ray expect = primary_ray(view, kParams, s.path % 35, s.path / 35);
    EXPECT_EQ(s.ray.origin, expect.origin);
    EXPECT_EQ(s.ray.dir, expect.dir);
    EXPECT_EQ(s.throughput, vec3(1.0f));
  }
}

TEST(GenerateStage, EveryPathIsGeneratedExactlyOnceAcrossWaves) {
  // Whatever number of paths survive each bounce, the slots handed out cover
  // [0, pixels x samples) once each.
  std::vector<int> seen(kTotal, 0);
  uint32_t queued = 0, next_path = 0;
  std::mt19937 rng(4);
  while (next_path < kTotal) {
    uint32_t live = live_paths(queued, next_path, kTotal, 16);
    for (uint32_t slot = queued; slot < live; ++slot) ++seen[next_path + slot - queued];
    next_path += live - queued;
    queued = std::uniform_int_distribution<uint32_t>(0, live)(rng);
  }
  for (uint32_t p = 0; p < kTotal; ++p) EXPECT_EQ(seen[p], 1) << "path " << p;
}

TEST(GenerateStage, GpuMatchesTheCamera) {
  WT_REQUIRE_CUDA();
  Scene scene = stage_scene();
  cuda::DeviceScene ds(scene, kParams.width, kParams.height);
  cuda::WaveMemory wave(64);
  WaveCounters c{{3, 0}, 10, 0, 0};
  WT_CUDA(cudaMemcpy(wave.counters(), &c, sizeof(c), cudaMemcpyHostToDevice), "test");
  cuda::launch_generate(ds.view(), kParams, wave, 0, kTotal, nullptr);
  std::vector<float> dx(64), oz(64);
  std::vector<uint32_t> path(64);
  WT_CUDA(cudaMemcpy(dx.data(), wave.queue(0).dx, 64 * sizeof(float), cudaMemcpyDeviceToHost), "test");
  WT_CUDA(cudaMemcpy(oz.data(), wave.queue(0).oz, 64 * sizeof(float), cudaMemcpyDeviceToHost), "test");
  WT_CUDA(cudaMemcpy(path.data(), wave.queue(0).path, 64 * sizeof(uint32_t), cudaMemcpyDeviceToHost), "test");
  std::vector<ImageView> images;
  SceneView view = host_view(scene, images);
  view.camera = Camera::make(scene.camera, kParams.width, kParams.height);
  for (uint32_t slot = 3; slot < 64; ++slot) {
    ASSERT_EQ(path[slot], 10 + slot - 3);
    Ray expect = primary_ray(view, kParams, path[slot] % 35, path[slot] / 35);
    EXPECT_NEAR(dx[slot], expect.dir.x, 1e-5f);
    EXPECT_NEAR(oz[slot], expect.origin.z, 1e-5f);
  }
}

// ---------- intersect ----------

// Rays with known outcomes: into the overlap (closest is the glass sphere's front
// at z = 2.5), at the red sphere from the side, at the mirror, and a miss.
std::vector<PathState> known_rays() {
  auto make = [](vec3 o, vec3 d, uint32_t path) {
    return PathState{Ray{o, glm::normalize(d)}, vec3(0.5f, 0.25f, 1.0f), path, 0};
  };
  return {make(vec3(0, 0, 10), vec3(0, 0, -1), 0), make(vec3(-10, 0, 0), vec3(1, 0, 0), 1),
          make(vec3(5, 10, 0), vec3(0, -1, 0), 2), make(vec3(0, 0, 10), vec3(0, 1, 0), 3)};
}

void expect_known_hits(const Scene& scene, const std::vector<float>& t, const std::vector<int32_t>& sphere,
                       const std::vector<uint32_t>& entries, const std::vector<float>& film) {
  EXPECT_NEAR(t[0], 7.5f, 1e-5f);
  EXPECT_EQ(sphere[0], sphere_at(scene, vec3(0, 0, 1.5f)));
  EXPECT_NEAR(t[1], 9.0f, 1e-5f);
  EXPECT_EQ(sphere[1], sphere_at(scene, vec3(0, 0, 0)));
  EXPECT_NEAR(t[2], 9.0f, 1e-5f);
  EXPECT_EQ(sphere[2], sphere_at(scene, vec3(5, 0, 0)));
  EXPECT_EQ(sphere[3], -1);
  for (uint32_t i = 0; i < 3; ++i) {
    EXPECT_EQ(entry_slot(entries[i]), i);
    EXPECT_EQ(entry_key(entries[i]), scene.materials[scene.sphere_material[sphere[i]]].sort_key);
  }
  EXPECT_EQ(entry_key(entries[3]), kSortKeyMiss);
  // The miss added throughput x sky (straight up: the zenith colour) to pixel 3.
  EXPECT_NEAR(film[9], 0.5f * 0.5f, 1e-6f);
  EXPECT_NEAR(film[10], 0.25f * 0.7f, 1e-6f);
  EXPECT_NEAR(film[11], 1.0f * 1.0f, 1e-6f);
  for (size_t i = 0; i < film.size(); ++i) {
    if (i < 9 || i > 11) {
      EXPECT_EQ(film[i], 0.0f) << "film[" << i << "]";
    }
  }
}

TEST(IntersectStage, FindsClosestHitsAndAddsSkyForMisses) {
  Scene scene = stage_scene();
  std::vector<ImageView> images;
  SceneView view = host_view(scene, images);
  HostQueue hq(4);
  std::vector<PathState> rays = known_rays();
  for (uint32_t i = 0; i < 4; ++i) hq.q.store(i, rays[i]);
  std::vector<float> t(4), film(35 * 3, 0.0f);
  std::vector<int32_t> sphere(4);
  std::vector<uint32_t> entries(4);
  HitQueue hits{t.data(), sphere.data()};
  for (uint32_t i = 0; i < 4; ++i) entries[i] = intersect_one(i, view, kParams, hq.q, hits, film.data());
  expect_known_hits(scene, t, sphere, entries, film);
}

template <class T>
std::vector<T> download(const T* p, size_t n) {
  std::vector<T> v(n);
  WT_CUDA(cudaMemcpy(v.data(), p, n * sizeof(T), cudaMemcpyDeviceToHost), "test");
  return v;
}

template <class T>
void upload(T* p, const std::vector<T>& v) {
  WT_CUDA(cudaMemcpy(p, v.data(), v.size() * sizeof(T), cudaMemcpyHostToDevice), "test");
}

TEST(IntersectStage, GpuFindsClosestHitsAndCountsRays) {
  WT_REQUIRE_CUDA();
  Scene scene = stage_scene();
  cuda::DeviceScene ds(scene, kParams.width, kParams.height);
  cuda::WaveMemory wave(8);
  HostQueue hq(8);
  std::vector<PathState> rays = known_rays();
  for (uint32_t i = 0; i < 4; ++i) hq.q.store(i, rays[i]);
  cudaMemcpy(wave.queue(0).ox, hq.mem.data(), hq.mem.size() * sizeof(float), cudaMemcpyHostToDevice);
  // All paths handed out: live = queued = 4; slots 4..7 must come out as misses.
  WaveCounters c{{4, 77}, kTotal, 0, 100};
  upload(wave.counters(), std::vector<WaveCounters>{c});
  cuda::DeviceBuffer<float> film(35 * 3, "test");
  film.zero("test");
  cuda::launch_intersect(ds.view(), kParams, wave, 0, kTotal, film.get(), nullptr);
  auto entries = download(wave.entries(), 8);
  expect_known_hits(scene, download(wave.hits().t, 4), download(wave.hits().sphere, 4), entries, film.download("test"));
  for (uint32_t i = 4; i < 8; ++i) EXPECT_EQ(entry_key(entries[i]), kSortKeyMiss);
  WaveCounters after = download(wave.counters(), 1)[0];
  EXPECT_EQ(after.rays, 104u);
  EXPECT_EQ(after.queued[0], 4u);
  EXPECT_EQ(after.queued[1], 0u);  // emptied for shade's pushes
  EXPECT_EQ(after.next_path, kTotal);
}

// ---------- compact and sort ----------

std::vector<uint32_t> random_entries(size_t n, uint32_t seed, bool with_misses) {
  std::mt19937 rng(seed);
  std::vector<uint32_t> e(n);
  for (uint32_t i = 0; i < n; ++i) {
    uint32_t key = std::uniform_int_distribution<uint32_t>(0, kSortKeyCount - 1)(rng);
    if (with_misses && rng() % 3 == 0) key = kSortKeyMiss;
    e[i] = pack_entry(key, i);
  }
  return e;
}

void expect_compacted(const std::vector<uint32_t>& in, const std::vector<uint32_t>& out) {
  std::vector<uint32_t> expect;
  for (uint32_t e : in) {
    if (entry_key(e) != kSortKeyMiss) expect.push_back(e);
  }
  // Exactly the live entries, each once, in their order.
  EXPECT_EQ(out, expect);
}

void expect_sorted_permutation(std::vector<uint32_t> in, const std::vector<uint32_t>& out) {
  ASSERT_EQ(in.size(), out.size());
  for (size_t i = 1; i < out.size(); ++i) {
    ASSERT_LE(entry_key(out[i - 1]), entry_key(out[i])) << i;
    if (entry_key(out[i - 1]) == entry_key(out[i])) {
      ASSERT_LT(entry_slot(out[i - 1]), entry_slot(out[i])) << i;
    }
  }
  // A permutation that keeps each slot with its key: the path's fields move with it.
  std::vector<uint32_t> sorted_out = out;
  std::sort(in.begin(), in.end());
  std::sort(sorted_out.begin(), sorted_out.end());
  EXPECT_EQ(in, sorted_out);
}

TEST(CompactStage, KeepsExactlyTheLiveEntriesInOrder) {
  auto in = random_entries(5000, 1, true);
  std::vector<uint32_t> out;
  cpu::compact_entries(in.data(), in.size(), out);
  expect_compacted(in, out);
}

TEST(CompactStage, GpuKeepsExactlyTheLiveEntriesInOrder) {
  WT_REQUIRE_CUDA();
  const size_t n = 100000;
  cuda::WaveMemory wave(n);
  auto in = random_entries(n, 2, true);
  upload(wave.entries(), in);
  cuda::compact_entries(wave, nullptr);
  uint32_t hits = download(wave.counters(), 1)[0].hits;
  expect_compacted(in, download(wave.selected(), hits));
}

TEST(SortStage, OrdersByKeyAsAPermutation) {
  auto in = random_entries(5000, 3, false);
  std::vector<uint32_t> out = in;
  cpu::sort_entries(out);
  expect_sorted_permutation(in, out);
}

TEST(SortStage, GpuOrdersByKeyAsAPermutationLikeTheCpu) {
  WT_REQUIRE_CUDA();
  const size_t n = 100000;
  cuda::WaveMemory wave(n);
  auto in = random_entries(n, 4, false);
  upload(wave.selected(), in);
  cuda::sort_entries(wave, static_cast<uint32_t>(n), 5, nullptr);
  auto out = download(wave.sorted(), n);
  expect_sorted_permutation(in, out);
  std::vector<uint32_t> cpu_out = in;
  cpu::sort_entries(cpu_out);
  EXPECT_EQ(out, cpu_out);
}

// ---------- shade ----------

// One path per sphere of the stage scene, arriving head-on along -z or +x, after
// intersect has run on them (so the hit records are real).
struct ShadeCase {
  Scene scene = stage_scene();
  std::vector<ImageView> images;
  SceneView view{};
  HostQueue hq{3};
  std::vector<float> t = std::vector<float>(3);
  std::vector<int32_t> sphere = std::vector<int32_t>(3);
  std::vector<float> film = std::vector<float>(35 * 3, 0.0f);
  HitQueue hits{t.data(), sphere.data()};

  ShadeCase() {
    view = host_view(scene, images);
    std::vector<PathState> rays = known_rays();
    for (uint32_t i = 0; i < 3; ++i) {
      rays[i].bounce = 1;
      rays[i].path = 7 + i;
      hq.q.store(i, rays[i]);
      intersect_one(i, view, kParams, hq.q, hits, film.data());
    }
  }
};

TEST(ShadeStage, EachMaterialScattersAsItsDefinitionSays) {
  ShadeCase sc;
  PathState next[3];
  for (uint32_t i = 0; i < 3; ++i) {
    ASSERT_TRUE(shade_one(i, sc.view, kParams, sc.hq.q, sc.hits, sc.film.data(), next[i])) << i;
    EXPECT_EQ(next[i].bounce, 2u);
    EXPECT_EQ(next[i].path, 7 + i);
  }
  // Glass, head-on at z = 2.5: refracts straight through or reflects straight back
  // (Schlick at normal incidence); either way along the axis, throughput unchanged.
  EXPECT_NEAR(std::fabs(next[0].ray.dir.z), 1.0f, 1e-5f);
  EXPECT_EQ(next[0].throughput, vec3(0.5f, 0.25f, 1.0f));
  // Lambertian, hit at (-1, 0, 0): leaves into the -x hemisphere with throughput x albedo.
  EXPECT_LT(next[1].ray.dir.x, 0.0f);
  EXPECT_NEAR(next[1].throughput.x, 0.5f * 0.8f, 1e-6f);
  EXPECT_NEAR(next[1].throughput.y, 0.25f * 0.2f, 1e-6f);
  // Mirror, hit from above at (5, 1, 0): straight back up, throughput x albedo,
  // starting kSurfaceOffset above the surface.
  EXPECT_NEAR(next[2].ray.dir.y, 1.0f, 1e-6f);
  EXPECT_NEAR(next[2].ray.origin.y, 1.0f + kSurfaceOffset, 1e-5f);
  EXPECT_NEAR(next[2].throughput.z, 1.0f * 0.7f, 1e-6f);
}

TEST(ShadeStage, PathsAtTheDepthLimitEnd) {
  ShadeCase sc;
  RenderParams shallow = kParams;
  shallow.depth = 2;  // the paths are at bounce 1: their next ray would be the third
  PathState next;
  for (uint32_t i = 0; i < 3; ++i) EXPECT_FALSE(shade_one(i, sc.view, shallow, sc.hq.q, sc.hits, sc.film.data(), next));
}

TEST(ShadeStage, GpuPushesTheSameNextPathsAsTheCpu) {
  WT_REQUIRE_CUDA();
  ShadeCase sc;
  cuda::DeviceScene ds(sc.scene, kParams.width, kParams.height);
  cuda::WaveMemory wave(3);
  upload(wave.queue(0).ox, sc.hq.mem);  // the queue's arrays are one allocation, laid out alike
  upload(wave.hits().t, sc.t);
  upload(wave.hits().sphere, sc.sphere);
  upload(wave.counters(), std::vector<WaveCounters>{WaveCounters{{3, 0}, kTotal, 3, 0}});
  std::vector<uint32_t> list = {pack_entry(0, 2), pack_entry(0, 0), pack_entry(0, 1)};
  upload(wave.sorted(), list);
  cuda::DeviceBuffer<float> film(35 * 3, "test");
  film.zero("test");
  cuda::launch_shade(ds.view(), kParams, wave, 0, wave.sorted(), 3, film.get(), nullptr);
  ASSERT_EQ(download(wave.counters(), 1)[0].queued[1], 3u);
  HostQueue out(3);
  WT_CUDA(cudaMemcpy(out.mem.data(), wave.queue(1).ox, out.mem.size() * sizeof(float), cudaMemcpyDeviceToHost), "test");
  std::map<uint32_t, PathState> gpu;
  for (uint32_t i = 0; i < 3; ++i) gpu[out.q.load(i).path] = out.q.load(i);
  for (uint32_t i = 0; i < 3; ++i) {
    PathState cpu;
    ASSERT_TRUE(shade_one(i, sc.view, kParams, sc.hq.q, sc.hits, sc.film.data(), cpu));
    ASSERT_EQ(gpu.count(cpu.path), 1u);
    const PathState& g = gpu[cpu.path];
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(g.ray.dir[k], cpu.ray.dir[k], 1e-5f);
      EXPECT_NEAR(g.ray.origin[k], cpu.ray.origin[k], 1e-5f);
      EXPECT_NEAR(g.throughput[k], cpu.throughput[k], 1e-6f);
    }
    EXPECT_EQ(g.bounce, cpu.bounce);
  }
}

}  // namespace
}  // namespace wt

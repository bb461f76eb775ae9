// Each wavefront stage on its own, on fixed inputs, on both backends: the test body
// is written once and runs over the CPU executor and over the CUDA executor (where a
// device is present), as the wavefront driver itself does.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <memory>
#include <random>

#include "cpu/executor.hpp"
#include "cuda/device_scene.hpp"
#include "cuda/executor.cuh"
#include "stages/wavefront.hpp"
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
constexpr int kPixels = 7 * 5;

// What a test needs of a backend besides its executor: a scene view in its memory,
// and copies between its memory and the test's vectors.
struct CpuSide {
  using Exec = cpu::Executor;
  static constexpr const char* kName = "cpu";
  static constexpr float kTolerance = 0.0f;  // the test's reference is computed by the same code
  static bool available() { return true; }
  static std::unique_ptr<Exec> make() { return std::make_unique<Exec>(0); }
  struct SceneData {
    SceneData(const Scene& s, int w, int h) : view(host_view(s, w, h, images)) {}
    std::vector<ImageView> images;
    SceneView view;
  };
  template <class T>
  static void upload(T* dst, const std::vector<T>& v) {
    std::copy(v.begin(), v.end(), dst);
  }
  template <class T>
  static std::vector<T> download(const T* src, size_t n) {
    return std::vector<T>(src, src + n);
  }
};

struct CudaSide {
  using Exec = cuda::Executor;
  static constexpr const char* kName = "cuda";
  static constexpr float kTolerance = 1e-5f;  // the device's and the host's math libraries differ in rounding
  static bool available() { return test::cuda_available(); }
  static std::unique_ptr<Exec> make() { return std::make_unique<Exec>(); }
  struct SceneData {
    SceneData(const Scene& s, int w, int h) : device(s, w, h), view(device.view()) {}
    cuda::DeviceScene device;
    SceneView view;
  };
  template <class T>
  static void upload(T* dst, const std::vector<T>& v) {
    WT_CUDA(cudaMemcpy(dst, v.data(), v.size() * sizeof(T), cudaMemcpyHostToDevice), "test");
  }
  template <class T>
  static std::vector<T> download(const T* src, size_t n) {
    std::vector<T> v(n);
    WT_CUDA(cudaMemcpy(v.data(), src, n * sizeof(T), cudaMemcpyDeviceToHost), "test");
    return v;
  }
};

template <class Side>
class Stages : public testing::Test {
 protected:
  void SetUp() override {
    if (!Side::available()) GTEST_SKIP() << "no CUDA device";
    ex = Side::make();
  }

  // A wave of `capacity` slots in the backend's memory, every byte zeroed.
  WaveView wave(size_t capacity) {
    const size_t temp = Side::Exec::temp_bytes(capacity);
    memory.push_back(std::make_unique<Memory>(ex->alloc(wave_bytes(capacity, temp), "test")));
    size_t bytes = 0;
    WaveView w = lay_out_wave(memory.back()->get(), capacity, temp, &bytes);
    ex->zero(memory.back()->get(), bytes);
    return w;
  }

  template <class T>
  T* array(size_t n) {
    memory.push_back(std::make_unique<Memory>(ex->alloc(n * sizeof(T), "test")));
    ex->zero(memory.back()->get(), n * sizeof(T));
    return reinterpret_cast<T*>(memory.back()->get());
  }

  using Memory = decltype(std::declval<typename Side::Exec&>().alloc(0, ""));
  std::unique_ptr<typename Side::Exec> ex;
  std::vector<std::unique_ptr<Memory>> memory;
};

struct SideName {
  template <class Side>
  static std::string GetName(int) {
    return Side::kName;
  }
};

using Sides = testing::Types<CpuSide, CudaSide>;
TYPED_TEST_SUITE(Stages, Sides, SideName);

// A queue's slot as a value, read back from the backend's memory.
template <class Side>
PathState download_slot(const PathQueue& q, uint32_t i) {
  PathState s;
#define WT_TEST_FIELD(T, array, member) s.member = Side::download(q.array + i, 1)[0];
  WT_PATH_FIELDS(WT_TEST_FIELD)
#undef WT_TEST_FIELD
  return s;
}

template <class Side>
void upload_slots(const PathQueue& q, const std::vector<PathState>& states) {
#define WT_TEST_FIELD(T, array, member)                                  \
  {                                                                      \
    std::vector<T> column;                                               \
    for (const PathState& s : states) column.push_back(s.member);        \
    Side::upload(q.array, column);                                       \
  }
  WT_PATH_FIELDS(WT_TEST_FIELD)
#undef WT_TEST_FIELD
}

// ---------- generate (inside intersect's launch) ----------

TYPED_TEST(Stages, IntersectStartsCameraPathsInTheFreeSlots) {
  using Side = TypeParam;
  Scene scene = stage_scene();
  typename Side::SceneData sd(scene, kParams.width, kParams.height);
  WaveView w = this->wave(16);
  float* film = this->template array<float>(kPixels * 3);
  // 5 paths wait in slots 0..4 (all zero: rays from the origin along nothing, path
  // 0); the free slots 5..15 start paths 40..50.
  Side::upload(w.counters, std::vector<WaveCounters>{WaveCounters{{5, 0}, 40, 0, 0}});
  this->ex->launch(stage::kIntersect, 16,
                   IntersectItem<kAllKinds>{sd.view, kParams, w.queue[0], w.hits, w.entries, w.counters, 0, kTotal, 0, 16, film});
  std::vector<ImageView> images;
  const SceneView host = host_view(scene, kParams.width, kParams.height, images);
  for (uint32_t slot = 5; slot < 16; ++slot) {
    PathState s = download_slot<Side>(w.queue[0], slot);
    ASSERT_EQ(s.path, 40 + slot - 5);
    EXPECT_EQ(s.bounce, 0u);
    Ray expect = primary_ray(host, kParams, s.path % kPixels, s.path / kPixels);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(s.ray.origin[k], expect.origin[k], Side::kTolerance);
      EXPECT_NEAR(s.ray.dir[k], expect.dir[k], Side::kTolerance);
    }
    EXPECT_EQ(s.throughput, vec3(1.0f));
  }
  // The waiting paths' slots are left alone.
  for (uint32_t slot = 0; slot < 5; ++slot) EXPECT_EQ(download_slot<Side>(w.queue[0], slot).path, 0u);
}

TEST(GenerateStage, StartPathIsTheCameraRayOfTheSlotsPath) {
  Scene scene = stage_scene();
  std::vector<ImageView> images;
  const SceneView view = host_view(scene, kParams.width, kParams.height, images);
  const PathState s = start_path(9, 5, 40, 0, view, kParams);
  EXPECT_EQ(s.path, 44u);
  EXPECT_EQ(s.bounce, 0u);
  EXPECT_EQ(s.throughput, vec3(1.0f));
  const Ray expect = primary_ray(view, kParams, 44 % kPixels, 44 / kPixels);
  EXPECT_EQ(s.ray.origin, expect.origin);
  EXPECT_EQ(s.ray.dir, expect.dir);
  // In a pass that starts at sample 2, the same path index is two samples later.
  const PathState later = start_path(9, 5, 40, 2, view, kParams);
  const Ray expect_later = primary_ray(view, kParams, 44 % kPixels, 2 + 44 / kPixels);
  EXPECT_EQ(later.path, 44u);
  EXPECT_EQ(later.ray.dir, expect_later.dir);
  EXPECT_NE(later.ray.dir, s.ray.dir);
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

TYPED_TEST(Stages, IntersectFindsClosestHitsAddsSkyForMissesAndCountsRays) {
  using Side = TypeParam;
  Scene scene = stage_scene();
  typename Side::SceneData sd(scene, kParams.width, kParams.height);
  WaveView w = this->wave(8);
  float* film = this->template array<float>(kPixels * 3);
  upload_slots<Side>(w.queue[0], known_rays());
  // All paths handed out: live = queued = 4; slots 4..7 must come out as misses.
  Side::upload(w.counters, std::vector<WaveCounters>{WaveCounters{{4, 77}, kTotal, 0, 100}});
  this->ex->launch(stage::kIntersect, 8,
                   IntersectItem<kAllKinds>{sd.view, kParams, w.queue[0], w.hits, w.entries, w.counters, 0, kTotal, 0, 8, film});
  this->ex->launch(stage::kIntersect, 1, AdvanceCountersItem{w.counters, 0, kTotal, 8});

  const auto t = Side::download(w.hits.t, 4);
  const auto sphere = Side::download(w.hits.prim, 4);
  const auto instance = Side::download(w.hits.instance, 4);
  const auto entries = Side::download(w.entries, 8);
  const auto image = Side::download(film, kPixels * 3);
  EXPECT_NEAR(t[0], 7.5f, 1e-5f);
  EXPECT_EQ(sphere[0], sphere_at(scene, vec3(0, 0, 1.5f)));
  EXPECT_NEAR(t[1], 9.0f, 1e-5f);
  EXPECT_EQ(sphere[1], sphere_at(scene, vec3(0, 0, 0)));
  EXPECT_NEAR(t[2], 9.0f, 1e-5f);
  EXPECT_EQ(sphere[2], sphere_at(scene, vec3(5, 0, 0)));
  EXPECT_EQ(instance[0], 0);
  EXPECT_EQ(instance[3], -1);
  for (uint32_t i = 0; i < 3; ++i) {
    EXPECT_EQ(entry_slot(entries[i]), i);
    EXPECT_EQ(entry_key(entries[i]), scene.materials[scene.sphere_materials[sphere[i]]].sort_key);
  }
  for (uint32_t i = 3; i < 8; ++i) EXPECT_EQ(entry_key(entries[i]), kSortKeyMiss) << i;
  // The miss added throughput x sky (straight up: the zenith colour) to pixel 3, and nothing else was added.
  EXPECT_NEAR(image[9], 0.5f * 0.5f, 1e-6f);
  EXPECT_NEAR(image[10], 0.25f * 0.7f, 1e-6f);
  EXPECT_NEAR(image[11], 1.0f * 1.0f, 1e-6f);
  for (size_t i = 0; i < image.size(); ++i) {
    if (i < 9 || i > 11) EXPECT_EQ(image[i], 0.0f) << "film[" << i << "]";
  }
  const WaveCounters after = Side::download(w.counters, 1)[0];
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

TYPED_TEST(Stages, CompactKeepsExactlyTheLiveEntriesInOrder) {
  using Side = TypeParam;
  const uint32_t n = 100000;
  WaveView w = this->wave(n);
  const auto in = random_entries(n, 2, true);
  Side::upload(w.entries, in);
  this->ex->select(stage::kCompact, w.entries, w.selected, &w.counters->hits, n, HitSomething{}, w.temp,
                   w.temp_bytes);
  const uint32_t hits = Side::download(&w.counters->hits, 1)[0];
  std::vector<uint32_t> expect;
  for (uint32_t e : in) {
    if (entry_key(e) != kSortKeyMiss) expect.push_back(e);
  }
  // Exactly the live entries, each once, in their order.
  EXPECT_EQ(Side::download(w.selected, hits), expect);
}

TYPED_TEST(Stages, SortOrdersByKeyStablyAsAPermutation) {
  using Side = TypeParam;
  const uint32_t n = 100000;
  const int key_bits = 5;
  WaveView w = this->wave(n);
  const auto in = random_entries(n, 4, false);
  Side::upload(w.selected, in);
  const uint32_t* sorted = this->ex->sort(stage::kSort, w.selected, w.entries, n, sort_bits(key_bits), w.temp,
                                          w.temp_bytes);
  ASSERT_TRUE(sorted == w.selected || sorted == w.entries);
  const auto out = Side::download(sorted, n);
  // Ordered by key; within a key, the input's (ascending slot) order; the same entries.
  std::vector<uint32_t> expect = in;
  std::stable_sort(expect.begin(), expect.end(),
                   [](uint32_t a, uint32_t b) { return entry_key(a) < entry_key(b); });
  EXPECT_EQ(out, expect);
}

// ---------- shade ----------

// One path per sphere of the stage scene, arriving head-on along -z, +x or -y,
// after intersect has run on them on the host (so the hit records are real).
// shade_one for scenes without emitters: no light sample comes out.
template <class Scene>
bool shade_path(uint32_t slot, const Scene& view, const RenderParams& rp, const PathQueue& q, const HitQueue& hits,
                float* film, PathState& next) {
  ShadowRay shadow;
  uint32_t pixel;
  const bool alive = shade_one(slot, 0, view, rp, q, hits, film, next, shadow, pixel);
  EXPECT_FALSE(shadow.valid);
  return alive;
}

struct ShadeCase {
  Scene scene = stage_scene();
  std::vector<ImageView> images;
  SceneView view = host_view(scene, kParams.width, kParams.height, images);
  std::vector<PathState> rays = known_rays();
  std::vector<float> t = std::vector<float>(3);
  std::vector<int32_t> instance = std::vector<int32_t>(3);
  std::vector<int32_t> prim = std::vector<int32_t>(3);
  std::vector<float> b1 = std::vector<float>(3), b2 = std::vector<float>(3);
  std::vector<float> film = std::vector<float>(kPixels * 3, 0.0f);
  HitQueue hits{t.data(), instance.data(), prim.data(), b1.data(), b2.data()};
  cpu::HostMemory memory{queue_bytes(3)};
  PathQueue q;

  static size_t queue_bytes(size_t capacity) {
    Arena sizing(nullptr);
    PathQueue::take(sizing, capacity);
    return sizing.size();
  }

  ShadeCase() {
    rays.resize(3);
    Arena arena(memory.get());
    q = PathQueue::take(arena, 3);
    for (uint32_t i = 0; i < 3; ++i) {
      rays[i].bounce = 1;
      rays[i].path = 7 + i;
      q.store(i, rays[i]);
      intersect_one(i, rays[i].ray, view, kParams, q, hits, film.data());
    }
  }
};

TEST(ShadeStage, EachMaterialScattersAsItsDefinitionSays) {
  ShadeCase sc;
  PathState next[3];
  for (uint32_t i = 0; i < 3; ++i) {
    ASSERT_TRUE(shade_path(i, sc.view, kParams, sc.q, sc.hits, sc.film.data(), next[i])) << i;
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
  // starting the sphere's offset above the surface.
  EXPECT_NEAR(next[2].ray.dir.y, 1.0f, 1e-6f);
  EXPECT_NEAR(next[2].ray.origin.y, 1.0f + kSphereSurfaceOffset, 1e-5f);
  EXPECT_NEAR(next[2].throughput.z, 1.0f * 0.7f, 1e-6f);
}

TEST(ShadeStage, PathsAtTheDepthLimitEnd) {
  ShadeCase sc;
  RenderParams shallow = kParams;
  shallow.depth = 2;  // the paths are at bounce 1: their next ray would be the third
  PathState next;
  for (uint32_t i = 0; i < 3; ++i) EXPECT_FALSE(shade_path(i, sc.view, shallow, sc.q, sc.hits, sc.film.data(), next));
}

TYPED_TEST(Stages, ShadePushesEachListedPathsNextBounceOnce) {
  using Side = TypeParam;
  ShadeCase sc;
  typename Side::SceneData sd(sc.scene, kParams.width, kParams.height);
  WaveView w = this->wave(3);
  float* film = this->template array<float>(kPixels * 3);
  upload_slots<Side>(w.queue[0], sc.rays);
  Side::upload(w.hits.t, sc.t);
  Side::upload(w.hits.instance, sc.instance);
  Side::upload(w.hits.prim, sc.prim);
  Side::upload(w.hits.b1, sc.b1);
  Side::upload(w.hits.b2, sc.b2);
  Side::upload(w.selected, std::vector<uint32_t>{pack_entry(0, 2), pack_entry(0, 0), pack_entry(0, 1)});
  this->ex->launch(stage::kShade, 3,
                   ShadeItem<kAllKinds>{sd.view, kParams, w.queue[0], w.hits, w.queue[1], &w.counters->queued[1],
                                        w.shadows, &w.counters->shadows, w.selected, 0, film});
  ASSERT_EQ(Side::download(&w.counters->queued[1], 1)[0], 3u);
  std::map<uint32_t, PathState> pushed;
  for (uint32_t i = 0; i < 3; ++i) {
    PathState s = download_slot<Side>(w.queue[1], i);
    pushed[s.path] = s;
  }
  for (uint32_t i = 0; i < 3; ++i) {
    PathState expect;
    ASSERT_TRUE(shade_path(i, sc.view, kParams, sc.q, sc.hits, sc.film.data(), expect));
    ASSERT_EQ(pushed.count(expect.path), 1u);
    const PathState& got = pushed[expect.path];
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(got.ray.dir[k], expect.ray.dir[k], Side::kTolerance);
      EXPECT_NEAR(got.ray.origin[k], expect.ray.origin[k], Side::kTolerance);
      EXPECT_NEAR(got.throughput[k], expect.throughput[k], Side::kTolerance);
    }
    EXPECT_EQ(got.bounce, expect.bounce);
  }
}

// ---------- shadow ----------

// Shadow rays from around the stage scene, in all directions and to all lengths:
// the stage adds exactly the contributions of those that nothing blocks before
// their tmax (brute force over the spheres decides), to their pixels; slots past
// the queued count do nothing; then the next counter update counts the rays and
// empties the queue.
TYPED_TEST(Stages, ShadowAddsExactlyTheUnblockedSamples) {
  using Side = TypeParam;
  Scene scene = stage_scene();
  typename Side::SceneData sd(scene, kParams.width, kParams.height);
  const uint32_t n = 60, capacity = 64;
  WaveView w = this->wave(capacity);
  float* film = this->template array<float>(kPixels * 3);
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> pos(-3.0f, 7.0f), length(0.5f, 12.0f);
  std::normal_distribution<float> g;
  std::vector<ShadowState> shadows;
  std::vector<float> expect(kPixels * 3, 0.0f);
  int blocked = 0;
  for (uint32_t i = 0; i < n; ++i) {
    ShadowState s;
    s.ray = Ray{vec3(pos(rng), pos(rng) * 0.3f, pos(rng) * 0.3f), glm::normalize(vec3(g(rng), g(rng), g(rng)))};
    if (i % 2 == 0) s.ray.dir = glm::normalize(-s.ray.origin + vec3(g(rng), g(rng), g(rng)) * 0.3f);  // toward the spheres
    s.tmax = length(rng);
    s.contribution = vec3(static_cast<float>(i + 1), 0.5f, 0.25f * static_cast<float>(i));
    s.pixel = i % kPixels;
    bool hit = false;
    for (const SphereGeom& sg : scene.spheres) {
      float t;
      hit = hit || intersect_sphere(s.ray, vec3(sg.x, sg.y, sg.z), sg.w, kSphereTMin, s.tmax, t);
    }
    blocked += hit;
    if (!hit) {
      for (int k = 0; k < 3; ++k) expect[3 * s.pixel + k] += s.contribution[k];
    }
    shadows.push_back(s);
  }
  ASSERT_GT(blocked, 10);
  ASSERT_LT(blocked, static_cast<int>(n) - 10);
#define WT_TEST_FIELD(T, array, member)                                  \
  {                                                                      \
    std::vector<T> column;                                               \
    for (const ShadowState& s : shadows) column.push_back(s.member);     \
    Side::upload(w.shadows.array, column);                               \
  }
  WT_SHADOW_FIELDS(WT_TEST_FIELD)
#undef WT_TEST_FIELD
  WaveCounters counters{};
  counters.shadows = n;
  counters.shadow_rays = 1000;
  Side::upload(w.counters, std::vector<WaveCounters>{counters});
  this->ex->launch(stage::kShadow, capacity, ShadowItem<kAllKinds>{sd.view, w.shadows, w.counters, film});
  // The next bounce's counter update (intersect's) counts them and empties the queue.
  this->ex->launch(stage::kIntersect, 1, AdvanceCountersItem{w.counters, 0, 0, capacity});
  const auto image = Side::download(film, kPixels * 3);
  for (size_t i = 0; i < image.size(); ++i) EXPECT_NEAR(image[i], expect[i], 1e-5f * (1.0f + expect[i])) << i;
  const WaveCounters after = Side::download(w.counters, 1)[0];
  EXPECT_EQ(after.shadow_rays, 1000u + n);
  EXPECT_EQ(after.shadows, 0u);
}

}  // namespace
}  // namespace wt

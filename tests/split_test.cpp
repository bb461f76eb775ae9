// A render split over several devices (dispatch/split.hpp): on host "devices" of the
// CPU backend, and on one GPU named twice (the split's logic on a machine with one
// device). The N-way image is the one-way image within float-summation rounding (a
// pixel's samples summed in other groups); bit for bit with the CUDA megakernel on
// two devices, whose ten passes are then the split's ten chunks. Checkpoint
// passes, resumption, stopping and a failing device behave as on one device.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "app/job.hpp"
#include "cuda/buffer.hpp"
#include "cuda/cuda_backend.hpp"
#include "cuda/cuda_wavefront.hpp"
#include "device/device.hpp"
#include "dispatch/renderer.hpp"
#include "dispatch/split.hpp"
#include "errors/errors.hpp"
#include "queues/path_queue.hpp"
#include "render_support.hpp"
#include "test_support.hpp"

namespace wt {
namespace {

using test::mean;
using test::options_for;

// The bound of a split against one device: a pixel's sum of 12 samples added in
// other groups, relatively (float rounding of a few additions).
constexpr float kReorderBound = 1e-5f;

const Scene& quick() {
  static const Scene scene = load_scene(test::repo_path("scenes/quick.json"));
  return scene;
}

RenderOptions quick_options(Backend b, Kernel k, std::vector<int> devices) {
  RenderOptions o = options_for(b, k, 64, 36, 12, 8, 3, 5);
  o.devices = std::move(devices);
  return o;
}

void expect_same_image(const RenderResult& one, const RenderResult& split, bool bitwise, const std::string& what) {
  ASSERT_EQ(one.rgb.size(), split.rgb.size()) << what;
  for (size_t i = 0; i < one.rgb.size(); ++i) {
    if (bitwise) {
      ASSERT_EQ(one.rgb[i], split.rgb[i]) << what << " " << i;
    } else {
      ASSERT_NEAR(one.rgb[i], split.rgb[i], kReorderBound * (1.0f + std::fabs(one.rgb[i]))) << what << " " << i;
    }
  }
  EXPECT_EQ(one.rays, split.rays) << what;
  EXPECT_EQ(one.shadow_rays, split.shadow_rays) << what;
  EXPECT_EQ(one.paths, split.paths) << what;
  EXPECT_EQ(one.samples, split.samples) << what;
}

TEST(Split, HostDevicesRenderTheOneDeviceImage) {
  for (Kernel k : {Kernel::Megakernel, Kernel::Wavefront}) {
    const RenderResult one = render(quick(), quick_options(Backend::Cpu, k, {}));
    for (const std::vector<int>& devices : {std::vector<int>{0, 1}, std::vector<int>{0, 1, 2}}) {
      const RenderResult split = render(quick(), quick_options(Backend::Cpu, k, devices));
      const std::string what = std::string(kernel_name(k)) + " on " + std::to_string(devices.size());
      expect_same_image(one, split, false, what);
      ASSERT_EQ(split.shares.size(), devices.size()) << what;
      int samples = 0, chunks = 0;
      uint64_t paths = 0;
      for (const DeviceShare& s : split.shares) {
        // The wavefront's devices take blocks of the paths as they ask: one may, by
        // timing, take none.
        if (k == Kernel::Megakernel) {
          EXPECT_GT(s.chunks, 0) << what << ": " << s.device << " got no chunk";
        }
        samples += s.samples;
        chunks += s.chunks;
        paths += s.paths;
      }
      EXPECT_EQ(paths, one.paths) << what;
      if (k == Kernel::Megakernel) {
        EXPECT_EQ(samples, 12) << what;
        EXPECT_EQ(chunks, std::min(12, std::max(kMinChunks, kChunksPerDevice * static_cast<int>(devices.size()))))
            << what;
      } else {
        // One pass of 64 x 36 x 12 paths in blocks of a 1/(8 x devices) share.
        const uint64_t share = one.paths / (8 * devices.size());
        EXPECT_EQ(samples, 0) << what;
        EXPECT_EQ(static_cast<uint64_t>(chunks), (one.paths + share - 1) / share) << what;
      }
      EXPECT_TRUE(one.shares.empty());
    }
  }
}

// Checkpoint passes: after_pass sees the samples grow chunk by chunk in order, and
// each film it reads is the one-device render of that many samples; returning false
// stops the render there, interrupted, with the samples so far.
TEST(Split, PassesArriveInOrderAndStopWhereAsked) {
  RenderOptions o = quick_options(Backend::Cpu, Kernel::Megakernel, {0, 1, 2});
  o.samples_per_pass = 2;
  std::vector<int32_t> seen;
  std::vector<float> at_six;
  o.after_pass = [&](int32_t samples, const FilmReader& film) {
    seen.push_back(samples);
    if (samples == 6) at_six = film();
    return samples < 8;
  };
  const RenderResult r = render(quick(), o);
  // (Three devices: twelve chunks, one sample each; passes of at most 2 samples
  // are respected by making the chunks no larger.)
  ASSERT_EQ(seen.size(), 8u);
  for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], static_cast<int32_t>(i + 1));
  EXPECT_EQ(seen.back(), 8);
  EXPECT_TRUE(r.interrupted);
  EXPECT_EQ(r.samples, 8);

  RenderOptions six = quick_options(Backend::Cpu, Kernel::Megakernel, {});
  six.params.spp = 6;
  const RenderResult first_six = render(quick(), six);
  ASSERT_EQ(at_six.size(), first_six.rgb.size());
  for (size_t i = 0; i < at_six.size(); ++i) {
    ASSERT_NEAR(at_six[i] / 6.0f, first_six.rgb[i], kReorderBound * (1.0f + first_six.rgb[i])) << i;
  }
}

// Resuming from a film of the first samples, split, gives the whole render.
TEST(Split, AResumedSplitRenderIsTheWholeRender) {
  const RenderResult whole = render(quick(), quick_options(Backend::Cpu, Kernel::Megakernel, {}));
  RenderOptions part = quick_options(Backend::Cpu, Kernel::Megakernel, {});
  part.sample_count = 5;
  RenderResult first = render(quick(), part);
  for (float& v : first.rgb) v *= 5.0f;  // back to sums
  RenderOptions rest = quick_options(Backend::Cpu, Kernel::Megakernel, {0, 1});
  rest.first_sample = 5;
  rest.initial_film = &first.rgb;
  const RenderResult resumed = render(quick(), rest);
  EXPECT_EQ(resumed.samples, 12);
  for (size_t i = 0; i < whole.rgb.size(); ++i) ASSERT_NEAR(resumed.rgb[i], whole.rgb[i], 1e-6f * (1 + whole.rgb[i]));
}

// A device that fails stops the render: the error is the device's, of its kind,
// named after it, and no result comes back.
TEST(Split, AFailingDeviceFailsTheRenderAndSaysWhich) {
  const RenderOptions o = quick_options(Backend::Cpu, Kernel::Megakernel, {});
  std::atomic<int> chunks_done{0};
  auto make = [&](size_t d) -> ChunkRenderer {
    if (d == 2) throw DeviceError("out of device memory");
    return [&](const RenderOptions& chunk) {
      ++chunks_done;
      return render(quick(), chunk);
    };
  };
  try {
    render_split(o, {"gpu:0", "gpu:1", "gpu:2"}, make);
    FAIL() << "the render should have failed";
  } catch (const DeviceError& e) {
    EXPECT_EQ(std::string(e.what()), "gpu:2: out of device memory");
  }
  // Device 1's first chunk fails; device 0 waits for that before it finishes its
  // own, so that it cannot take every chunk first.
  std::atomic<bool> failed{false};
  auto bad_chunk = [&](size_t d) -> ChunkRenderer {
    return [d, &o, &failed](const RenderOptions&) -> RenderResult {
      if (d == 1) {
        failed = true;
        throw InputError("width x height: too large for this device");
      }
      while (!failed) std::this_thread::yield();
      RenderResult r;
      r.rgb.assign(static_cast<size_t>(o.params.width) * o.params.height * 3, 0.0f);
      return r;
    };
  };
  EXPECT_THROW(render_split(o, {"gpu:0", "gpu:1"}, bad_chunk), InputError);
  // A chunk whose film has the wrong size is the device's failure, not a crash.
  auto short_film = [](size_t) -> ChunkRenderer { return [](const RenderOptions&) { return RenderResult{}; }; };
  EXPECT_THROW(render_split(o, {"gpu:0"}, short_film), DeviceError);
}

// A device that keeps its chunks' sums (as a GPU does, in its memory) adds every
// chunk to them and brings them back once; with after_pass, which must see the film
// after every chunk, it is asked for every chunk's sums instead.
TEST(Split, ADeviceThatKeepsItsSumsBringsThemBackOnce) {
  const RenderOptions o = quick_options(Backend::Cpu, Kernel::Megakernel, {});
  const RenderResult one = render(quick(), o);
  std::mutex m;
  std::atomic<int> kept_chunks{0}, plain_chunks{0}, collects{0}, prepares{0};
  // The sums a device brings back are its renderer's: destroying the renderer
  // spoils them, so an image made after that would show it.
  struct SpoiledWithTheRenderer {
    std::shared_ptr<std::vector<float>> sums;
    ~SpoiledWithTheRenderer() { std::fill(sums->begin(), sums->end(), std::nanf("")); }
  };
  auto keeping = [&](size_t) -> DeviceRenderer {
    auto sums = std::make_shared<std::vector<float>>();
    auto spoiled = std::make_shared<SpoiledWithTheRenderer>(SpoiledWithTheRenderer{sums});
    return {[&](const RenderOptions& chunk) {
              ++plain_chunks;
              return render_sums(quick(), chunk);
            },
            [&, sums](const RenderOptions& chunk) {
              ++kept_chunks;
              RenderResult r = render_sums(quick(), chunk);
              std::lock_guard<std::mutex> lock(m);
              if (sums->empty()) sums->assign(r.rgb.size(), 0.0f);
              for (size_t i = 0; i < r.rgb.size(); ++i) (*sums)[i] += r.rgb[i];
              r.rgb.clear();
              return r;
            },
            [&, sums, spoiled] {
              ++collects;
              return FilmSums{sums->data(), sums->size()};
            },
            [&, sums](const RenderOptions&) {
              ++prepares;
              EXPECT_TRUE(sums->empty()) << "prepared before any chunk";
            }};
  };
  RenderResult split = render_split(o, {"gpu:0", "gpu:1", "gpu:2"}, keeping);
  take_mean(split);
  expect_same_image(one, split, false, "kept sums");
  EXPECT_EQ(kept_chunks, std::min(12, std::max(kMinChunks, kChunksPerDevice * 3)));
  EXPECT_EQ(plain_chunks, 0);
  EXPECT_EQ(collects, 3);
  EXPECT_EQ(prepares, 3);

  RenderOptions watched = o;
  int passes = 0;
  watched.after_pass = [&](int32_t, const FilmReader&) { return ++passes > 0; };
  kept_chunks = plain_chunks = collects = prepares = 0;
  RenderResult in_order = render_split(watched, {"gpu:0", "gpu:1"}, keeping);
  take_mean(in_order);
  expect_same_image(one, in_order, false, "chunk order");
  EXPECT_EQ(kept_chunks, 0);
  EXPECT_EQ(plain_chunks, std::min(12, std::max(kMinChunks, kChunksPerDevice * 2)));
  EXPECT_EQ(passes, plain_chunks);
  EXPECT_EQ(prepares, 0);
}

// A pass watcher that fails (a checkpoint that cannot be written) fails the render
// with its error once the devices have stopped; it neither hangs nor aborts.
TEST(Split, AFailingPassWatcherFailsTheRender) {
  RenderOptions o = quick_options(Backend::Cpu, Kernel::Megakernel, {0, 1});
  int passes = 0;
  o.after_pass = [&](int32_t, const FilmReader&) -> bool {
    if (++passes == 2) throw std::runtime_error("checkpoint: disk full");
    return true;
  };
  try {
    render(quick(), o);
    FAIL() << "the render went on";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "checkpoint: disk full");
  }
  EXPECT_EQ(passes, 2);
}

// A path feed hands out each path of each pass once, in blocks of at most what the
// device asks and a 1/(8 x devices) share of the pass, and nothing once stopped.
TEST(PathFeedTest, EveryPathOnceInBoundedBlocks) {
  PathFeed feed(2);
  std::vector<int> seen(1000, 0);
  std::vector<PathFeed::Block> blocks;
  for (;;) {
    const PathFeed::Block b = feed.take(0, 1000, blocks.size() % 2 ? 40 : 1000);
    if (b.empty()) break;
    EXPECT_LE(b.end - b.first, blocks.size() % 2 ? 40u : 62u);  // 1000 / 16
    for (uint32_t p = b.first; p < b.end; ++p) ++seen[p];
    blocks.push_back(b);
  }
  for (size_t p = 0; p < seen.size(); ++p) ASSERT_EQ(seen[p], 1) << p;
  for (size_t i = 1; i < blocks.size(); ++i) EXPECT_EQ(blocks[i].first, blocks[i - 1].end);
  EXPECT_EQ(feed.given(), 1000u);
  // Another pass counts from its own start.
  EXPECT_EQ(feed.take(1, 500, 10).first, 0u);
  EXPECT_EQ(feed.given(), 1010u);
  feed.stop();
  EXPECT_TRUE(feed.take(1, 500, 10).empty());
  EXPECT_TRUE(feed.take(2, 500, 10).empty());
}

// Two fed host devices over several passes (a lowered path limit per pass) and a
// resumed range: the image is the one-device image, every path traced once.
TEST(Split, FedWavefrontDevicesOverSeveralPassesRenderTheOneDeviceImage) {
  RenderOptions o = quick_options(Backend::Cpu, Kernel::Wavefront, {});
  o.max_paths_per_pass = 64 * 36 * 5;  // passes of 5, 5 and 2 samples
  o.first_sample = 0;
  const RenderResult one = render(quick(), o);
  o.devices = {0, 1};
  const RenderResult split = render(quick(), o);
  expect_same_image(one, split, false, "three passes");
  uint64_t paths = 0;
  for (const DeviceShare& s : split.shares) paths += s.paths;
  EXPECT_EQ(paths, 64u * 36 * 12);

  o.first_sample = 4;
  o.sample_count = 5;
  o.devices = {};
  const RenderResult part = render(quick(), o);
  o.devices = {0, 1, 2};
  expect_same_image(part, render(quick(), o), false, "samples 4 to 8");
}

TEST(Split, DeviceListsAreParsedAndChecked) {
  using app::parse_devices;
  EXPECT_EQ(parse_devices("all", Backend::Cuda, 2), (std::vector<int>{0, 1}));
  EXPECT_TRUE(parse_devices("all", Backend::Cpu, 2).empty());
  EXPECT_EQ(parse_devices("1,0", Backend::Cuda, 2), (std::vector<int>{1, 0}));
  EXPECT_EQ(parse_devices("0,1,2", Backend::Cpu, 0), (std::vector<int>{0, 1, 2}));
  for (const char* bad : {"0,", "a", "0;1", "-1", ",0", "0,,1"}) {
    EXPECT_THROW(parse_devices(bad, Backend::Cpu, 0), InputError) << bad;
  }
  try {
    parse_devices("0,2", Backend::Cuda, 2);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "devices: 2 is not a CUDA device (2 present)");
  }
}

// On the GPU: the one device named twice runs the split's two workers, each with its
// own upload and stream of chunks; the image is the one-device image.
TEST(Split, OneGpuTwiceRendersTheOneGpuImage) {
  WT_REQUIRE_CUDA();
  for (Kernel k : {Kernel::Megakernel, Kernel::MegakernelConstant, Kernel::Wavefront}) {
    const RenderResult one = render(quick(), quick_options(Backend::Cuda, k, {0}));
    const RenderResult split = render(quick(), quick_options(Backend::Cuda, k, {0, 0}));
    // Each worker keeps its chunks' sums (the wavefront: those of the paths it took)
    // on the device: the same samples, summed in other groups.
    expect_same_image(one, split, false, kernel_name(k));
    ASSERT_EQ(split.shares.size(), 2u);
    EXPECT_EQ(split.shares[0].paths + split.shares[1].paths, one.paths);
    if (!is_wavefront(k)) {
      EXPECT_EQ(split.shares[0].samples + split.shares[1].samples, 12);
    }
  }
}

// A scene's copies kept on the device between renders (a session's): the first render
// uploads, every later one (another kernel, film size, an adaptive render, the AOVs'
// pass) takes that copy and renders what a fresh upload renders, bit for bit where the
// kernel is; a split that names the device twice holds two copies at once.
TEST(ResidentScenes, OneUploadServesRendersOfAnySettings) {
  WT_REQUIRE_CUDA();
  const std::shared_ptr<ResidentScenes> kept = keep_scene(quick(), Backend::Cuda);
  ASSERT_NE(kept, nullptr);
  EXPECT_EQ(scene_uploads(kept.get()), 0);
  EXPECT_EQ(keep_scene(quick(), Backend::Cpu), nullptr);  // the CPU renders the scene where it lies
  for (int round = 0; round < 2; ++round) {
    for (Kernel k : {Kernel::Megakernel, Kernel::MegakernelConstant, Kernel::Wavefront}) {
      for (int width : {64, 40}) {
        RenderOptions o = quick_options(Backend::Cuda, k, {0});
        o.params.width = width;
        const RenderResult fresh = render(quick(), o);
        o.resident = kept;
        const RenderResult again = render(quick(), o);
        expect_same_image(fresh, again, !is_wavefront(k), kernel_name(k));
        EXPECT_EQ(again.upload_seconds > 0, round == 0 && k == Kernel::Megakernel && width == 64);
      }
    }
  }
  RenderOptions adaptive = quick_options(Backend::Cuda, Kernel::Wavefront, {0});
  adaptive.noise_threshold = 0.05;
  RenderResult a = render(quick(), adaptive);
  adaptive.resident = kept;
  RenderResult b = render(quick(), adaptive);
  expect_same_image(a, b, false, "adaptive");
  const AovSums aovs = render_aovs(quick(), adaptive);
  adaptive.resident = nullptr;
  EXPECT_EQ(aovs.sums, render_aovs(quick(), adaptive).sums);
  EXPECT_EQ(scene_uploads(kept.get()), 1);
  RenderOptions twice = quick_options(Backend::Cuda, Kernel::Megakernel, {0, 0});
  twice.resident = kept;
  render(quick(), twice);
  EXPECT_EQ(scene_uploads(kept.get()), 2);  // the second worker's copy, kept too
  render(quick(), twice);
  EXPECT_EQ(scene_uploads(kept.get()), 2);
}

// What a kept copy keeps for its renders (the wave's memory, render_image's film)
// serves its next render, and is not counted again as memory that render needs: a
// wave of 60% of the memory left free (device memory taken beforehand, so that the
// wave is the largest, kMaxWaveSize slots, where the device has room) renders again,
// and its image too, from one copy (counted against the memory left free beside the
// kept wave, the second render would be refused). A render that does not fit beside
// the copy, another upload of the same wave, is still refused with the fit check's
// message.
TEST(ResidentScenes, WhatACopyKeepsServesItsNextRender) {
  WT_REQUIRE_CUDA();
  ASSERT_EQ(cudaSetDevice(0), cudaSuccess);
  size_t free_bytes = 0, total = 0;
  ASSERT_EQ(cudaMemGetInfo(&free_bytes, &total), cudaSuccess);
  const double per_slot = static_cast<double>(cuda::wavefront_bytes(int64_t(1) << 20)) / (1 << 20);
  RenderOptions o = quick_options(Backend::Cuda, Kernel::Wavefront, {0});
  o.wave_size = std::min(static_cast<int64_t>(kMaxWaveSize),
                         static_cast<int64_t>(0.6 * static_cast<double>(free_bytes) / per_slot));
  const int64_t pixels = static_cast<int64_t>(o.params.width) * o.params.height;
  o.params.spp = static_cast<int32_t>((o.wave_size + pixels - 1) / pixels);  // one wave's paths at least
  o.params.depth = 2;
  const size_t leave = static_cast<size_t>(static_cast<double>(cuda::wavefront_bytes(o.wave_size)) / 0.6);
  const cuda::DeviceBuffer<unsigned char> taken(free_bytes - std::min(free_bytes, leave), "test");
  const std::shared_ptr<ResidentScenes> kept = keep_scene(quick(), Backend::Cuda);
  o.resident = kept;
  const RenderResult first = render(quick(), o);
  const RenderResult again = render(quick(), o);
  expect_same_image(first, again, false, "again");
  cuda::DeviceImage image;
  render_to_device(quick(), o, image);
  image.wait();
  render_to_device(quick(), o, image);
  image.wait();
  EXPECT_EQ(scene_uploads(kept.get()), 1);
  RenderOptions beside = o;
  beside.resident = keep_scene(quick(), Backend::Cuda);
  try {
    render(quick(), beside);
    ADD_FAILURE() << "a second wave of 60% of the free memory was not refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("of device memory"), std::string::npos) << e.what();
  }
}

// A render's image finished on its device (render_to_device: a session's renders that
// keep their image there or bring it back once) holds the means render() brings back:
// bit for bit where the kernel is (the same division by the samples, in single
// precision), within the reordering bound for the wavefront; with warm-ups, and with
// a kept copy. The options it does not take are refused.
TEST(ImageOnDevice, HoldsTheMeansRenderReturns) {
  WT_REQUIRE_CUDA();
  const std::shared_ptr<ResidentScenes> kept = keep_scene(quick(), Backend::Cuda);
  const float* last_block = nullptr;
  for (Kernel k : {Kernel::Megakernel, Kernel::MegakernelConstant, Kernel::Wavefront}) {
    for (int warmup : {0, 1}) {
      const std::string what = std::string(kernel_name(k)) + " warm-ups " + std::to_string(warmup);
      RenderOptions o = quick_options(Backend::Cuda, k, {0});
      o.warmup = warmup;
      const RenderResult host = render(quick(), o);
      o.resident = kept;
      cuda::DeviceImage image;
      ASSERT_TRUE(renders_to_device(o));
      RenderResult on = render_to_device(quick(), o, image);
      image.wait();
      // With the image before let go, the kept copy writes into its block again.
      if (last_block != nullptr) {
        EXPECT_EQ(image.rgba.get(), last_block) << what;
      }
      last_block = image.rgba.get();
      EXPECT_TRUE(on.rgb.empty()) << what;
      EXPECT_EQ(on.radiance, Radiance::MeanOfSamples) << what;
      ASSERT_TRUE(image.rgba) << what;
      EXPECT_EQ(image.device, 0);
      const size_t pixels = host.rgb.size() / 3;
      std::vector<float> rgba(pixels * 4);
      cuda::copy_to_host(image.rgba.get(), rgba.size(), rgba.data());
      for (size_t p = 0; p < pixels; ++p) {
        ASSERT_EQ(rgba[4 * p + 3], 1.0f) << what << " alpha of pixel " << p;
        for (int c = 0; c < 3; ++c) on.rgb.push_back(rgba[4 * p + c]);
      }
      expect_same_image(host, on, !is_wavefront(k), what);
      EXPECT_EQ(image.nonfinite_pixels, app::count_nonfinite_pixels(host.rgb)) << what;
    }
  }
  EXPECT_EQ(scene_uploads(kept.get()), 1);
  RenderOptions adaptive = quick_options(Backend::Cuda, Kernel::Wavefront, {0});
  adaptive.noise_threshold = 0.05;
  RenderOptions two = quick_options(Backend::Cuda, Kernel::Megakernel, {0, 0});
  RenderOptions cpu = quick_options(Backend::Cpu, Kernel::Megakernel, {});
  for (const RenderOptions* o : {&adaptive, &two, &cpu}) {
    EXPECT_FALSE(renders_to_device(*o));
    cuda::DeviceImage image;
    EXPECT_THROW(render_to_device(quick(), *o, image), std::logic_error);
  }
}

// The finishing kernel over a film of known sums, with a NaN, both infinities and a
// subnormal among them: its means are take_mean's bit for bit (the NaN a NaN), and it
// counts the pixels count_nonfinite_pixels counts, after the film's queued work. The
// pixels are more than a block.
TEST(ImageOnDevice, FinishesAFilmAsTheHostDoes) {
  WT_REQUIRE_CUDA();
  RenderResult host;
  host.samples = 7;
  const size_t pixels = 1000;
  for (size_t i = 0; i < pixels * 3; ++i) host.rgb.push_back(static_cast<float>(i % 97) * 0.37f + 1e-3f);
  host.rgb[3 * 3 + 1] = std::nanf("");
  host.rgb[3 * 10] = INFINITY;
  host.rgb[3 * 999 + 2] = -INFINITY;
  host.rgb[3 * 500] = 3e-39f;  // subnormal
  host.rgb[3 * 501] = 3e38f;   // finite, its mean too
  float* film = cuda::copy_to_device(host.rgb.data(), host.rgb.size(), 0);
  // Into device memory, and into a page-locked block the kernel writes across the
  // bus, by one finisher: its count, kept, is cleared by each.
  cuda::ImageFinisher finisher;
  cuda::ImageBlocks device_blocks(cuda::ImageBlocks::Memory::Device), host_blocks(cuda::ImageBlocks::Memory::PageLocked);
  cuda::DeviceImage on_device;
  on_device.rgba = device_blocks.take(pixels * 4);
  finisher.finish(film, pixels, host.samples, on_device);
  cuda::DeviceImage on_host;
  on_host.rgba = host_blocks.take(pixels * 4);
  const float* block = on_host.rgba.get();
  finisher.finish(film, pixels, host.samples, on_host);
  on_device.wait();
  on_host.wait();
  EXPECT_FALSE(on_host.writing);
  // A film as the default stream's queued work leaves it: copied there behind the
  // clearing of 256 MiB (some 0.1 ms), which the count, on a stream of its own, must
  // wait for (read at once, the film is zeros: no pixel counted).
  {
    cuda::DeviceBuffer<float> slow(size_t(64) << 20, "test"), late(pixels * 3, "test");
    late.zero("test");
    ASSERT_EQ(cudaDeviceSynchronize(), cudaSuccess);
    slow.zero("test");
    ASSERT_EQ(cudaMemcpyAsync(late.get(), film, pixels * 3 * sizeof(float), cudaMemcpyDeviceToDevice, nullptr),
              cudaSuccess);
    cuda::DeviceImage after;
    after.rgba = device_blocks.take(pixels * 4);
    finisher.finish(late.get(), pixels, host.samples, after);
    after.wait();
    EXPECT_EQ(after.nonfinite_pixels, 3u);
  }
  cuda::free_on_device(film);
  EXPECT_EQ(on_host.rgba.get(), block);  // written where it was given
  cuda::DeviceImage none;
  EXPECT_THROW(finisher.finish(film, pixels, host.samples, none), std::logic_error);
  std::vector<float> from_device(pixels * 4);
  cuda::copy_to_host(on_device.rgba.get(), from_device.size(), from_device.data());
  take_mean(host);
  for (const float* rgba : {static_cast<const float*>(from_device.data()), block}) {
    for (size_t p = 0; p < pixels; ++p) {
      for (int c = 0; c < 3; ++c) {
        const float want = host.rgb[3 * p + c], got = rgba[4 * p + c];
        if (std::isnan(want)) {
          EXPECT_TRUE(std::isnan(got)) << p;
        } else {
          ASSERT_EQ(want, got) << "pixel " << p << " channel " << c;
        }
      }
      ASSERT_EQ(rgba[4 * p + 3], 1.0f) << p;
    }
  }
  for (const cuda::DeviceImage* image : {&on_device, &on_host}) {
    EXPECT_EQ(image->nonfinite_pixels, 3u);
    EXPECT_EQ(image->nonfinite_pixels, app::count_nonfinite_pixels(host.rgb));
    EXPECT_EQ(image->device, 0);
  }
}

// The blocks images are finished into, page-locked or on the device: one whose owner
// let go serves the next image of its size; the two let go last are kept (blocks of
// an earlier size give way to those of the size now rendered), and a block of another
// size is new.
TEST(ImageOnDevice, BlocksServeTheNextImageOfTheirSize) {
  WT_REQUIRE_CUDA();
  for (cuda::ImageBlocks::Memory memory : {cuda::ImageBlocks::Memory::PageLocked, cuda::ImageBlocks::Memory::Device}) {
    SCOPED_TRACE(memory == cuda::ImageBlocks::Memory::Device ? "device" : "page-locked");
    cuda::ImageBlocks blocks(memory, 2);
    float* first = nullptr;
    {
      const std::shared_ptr<float> a = blocks.take(1000), b = blocks.take(1000);
      EXPECT_NE(a.get(), b.get());
      EXPECT_EQ(blocks.allocations(), 2);
      first = a.get();  // let go last (b goes first)
    }
    {
      const std::shared_ptr<float> a = blocks.take(1000), b = blocks.take(1000);
      EXPECT_EQ(a.get(), first);  // the block let go last comes first
      EXPECT_EQ(blocks.allocations(), 2);  // both kept ones
      const std::shared_ptr<float> c = blocks.take(1000);
      EXPECT_EQ(blocks.allocations(), 3);
    }
    {
      const std::shared_ptr<float> a = blocks.take(1000), b = blocks.take(1000), c = blocks.take(1000);
      EXPECT_EQ(blocks.allocations(), 4);  // of the three let go, two were kept
    }
    // Two blocks of 1000 kept; renders of another size take their place one by one.
    for (int i = 0; i < 3; ++i) {
      const std::shared_ptr<float> other = blocks.take(10);
      EXPECT_EQ(blocks.allocations(), 5);
    }
    const std::shared_ptr<float> kept = blocks.take(1000);  // the one block of 1000 still kept
    EXPECT_EQ(blocks.allocations(), 5);
  }
}

// Two GPUs where the machine has them: the split over both is the one-GPU image,
// and (chunks) both take part.
TEST(Split, TwoGpusRenderTheOneGpuImage) {
  WT_REQUIRE_CUDA();
  if (cuda::device_count() < 2) GTEST_SKIP() << "one CUDA device: the two-GPU split needs two";
  for (Kernel k : {Kernel::Megakernel, Kernel::Wavefront}) {
    const RenderResult one = render(quick(), quick_options(Backend::Cuda, k, {0}));
    const RenderResult split = render(quick(), quick_options(Backend::Cuda, k, {0, 1}));
    expect_same_image(one, split, false, kernel_name(k));
    ASSERT_EQ(split.shares.size(), 2u);
    EXPECT_EQ(split.shares[0].paths + split.shares[1].paths, one.paths);
    if (!is_wavefront(k)) {
      // (The wavefront's devices take blocks of paths as they ask: both do in
      // practice, neither is bound to.)
      EXPECT_GT(split.shares[0].chunks, 0);
      EXPECT_GT(split.shares[1].chunks, 0);
    }
  }
}

}  // namespace
}  // namespace wt

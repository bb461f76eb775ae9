// The wavefront, written once for every backend over an executor that runs named
// stages: per bounce (generate +) intersect -> compact -> (readback) -> sort (where
// it pays: sorts_bounce) -> shade -> shadow (the light samples shade queued, where the scene has lights and
// light sampling is on), with path regeneration keeping the wave full while paths
// remain. The host
// reads the counters back once per bounce (after compact), which tells it how many
// entries to sort and shade and when every path is done.
//
// An executor (cpu/executor.hpp, cuda/executor.cuh) provides:
//   Memory alloc(bytes, stage)               an owning block with get()
//   wave_memory(bytes) -> unsigned char*     a block the executor keeps (grown where a
//                                            render asks for more): renders one after
//                                            another on one executor allocate it once
//   static size_t temp_bytes(capacity)       its compact's and sort's temporary storage
//   launch(stage, n, item)                   item(i) for every i < n, in parallel
//   select(stage, in, out, count, n, pred, temp, temp_bytes)  keeps in[i] with pred, in order
//   sort(stage, keys, alternate, n, bits, temp, temp_bytes) -> the buffer holding the result
//                                            (stable, over the key bits alone)
//   read(stage, const T*) -> T               reads a value back to the host
//   zero(p, bytes), upload(float*, const vector<float>&), download(const float*, n)
//   start_timer(), stop_timer() -> seconds, elapsed_host(), take_stage_ms(count)
// Every launch goes through launch/select/sort/read with its stage, and is timed
// by the executor under that stage's name.
#pragma once

#include <array>
#include <vector>

#include "render/passes.hpp"
#include "render/render_types.hpp"
#include "stages/compact.hpp"
#include "stages/generate.hpp"
#include "stages/intersect.hpp"
#include "stages/shade.hpp"
#include "stages/sort.hpp"
#include "stages/stage.hpp"

namespace wt {

// The wavefront's stages, in the order they run. "readback" is the host's one wait
// per bounce for the counters.
namespace stage {
constexpr Stage kIntersect{0, "intersect"};
constexpr Stage kCompact{1, "compact"};
constexpr Stage kReadback{2, "readback"};
constexpr Stage kSort{3, "sort"};
constexpr Stage kShade{4, "shade"};
constexpr Stage kShadow{5, "shadow"};
constexpr std::array<Stage, 6> kAll = {kIntersect, kCompact, kReadback, kSort, kShade, kShadow};
// Shade by material kind (RenderOptions::shade_by_kind), after the stages above:
// every kind but the blend, whose hits shade as the material they pick.
static_assert(static_cast<uint32_t>(MaterialKind::Blend) + 1 == kMaterialKindCount, "the blend is the last kind");
constexpr std::array<Stage, kMaterialKindCount - 1> kShadeKinds = {
    Stage{6, "  lambertian"}, Stage{7, "  metal"},     Stage{8, "  dielectric"}, Stage{9, "  coated"},
    Stage{10, "  emissive"},  Stage{11, "  conductor"}, Stage{12, "  glass"},     Stage{13, "  plastic"},
    Stage{14, "  principled"}};
}  // namespace stage

// `wavefront` sorts a bounce's hits when they hold at least this many sort keys
// (kinds of shading work: material kind x texture kind), read from the mask
// intersect gathers. Measured on the H100 (bench/RESULTS.md, "A sort that pays or
// is skipped"): seed57, rtiow-cover and sky-sun (3-5 keys) shade no faster sorted
// and lose the sort's time; divergent (9 keys, noise textures among them) shades
// 1.6x faster sorted, far more than the sort costs. A bounce whose keys include a
// microfacet kind's sorts from two keys on: on the H200, materials.json (four keys)
// renders in 0.054 s sorted against 0.114 s unsorted, cornell-materials.json (four)
// in 0.025 s against 0.062 s.
constexpr int kSortMinKeys = 6;

// Whether `kernel` sorts a bounce whose hits hold the sort keys of `key_mask`.
inline bool sorts_bounce(Kernel kernel, uint32_t key_mask) {
  if (kernel == Kernel::WavefrontSorted) return true;
  if (kernel == Kernel::WavefrontUnsorted) return false;
  int keys = 0;
  for (uint32_t m = key_mask; m != 0; m &= m - 1) ++keys;
  return keys >= kSortMinKeys || (keys >= 2 && (key_mask & kMicrofacetKeyMask) != 0);
}

// Bytes a wave of `capacity` slots takes on the executor's memory.
template <class Exec>
size_t wavefront_bytes(size_t capacity) {
  return wave_bytes(capacity, Exec::temp_bytes(capacity));
}

// Renders with a wave of `capacity` slots, pass after pass of samples (each pass's
// paths are numbered from 0 in 32 bits); the result holds pixel sums. With a path
// feed (options.path_feed), of each pass only the blocks of paths it takes from the
// feed: it takes the next block while a bounce may still use up the one it has, so
// the wave refills across blocks and drains once a pass, when the feed is empty.
template <class Exec>
RenderResult render_wavefront(Exec& ex, const SceneView& scene, int key_bits, const RenderOptions& options,
                              int64_t capacity) {
  const RenderParams& rp = options.params;
  const bool light_sampling = scene.samples_lights(rp);
  const uint32_t shade_kinds = scene.kinds | (light_sampling ? kLightSampling : 0u);
  // The pixels a sample of a pass visits (options.active_pixels, or every one).
  const uint64_t pixels = rendered_pixels(options);
  // Passes asked for (for checkpoints) hold at least four waves' paths: every pass
  // ends with the wave draining, which a full wave's regeneration otherwise hides.
  // (With a feed every device must plan the same passes: none asked for, none by capacity.)
  const std::vector<SamplePass> passes =
      plan_passes(options, 1, options.path_feed ? 0 : 4 * static_cast<uint64_t>(capacity));
  const uint64_t all_paths = pixels * static_cast<uint64_t>(passes.empty() ? 0 : passes.back().first +
                                                                                   passes.back().count - passes.front().first);
  const uint32_t slots = static_cast<uint32_t>(capacity);
  const size_t film_floats = static_cast<size_t>(rp.width) * rp.height * 3;

  size_t bytes = 0;
  const size_t temp_bytes = Exec::temp_bytes(slots);
  const WaveView w = lay_out_wave(ex.wave_memory(wave_bytes(slots, temp_bytes)), slots, temp_bytes, &bytes);
  // The render's own film, or the one it adds into (options.device_film).
  auto film_memory = ex.alloc(options.device_film ? 0 : film_floats * sizeof(float), "wave allocation");
  auto key_memory = ex.alloc(options.shade_by_kind ? sizeof(KeyStarts) : 0, "wave allocation");
  KeyStarts* const key_starts = reinterpret_cast<KeyStarts*>(key_memory.get());
  float* film = options.device_film ? options.device_film : reinterpret_cast<float*>(film_memory.get());
  // The listed pixels, where the device reads them.
  auto active_memory = ex.alloc(options.active_pixels ? options.active_pixels->size() * sizeof(uint32_t) : 0,
                                "wave allocation");
  PassPixels pass_pixels_of{};
  if (options.active_pixels && !options.active_pixels->empty()) {
    uint32_t* active = reinterpret_cast<uint32_t*>(active_memory.get());
    ex.upload(active, *options.active_pixels);
    pass_pixels_of = PassPixels{active, static_cast<uint32_t>(options.active_pixels->size())};
  }

  RenderResult out;
  auto run = [&](bool last) {
    if (options.initial_film) {
      ex.upload(film, *options.initial_film);
    } else if (!options.device_film) {
      ex.zero(film, film_floats * sizeof(float));
    }
    std::vector<uint64_t> live_per_bounce;
    uint64_t rays = 0, shadow_rays = 0, paths_done = 0, bounces_shaded = 0, bounces_sorted = 0, blocks = 0;
    out.samples = options.first_sample;
    out.interrupted = false;
    PathFeed* const feed = last ? options.path_feed : nullptr;
    ex.start_timer();
    for (size_t pass_index = 0; pass_index < passes.size(); ++pass_index) {
      const SamplePass& pass = passes[pass_index];
      const uint32_t total = static_cast<uint32_t>(pixels * static_cast<uint64_t>(pass.count));
      const uint32_t first = static_cast<uint32_t>(pass.first);
      ex.zero(w.counters, sizeof(WaveCounters));
      // The wave generates paths up to `limit`: the pass's end, or that of the feed's
      // block it works on; `pending` is the block after it, `fed_out` when none is left.
      uint32_t limit = total;
      PathFeed::Block pending;
      bool fed_out = feed == nullptr;
      uint64_t taken = feed ? 0 : total;
      if (feed) {
        const PathFeed::Block b = feed->take(pass_index, total, slots);
        if (b.empty()) continue;
        if (b.first != 0) ex.launch(stage::kIntersect, 1, SetNextPathItem{w.counters, b.first});
        limit = b.end;
        taken += b.end - b.first;
        ++blocks;
      }
      for (int cur = 0;; cur = 1 - cur) {
        // (With the alpha bit where the scene has alpha-tested triangles:
        // geometry.hpp's kAlphaTested.)
        with_kinds<false, false, true>(scene.kinds, [&](auto kinds) {
          ex.launch(stage::kIntersect, slots,
                    IntersectItem<decltype(kinds)::value>{scene, rp, w.queue[cur], w.hits, w.entries, w.counters, cur, limit, first,
                                           slots, film, pass_pixels_of});
        });
        ex.launch(stage::kIntersect, 1, AdvanceCountersItem{w.counters, cur, limit, slots});
        ex.select(stage::kCompact, w.entries, w.selected, &w.counters->hits, slots, HitSomething{}, w.temp,
                  w.temp_bytes);
        const WaveCounters c = ex.read(stage::kReadback, w.counters);
        live_per_bounce.push_back(c.queued[cur]);
        uint32_t next_path = c.next_path;
        if (!fed_out && pending.empty() && static_cast<uint64_t>(next_path) + slots > limit) {
          // The next bounce may use the block up: take the next (one that follows it
          // extends it).
          const PathFeed::Block b = feed->take(pass_index, total, slots);
          taken += b.end - b.first;
          blocks += b.empty() ? 0 : 1;
          if (b.empty()) {
            fed_out = true;
          } else if (b.first == limit) {
            limit = b.end;
          } else {
            pending = b;
          }
        }
        if (!pending.empty() && next_path >= limit) {
          ex.launch(stage::kIntersect, 1, SetNextPathItem{w.counters, pending.first});
          next_path = pending.first;
          limit = pending.end;
          pending = PathFeed::Block{};
        }

        const uint32_t* list = w.selected;
        if (c.hits > 0) ++bounces_shaded;
        const bool sorted = c.hits > 0 && sorts_bounce(options.kernel, c.key_mask[cur]);
        if (sorted) {
          ++bounces_sorted;
          list = ex.sort(stage::kSort, w.selected, w.entries, c.hits, sort_bits(key_bits), w.temp, w.temp_bytes);
        }
        const bool by_kind = options.shade_by_kind && sorted;
        KeyStarts starts{};
        if (by_kind) {
          ex.launch(stage::kSort, kSortKeyMiss + 1, FindKeyStartsItem{list, c.hits, key_starts});
          starts = ex.read(stage::kReadback, key_starts);
        }
        with_kinds(shade_kinds, [&](auto kinds) {
          using Item = ShadeItem<decltype(kinds)::value>;
          const Item item{scene, rp, w.queue[cur], w.hits, w.queue[1 - cur], &w.counters->queued[1 - cur], w.shadows,
                          &w.counters->shadows, list, first, film, pass_pixels_of};
          if (!by_kind) {
            ex.launch(stage::kShade, c.hits, item);
          } else {
            // The sorted list holds each key's entries together: one launch per key.
            for (uint32_t k = 0; k < kSortKeyMiss; ++k) {
              const uint32_t count = starts.at[k + 1] - starts.at[k];
              if (count == 0) continue;
              Item part = item;
              part.list = list + starts.at[k];
              ex.launch(stage::kShadeKinds[static_cast<uint32_t>(sort_key_kind(k))], count, part);
            }
          }
          if (light_sampling && c.hits > 0) {
            ex.launch(stage::kShadow, c.hits, ShadowItem<decltype(kinds)::value>{scene, w.shadows, w.counters, film});
          }
        });
        if (last && options.progress) {
          options.progress(static_cast<double>(paths_done + c.next_path - c.queued[cur]) / all_paths, rays + c.rays,
                           ex.elapsed_host());
        }
        if (c.hits == 0 && next_path >= limit) {
          rays += c.rays;
          shadow_rays += c.shadow_rays;
          break;
        }
      }
      paths_done += taken;
      out.samples = pass.first + pass.count;
      if (last && options.after_pass &&
          !options.after_pass(out.samples, [&] { return ex.download(film, film_floats); })) {
        out.interrupted = out.samples < passes.back().first + passes.back().count;
        break;
      }
    }
    out.seconds = ex.stop_timer();
    out.rays = rays;
    out.shadow_rays = shadow_rays;
    out.bounces_shaded = bounces_shaded;
    out.bounces_sorted = bounces_sorted;
    out.blocks = blocks;
    out.paths = paths_done;
    const std::vector<double> ms = ex.take_stage_ms(stage::kAll.size() + stage::kShadeKinds.size());
    out.stages.clear();
    for (const Stage& s : stage::kAll) out.stages.push_back(StageTime{s.name, ms[s.index]});
    if (options.shade_by_kind) {
      for (const Stage& s : stage::kShadeKinds) {
        out.stages[stage::kShade.index].ms += ms[s.index];
        out.stages.push_back(StageTime{s.name, ms[s.index], true});
      }
    }
    out.live_per_bounce = std::move(live_per_bounce);
  };
  for (int i = 0; i < options.warmup; ++i) run(false);
  run(true);

  if (!options.device_film) out.rgb = ex.download(film, film_floats);
  out.radiance = Radiance::SumOfSamples;
  return out;
}

}  // namespace wt

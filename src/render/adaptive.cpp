#include "render/adaptive.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

namespace wt {

namespace {

// V of one quantity from its halves' means (the header's formula); both halves hold
// samples.
double variance_of_mean(double mean_a, double mean_b, int32_t n_a, int32_t n_b) {
  const double n = static_cast<double>(n_a) + n_b;
  const double d = mean_a - mean_b;
  return d * d * (static_cast<double>(n_a) * n_b) / (n * n);
}

}  // namespace

void mean_variance(const PixelHalves& h, double v[3]) {
  for (int c = 0; c < 3; ++c) {
    v[c] = h.n_a == 0 || h.n_b == 0 ? 0.0 : variance_of_mean(h.a[c] / h.n_a, h.b[c] / h.n_b, h.n_a, h.n_b);
  }
}

double relative_error_squared(const PixelHalves& h) {
  if (h.n_a == 0 || h.n_b == 0) return 0.0;
  const double ya = luminance(h.a[0], h.a[1], h.a[2]) / h.n_a;
  const double yb = luminance(h.b[0], h.b[1], h.b[2]) / h.n_b;
  const double y = (ya * h.n_a + yb * h.n_b) / (static_cast<double>(h.n_a) + h.n_b);
  const double scale = std::max(y, kNoiseFloor);
  return variance_of_mean(ya, yb, h.n_a, h.n_b) / (scale * scale);
}

std::vector<uint8_t> converged_pixels(const std::vector<double>& r2, int width, int height, double threshold) {
  std::vector<uint8_t> done(r2.size(), 0);
  const double t2 = threshold * threshold;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      double sum = 0.0;
      int count = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= width || qy >= height) continue;
          sum += r2[static_cast<size_t>(qy) * width + qx];
          ++count;
        }
      }
      done[static_cast<size_t>(y) * width + x] = sum <= t2 * count ? 1 : 0;
    }
  }
  return done;
}

int32_t step_samples(int32_t n, int32_t min_spp, int32_t spp) {
  int32_t k = std::max(min_spp, n / 4);
  k += k & 1;
  return std::max<int32_t>(0, std::min(k, spp - n));
}

namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

AdaptiveState AdaptiveState::start(size_t pixels) {
  AdaptiveState s;
  s.half_a.assign(pixels * 3, 0.0f);
  s.half_b.assign(pixels * 3, 0.0f);
  s.n_a.assign(pixels, 0);
  s.n_b.assign(pixels, 0);
  s.converged.assign(pixels, 0);
  return s;
}

std::string AdaptiveState::check(size_t pixels, int32_t spp) const {
  if (half_a.size() != pixels * 3 || half_b.size() != pixels * 3 || n_a.size() != pixels || n_b.size() != pixels ||
      converged.size() != pixels) {
    return "its adaptive state is not of " + std::to_string(pixels) + " pixels";
  }
  if (samples < 0 || samples > spp) return "its adaptive samples " + std::to_string(samples) + " lie outside 0..spp";
  for (size_t p = 0; p < pixels; ++p) {
    const int64_t n = static_cast<int64_t>(n_a[p]) + n_b[p];
    const bool counts_fit = n_a[p] >= 0 && n_b[p] >= 0 && n <= samples && (converged[p] ? true : n == samples);
    if (!counts_fit || converged[p] > 1) {
      return "pixel " + std::to_string(p) + "'s adaptive counts (" + std::to_string(n_a[p]) + ", " +
             std::to_string(n_b[p]) + ") do not fit its " + std::to_string(samples) + " samples";
    }
    for (int c = 0; c < 3; ++c) {
      const float a = half_a[3 * p + c], b = half_b[3 * p + c];
      if (!(std::isfinite(a) && std::isfinite(b) && a >= 0.0f && b >= 0.0f)) {
        return "pixel " + std::to_string(p) + "'s halves hold a sum that is not a finite radiance";
      }
    }
  }
  return "";
}

int32_t resolved_min_spp(int32_t min_spp, int32_t spp) { return min_spp > 0 ? min_spp : std::min(16, spp); }

RenderResult render_adaptive(const ChunkRenderer& render, const RenderOptions& options, double threshold,
                             int32_t min_spp, const AdaptiveHooks& hooks) {
  const RenderParams& rp = options.params;
  const size_t pixels = static_cast<size_t>(rp.width) * rp.height;
  // Each half's sums: the rounds' films added on the host.
  AdaptiveState st = hooks.resume ? *hooks.resume : AdaptiveState::start(pixels);
  auto halves_of = [&](size_t p) {
    return PixelHalves{{st.half_a[3 * p], st.half_a[3 * p + 1], st.half_a[3 * p + 2]},
                       {st.half_b[3 * p], st.half_b[3 * p + 1], st.half_b[3 * p + 2]},
                       st.n_a[p],
                       st.n_b[p]};
  };
  std::vector<uint32_t> active;
  for (size_t p = 0; p < pixels; ++p) {
    if (!st.converged[p]) active.push_back(static_cast<uint32_t>(p));
  }

  RenderResult out;
  const auto t0 = Clock::now();
  int32_t& n = st.samples;  // the samples every active pixel has
  const int32_t first_step = std::min(std::max(min_spp, 2), rp.spp);
  // Rendered paths over all the render could take (progress's fraction), from where
  // it starts.
  uint64_t paths_before = 0;
  for (size_t p = 0; p < pixels; ++p) paths_before += static_cast<uint64_t>(st.n_a[p]) + st.n_b[p];
  const double all_paths = static_cast<double>(pixels) * rp.spp;
  auto round = [&](int32_t count, bool into_a) {
    if (count <= 0 || active.empty()) return;
    RenderOptions o = options;
    o.first_sample = n;
    o.sample_count = count;
    o.active_pixels = active.size() == pixels ? nullptr : &active;
    o.progress = nullptr;
    o.after_pass = nullptr;
    o.initial_film = nullptr;
    o.warmup = 0;
    const RenderResult r = render(o);
    std::vector<float>& half = into_a ? st.half_a : st.half_b;
    std::vector<int32_t>& counts = into_a ? st.n_a : st.n_b;
    for (uint32_t p : active) {
      for (int c = 0; c < 3; ++c) half[3 * p + c] += r.rgb[3 * p + c];
      counts[p] += count;
    }
    out.rays += r.rays;
    out.shadow_rays += r.shadow_rays;
    out.paths += r.paths;
    out.seconds += r.seconds;
    out.upload_seconds = r.upload_seconds;
    out.device = r.device;
    // Of a render split over devices: each device's part of the rounds.
    if (out.shares.size() < r.shares.size()) out.shares.resize(r.shares.size());
    for (size_t d = 0; d < r.shares.size(); ++d) {
      DeviceShare& s = out.shares[d];
      s.device = r.shares[d].device;
      s.name = r.shares[d].name;
      s.chunks += r.shares[d].chunks;
      s.paths += r.shares[d].paths;
      s.seconds += r.shares[d].seconds;
      s.rays += r.shares[d].rays;
      s.shadow_rays += r.shares[d].shadow_rays;
    }
    n += count;
    if (options.progress) {
      options.progress(std::min(1.0, (paths_before + static_cast<double>(out.paths)) / all_paths), out.rays,
                       std::chrono::duration<double>(Clock::now() - t0).count());
    }
  };
  // Warm-ups, as every kernel runs them: the first round's samples, untimed and
  // dropped.
  for (int i = 0; i < options.warmup; ++i) {
    RenderOptions o = options;
    o.sample_count = std::max(1, first_step / 2);
    o.progress = nullptr;
    o.after_pass = nullptr;
    o.warmup = 0;
    render(o);
  }
  int32_t step = n == 0 ? first_step : step_samples(n, min_spp, rp.spp);
  for (; step > 0 && !active.empty(); step = step_samples(n, min_spp, rp.spp)) {
    const int32_t a = step / 2, b = step - step / 2;
    round(a, true);
    round(b, false);
    // Which pixels go on: those whose neighbourhood is still above the threshold.
    std::vector<double> r2(pixels, 0.0);
    for (size_t p = 0; p < pixels; ++p) r2[p] = relative_error_squared(halves_of(p));
    const std::vector<uint8_t> now = converged_pixels(r2, rp.width, rp.height, threshold);
    std::vector<uint32_t> going;
    for (uint32_t p : active) {
      if (now[p]) {
        st.converged[p] = 1;
      } else {
        going.push_back(p);
      }
    }
    active = std::move(going);
    if (hooks.converged) {
      uint64_t done = 0;
      for (uint8_t c : st.converged) done += c;
      hooks.converged(done);
    }
    const bool last = step_samples(n, min_spp, rp.spp) == 0 || active.empty();
    if (hooks.after_step && !hooks.after_step(st, last) && !last) {
      out.interrupted = true;
      break;
    }
  }

  out.rgb.assign(pixels * 3, 0.0f);
  out.variance.assign(pixels * 3, 0.0f);
  out.pixel_samples.assign(pixels, 0);
  for (size_t p = 0; p < pixels; ++p) {
    const int32_t count = st.n_a[p] + st.n_b[p];
    out.pixel_samples[p] = count;
    double v[3];
    mean_variance(halves_of(p), v);
    for (int c = 0; c < 3; ++c) {
      out.rgb[3 * p + c] =
          count > 0 ? static_cast<float>((st.half_a[3 * p + c] + st.half_b[3 * p + c]) / count) : 0.0f;
      out.variance[3 * p + c] = static_cast<float>(v[c]);
    }
    out.converged += st.converged[p];
  }
  out.samples = n;
  out.radiance = Radiance::MeanOfSamples;
  return out;
}

double mean_spp(const RenderResult& r) {
  if (r.pixel_samples.empty()) return 0.0;
  uint64_t samples = 0;
  for (int32_t n : r.pixel_samples) samples += static_cast<uint64_t>(n);
  return static_cast<double>(samples) / r.pixel_samples.size();
}

}  // namespace wt

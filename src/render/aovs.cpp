#include "render/aovs.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "errors/errors.hpp"
#include "wavetrace/aov.hpp"

namespace wt {

const std::vector<std::string>& aov_names() {
  static const std::vector<std::string> names = {"albedo", "normal", "depth", "position", "variance", "spp"};
  return names;
}

const char* aov_name(AovKind kind) { return aov_names()[static_cast<size_t>(kind)].c_str(); }

std::vector<AovKind> parse_aovs(const std::string& list, const std::string& field) {
  std::vector<AovKind> kinds;
  const std::string prefix = field.empty() ? "" : field + ": ";
  size_t at = 0;
  for (;;) {
    const size_t comma = list.find(',', at);
    std::string name = list.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    name.erase(0, name.find_first_not_of(" \t"));
    name.erase(name.find_last_not_of(" \t") + 1);
    const auto& names = aov_names();
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) {
      std::string known;
      for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
      throw InputError(prefix + "unknown AOV '" + name + "' (known: " + known + ")");
    }
    const AovKind kind = static_cast<AovKind>(it - names.begin());
    if (std::find(kinds.begin(), kinds.end(), kind) != kinds.end()) {
      throw InputError(prefix + "AOV '" + name + "' is named twice");
    }
    kinds.push_back(kind);
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  return kinds;
}

namespace {

// Channels [first, first + n) of each pixel's sums, divided by `over` (the samples,
// or the pixel's hits); `missing` where that is 0.
std::vector<float> means(const AovSums& a, int first, int n, bool over_hits, float missing,
                         float lo = -std::numeric_limits<float>::infinity(),
                         float hi = std::numeric_limits<float>::infinity()) {
  const size_t pixels = a.sums.size() / kAovFloats;
  std::vector<float> out(pixels * n);
  for (size_t p = 0; p < pixels; ++p) {
    const float* s = a.sums.data() + p * kAovFloats;
    const int32_t samples = a.pixel_samples.empty() ? a.samples : a.pixel_samples[p];
    const float count = over_hits ? s[kAovHits] : static_cast<float>(samples);
    for (int c = 0; c < n; ++c) {
      out[p * n + c] = count > 0.0f ? std::clamp(s[first + c] / count, lo, hi) : missing;
    }
  }
  return out;
}

}  // namespace

AovImage aov_image(AovKind kind, const AovSums& sums) {
  AovImage image{kind, aov_name(kind), {}, {}};
  switch (kind) {
    case AovKind::Albedo:
      image.channels = {"R", "G", "B"};
      image.values = means(sums, kAovAlbedo, 3, false, 0.0f);
      break;
    case AovKind::Normal:
      image.channels = {"X", "Y", "Z"};
      image.values = means(sums, kAovNormal, 3, false, 0.0f);
      break;
    case AovKind::Depth:
      image.channels = {"Z"};
      image.values = means(sums, kAovDepth, 1, true, std::numeric_limits<float>::infinity());
      break;
    case AovKind::Position:
      image.channels = {"X", "Y", "Z"};
      image.values = means(sums, kAovPosition, 3, true, 0.0f);
      break;
    case AovKind::Variance:
    case AovKind::Spp:
      throw std::logic_error("aov_image: the render's own AOV, not the first-surface pass's");
  }
  return image;
}

bool from_first_surface(AovKind kind) { return kind != AovKind::Variance && kind != AovKind::Spp; }

AovImage result_aov_image(AovKind kind, const RenderResult& result) {
  AovImage image{kind, aov_name(kind), {}, {}};
  if (kind == AovKind::Variance) {
    image.channels = {"R", "G", "B"};
    image.values = result.variance;
  } else {
    image.channels = {"Y"};
    const size_t pixels = result.rgb.size() / 3;
    image.values.assign(pixels, static_cast<float>(result.samples));
    for (size_t p = 0; p < result.pixel_samples.size() && p < pixels; ++p) {
      image.values[p] = static_cast<float>(result.pixel_samples[p]);
    }
  }
  return image;
}

std::vector<float> denoise_albedo(const AovSums& sums) {
  return means(sums, kAovAlbedo, 3, false, 0.0f, 0.0f, 1.0f);
}

std::vector<float> denoise_normal(const AovSums& sums) {
  return means(sums, kAovNormal, 3, false, 0.0f, -1.0f, 1.0f);
}

}  // namespace wt

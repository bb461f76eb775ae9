#include "app/checkpoint.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>

#include "errors/errors.hpp"
#include "image/image_io.hpp"
#include "render/settings.hpp"
#include "scene/input_file.hpp"

namespace wt::app {

namespace {

using nlohmann::json;

constexpr char kMagic[8] = {'W', 'T', 'C', 'K', 'P', 'T', '\r', '\n'};

uint32_t crc_of(const char* data, size_t bytes) {
  uLong crc = crc32(0L, Z_NULL, 0);
  while (bytes > 0) {
    const uInt chunk = static_cast<uInt>(std::min<size_t>(bytes, 1u << 30));
    crc = crc32(crc, reinterpret_cast<const Bytef*>(data), chunk);
    data += chunk;
    bytes -= chunk;
  }
  return static_cast<uint32_t>(crc);
}

template <class T>
void put(std::string& out, T value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

json identity_json(const CheckpointIdentity& id) {
  json settings = json::object();
  for (SettingId s : render_settings()) settings[setting(s).key] = get_param(id.params, s);
  json j = {{"scene", id.scene},   {"scene_crc32", id.scene_crc}, {"settings", settings},
            {"kernel", id.kernel}, {"backend", id.backend},       {"renderer", id.renderer}};
  if (id.noise_threshold != 0) j["adaptive"] = {{"noise_threshold", id.noise_threshold}, {"min_spp", id.min_spp}};
  return j;
}

[[noreturn]] void damaged(const std::string& path, const std::string& what) {
  throw InputError(path + ": not a usable checkpoint: " + what);
}

// A header's count: a JSON integer (not 2.5, not "2") in lo..hi.
int64_t whole_number(const std::string& path, const json& value, const std::string& key, int64_t lo, int64_t hi) {
  if (!value.is_number_integer()) {
    damaged(path, "its " + key + " is " + value.dump() + ", not a whole number");
  }
  const bool negative = value.is_number_unsigned() ? false : value.get<int64_t>() < 0;
  const int64_t v = negative ? value.get<int64_t>()
                             : static_cast<int64_t>(std::min<uint64_t>(value.get<uint64_t>(), uint64_t{INT64_MAX}));
  if (v < lo || v > hi) {
    damaged(path, "its " + key + " is " + value.dump() + ", outside " + std::to_string(lo) + ".." + std::to_string(hi));
  }
  return v;
}

// The header's identity and samples, each field checked.
void read_header(const std::string& path, const std::string& text, Checkpoint& c) {
  try {
    const json header = json::parse(text);
    c.identity.scene = header.at("scene").get<std::string>();
    c.identity.scene_crc = header.at("scene_crc32").get<uint32_t>();
    for (SettingId s : render_settings()) {
      const Setting& info = setting(s);
      set_param(c.identity.params, s, whole_number(path, header.at("settings").at(info.key), info.key, info.lo, info.hi));
    }
    c.identity.kernel = header.at("kernel").get<std::string>();
    c.identity.backend = header.at("backend").get<std::string>();
    c.identity.renderer = header.at("renderer").get<std::string>();
    if (header.contains("adaptive")) {
      const json& a = header.at("adaptive");
      if (!a.at("noise_threshold").is_number()) damaged(path, "its adaptive noise_threshold is not a number");
      c.identity.noise_threshold = a.at("noise_threshold").get<double>();
      c.identity.min_spp = static_cast<int32_t>(whole_number(path, a.at("min_spp"), "min_spp", 0, kMaxSpp));
    }
    c.samples = static_cast<int32_t>(whole_number(path, header.at("samples"), "samples", 0, c.identity.params.spp));
  } catch (const nlohmann::json::exception& e) {
    damaged(path, std::string("its header cannot be read (") + e.what() + ")");
  }
}

// The bytes after the header, read in order: each array a u64 count, then its values.
class Body {
 public:
  Body(const std::string& path, const std::string& bytes, size_t at, const RenderParams& p)
      : path_(path), bytes_(bytes), at_(at),
        render_("a " + std::to_string(p.width) + " x " + std::to_string(p.height) + " render's") {}

  // An array of exactly `expected` values of T.
  template <class T>
  std::vector<T> array(uint64_t expected, const std::string& what) {
    uint64_t count = 0;
    take(&count, sizeof count, what);
    if (count != expected) {
      damaged(path_, "its " + what + " holds " + std::to_string(count) + " values; " + render_ + " holds " +
                         std::to_string(expected));
    }
    std::vector<T> out(count);
    take(out.data(), count * sizeof(T), what);
    return out;
  }

  // Nothing but the CRC-32 is left.
  void end() const {
    if (at_ + sizeof(uint32_t) != bytes_.size()) damaged(path_, "its film is not the size its header says");
  }

 private:
  void take(void* to, size_t n, const std::string& what) {
    if (bytes_.size() < sizeof(uint32_t) || at_ + n > bytes_.size() - sizeof(uint32_t)) {
      damaged(path_, "its " + what + " is cut short");
    }
    std::memcpy(to, bytes_.data() + at_, n);
    at_ += n;
  }

  const std::string& path_;
  const std::string& bytes_;
  size_t at_;
  std::string render_;
};

// A film of sums of radiance (which is never negative, so neither is a sum of
// samples of it): every value finite and at least 0.
void check_film(const std::string& path, const std::vector<float>& film, int32_t width, const char* what) {
  for (size_t i = 0; i < film.size(); ++i) {
    const float v = film[i];
    if (!std::isfinite(v) || v < 0.0f) {
      const size_t pixel = i / 3;
      const size_t w = static_cast<size_t>(width);
      damaged(path, std::string("its ") + what + "'s pixel (" + std::to_string(pixel % w) + ", " +
                        std::to_string(pixel / w) + ") holds " +
                        (std::isnan(v) ? std::string("NaN") : std::isinf(v) ? "an infinity" : std::to_string(v)) +
                        "; a sum of radiance is finite and at least 0");
    }
  }
}

// What follows the header at byte `at`: the film of the render's size, or of an
// adaptive render its halves, counts and converged pixels.
void read_body(const std::string& path, const std::string& bytes, size_t at, uint32_t format, Checkpoint& c) {
  const RenderParams& p = c.identity.params;
  const uint64_t pixels = static_cast<uint64_t>(p.width) * static_cast<uint64_t>(p.height);
  Body body(path, bytes, at, p);
  if (format == kCheckpointFormat) {
    c.film = body.array<float>(3 * pixels, "film");
    body.end();
    check_film(path, c.film, p.width, "film");
    return;
  }
  AdaptiveState a;
  a.samples = c.samples;
  a.half_a = body.array<float>(3 * pixels, "first half's film");
  a.half_b = body.array<float>(3 * pixels, "second half's film");
  a.n_a = body.array<int32_t>(pixels, "first half's counts");
  a.n_b = body.array<int32_t>(pixels, "second half's counts");
  a.converged = body.array<uint8_t>(pixels, "converged pixels");
  body.end();
  check_film(path, a.half_a, p.width, "first half's film");
  check_film(path, a.half_b, p.width, "second half's film");
  const std::string wrong = a.check(pixels, p.spp);
  if (!wrong.empty()) damaged(path, wrong);
  c.adaptive = std::move(a);
}

template <class T>
void put_array(std::string& out, const std::vector<T>& values) {
  put<uint64_t>(out, values.size());
  out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

}  // namespace

CheckpointIdentity checkpoint_identity(const std::string& scene, const std::map<std::string, std::string>& defines,
                                       const RenderParams& params, const std::string& kernel,
                                       const std::string& backend) {
  std::string bytes = read_input_file(scene, input::kScene);
  for (const auto& [name, value] : defines) bytes += "\n-D " + name + "=" + value;
  CheckpointIdentity id;
  id.scene = scene;
  id.scene_crc = crc_of(bytes.data(), bytes.size());
  id.params = params;
  id.kernel = kernel;
  id.backend = backend;
  return id;
}

// Layout (little-endian): magic, u32 format, u32 header length, the header (JSON:
// identity and samples), the body (each array a u64 count and its values): the film,
// or (format 2) an adaptive render's halves, counts and converged pixels; then u32
// CRC-32 of all before.
void write_checkpoint(const std::string& path, const Checkpoint& c) {
  json header = identity_json(c.identity);
  header["samples"] = c.adaptive ? c.adaptive->samples : c.samples;
  const std::string text = header.dump();
  std::string out(kMagic, sizeof kMagic);
  put<uint32_t>(out, c.adaptive ? kAdaptiveCheckpointFormat : kCheckpointFormat);
  put<uint32_t>(out, static_cast<uint32_t>(text.size()));
  out += text;
  if (c.adaptive) {
    put_array(out, c.adaptive->half_a);
    put_array(out, c.adaptive->half_b);
    put_array(out, c.adaptive->n_a);
    put_array(out, c.adaptive->n_b);
    put_array(out, c.adaptive->converged);
  } else {
    put_array(out, c.film);
  }
  put<uint32_t>(out, crc_of(out.data(), out.size()));
  write_file(path, out);
}

Checkpoint read_checkpoint(const std::string& path) {
  const std::string bytes = read_input_file(path, input::kCheckpoint);
  const size_t fixed = sizeof kMagic + 2 * sizeof(uint32_t);
  if (bytes.size() < fixed + sizeof(uint64_t) + sizeof(uint32_t) ||
      std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) {
    damaged(path, "it does not start as a wavetrace checkpoint does");
  }
  uint32_t stored_crc = 0;
  std::memcpy(&stored_crc, bytes.data() + bytes.size() - sizeof stored_crc, sizeof stored_crc);
  if (crc_of(bytes.data(), bytes.size() - sizeof stored_crc) != stored_crc) {
    damaged(path, "its checksum does not match (the file is damaged or was cut short)");
  }
  uint32_t format = 0, header_bytes = 0;
  std::memcpy(&format, bytes.data() + sizeof kMagic, sizeof format);
  std::memcpy(&header_bytes, bytes.data() + sizeof kMagic + sizeof format, sizeof header_bytes);
  if (format != kCheckpointFormat && format != kAdaptiveCheckpointFormat) {
    damaged(path, "format version " + std::to_string(format) + "; this wavetrace reads versions " +
                      std::to_string(kCheckpointFormat) + " and " + std::to_string(kAdaptiveCheckpointFormat));
  }
  if (fixed + header_bytes + sizeof(uint64_t) + sizeof(uint32_t) > bytes.size()) damaged(path, "its header is cut short");
  Checkpoint c;
  read_header(path, bytes.substr(fixed, header_bytes), c);
  if ((format == kAdaptiveCheckpointFormat) != (c.identity.noise_threshold != 0)) {
    damaged(path, format == kAdaptiveCheckpointFormat ? "format 2 (an adaptive render's) without its adaptive header"
                                                      : "an adaptive header in format 1");
  }
  read_body(path, bytes, fixed + header_bytes, format, c);
  return c;
}

void require_same_render(const std::string& path, const CheckpointIdentity& then, const CheckpointIdentity& now) {
  auto refuse = [&](const std::string& what) {
    throw InputError(path + ": the checkpoint is of another render: " + what);
  };
  if (then.renderer != now.renderer) refuse("made by " + then.renderer + ", this is " + now.renderer);
  if (then.scene_crc != now.scene_crc) {
    refuse("scene " + then.scene + " (CRC-32 " + std::to_string(then.scene_crc) + "), not " + now.scene +
           " as it is now (CRC-32 " + std::to_string(now.scene_crc) + ")");
  }
  for (SettingId s : render_settings()) {
    const int64_t a = get_param(then.params, s), b = get_param(now.params, s);
    if (a != b) {
      refuse(std::string(setting(s).key) + " " + std::to_string(a) + " in the checkpoint, " + std::to_string(b) +
             " now");
    }
  }
  if (then.noise_threshold != now.noise_threshold || then.min_spp != now.min_spp) {
    const auto adaptive = [](const CheckpointIdentity& id) {
      if (id.noise_threshold == 0) return std::string("a uniform render");
      char text[96];
      std::snprintf(text, sizeof text, "noise_threshold %g, min_spp %d", id.noise_threshold, id.min_spp);
      return std::string(text);
    };
    refuse(adaptive(then) + " in the checkpoint, " + adaptive(now) + " now");
  }
  if (then.kernel != now.kernel || then.backend != now.backend) {
    refuse(then.backend + "/" + then.kernel + " in the checkpoint, " + now.backend + "/" + now.kernel + " now");
  }
}

}  // namespace wt::app

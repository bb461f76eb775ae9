// Scene files: textures, and the images that image textures and the environment read.
#include <ImathBox.h>
#include <ImfArray.h>
#include <IexBaseExc.h>
#include <ImfIO.h>
#include <ImfRgbaFile.h>
#include <stb/stb_image.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <utility>

#include "errors/errors.hpp"
#include "scene/input_file.hpp"
#include "scene/scene_reader.hpp"
#include "wavetrace/film.hpp"

namespace wt {

void SceneReader::read_texture(const json& j, const JsonPath& path) {
  object(j, path);
  remember(texture_names_, name(j, path), scene_.textures.size(), "texture", path);
  size_t type = type_of(j, path, "texture", {"checker", "noise", "image", "uv_checker"});
  // Image textures' defaults: untransformed, u repeating and v clamped (the
  // spheres' mapping runs v pole to pole).
  Texture t = image_texture(-1, Wrap::Repeat, Wrap::Clamp);
  // The UV transform of image textures (and of the UV checker, an image).
  auto uv_transform = [&] {
    if (j.contains("uv_offset")) t.uv_offset = pair(j["uv_offset"], path / "uv_offset");
    if (j.contains("uv_scale")) t.uv_scale = pair(j["uv_scale"], path / "uv_scale");
    if (j.contains("uv_rotation")) {
      const float r = number(j["uv_rotation"], path / "uv_rotation");
      t.uv_cos = std::cos(r);
      t.uv_sin = std::sin(r);
    }
  };
  if (type == 0) {
    check_keys(j, path, {"name", "type", "size", "even", "odd"}, "checker");
    t.kind = TextureKind::Checker;
    t.scale = positive(required(j, path, "size"), path / "size");
    t.a = colour(required(j, path, "even"), path / "even");
    t.b = colour(required(j, path, "odd"), path / "odd");
  } else if (type == 1) {
    check_keys(j, path, {"name", "type", "scale", "octaves", "high", "low"}, "noise");
    t.kind = TextureKind::Noise;
    t.scale = positive(required(j, path, "scale"), path / "scale");
    t.octaves = j.contains("octaves") ? static_cast<int32_t>(integer(j["octaves"], path / "octaves", 1, 16)) : 7;
    t.a = colour(required(j, path, "high"), path / "high");
    t.b = colour(required(j, path, "low"), path / "low");
  } else if (type == 3) {
    // Squares in UV space, two to the unit: `even` where u and v are both in the
    // lower or both in the upper half of their unit (after the transform), `odd`
    // elsewhere. Held as a 2 x 2 image of those colours, read nearest and repeated,
    // so the squares are exact at every distance.
    check_keys(j, path, {"name", "type", "even", "odd", "uv_offset", "uv_scale", "uv_rotation"}, "uv_checker");
    const vec3 even = colour(required(j, path, "even"), path / "even");
    const vec3 odd = colour(required(j, path, "odd"), path / "odd");
    t.kind = TextureKind::Image;
    t.wrap_u = t.wrap_v = Wrap::Repeat;
    t.filter = t.magnify = Filter::Nearest;
    uv_transform();
    Image im;
    im.path = source() + "#" + (path / "even").str();
    im.width = im.height = 2;
    for (const vec3& c : {even, odd, odd, even}) im.texels.insert(im.texels.end(), {c.x, c.y, c.z, 1.0f});
    t.image = static_cast<int32_t>(scene_.images.size());
    scene_.images.push_back(std::move(im));
  } else {
    check_keys(j, path,
               {"name", "type", "file", "colorspace", "uv_offset", "uv_scale", "uv_rotation", "wrap", "filter"},
               "image");
    if (j.contains("filter")) {
      t.filter = static_cast<Filter>(choice(j["filter"], path / "filter", {"bilinear", "trilinear", "nearest"}));
      if (t.filter == Filter::Nearest) t.magnify = Filter::Nearest;
    }
    t.kind = TextureKind::Image;
    uv_transform();
    if (j.contains("wrap")) {
      static const std::vector<std::string> kWraps = {"repeat", "clamp", "mirror"};
      const json& w = j["wrap"];
      if (w.is_string()) {
        t.wrap_u = t.wrap_v = static_cast<Wrap>(choice(w, path / "wrap", kWraps));
      } else {
        if (!w.is_array() || w.size() != 2) fail_at(path / "wrap", "must be a wrap mode or a pair of them [u, v]");
        t.wrap_u = static_cast<Wrap>(choice(w[0], path / "wrap" / size_t{0}, kWraps));
        t.wrap_v = static_cast<Wrap>(choice(w[1], path / "wrap" / size_t{1}, kWraps));
      }
    }
    bool srgb = true;
    if (j.contains("colorspace")) {
      std::string cs = string(j["colorspace"], path / "colorspace");
      if (cs != "srgb" && cs != "linear") {
        fail_at(path / "colorspace", "unknown colorspace '" + cs + "' (expected srgb, linear)");
      }
      srgb = cs == "srgb";
    }
    t.image = image(string(required(j, path, "file"), path / "file"), srgb, path / "file");
  }
  scene_.textures.push_back(t);
}

int32_t SceneReader::image(const std::string& file, bool srgb, const JsonPath& path) {
  std::string resolved = (base_dir_ / file).lexically_normal().string();
  std::string why;
  int32_t index = image_at(resolved, srgb, why);
  if (index < 0) fail_at(path, "cannot read image '" + resolved + "' (" + why + ")");
  return index;
}

int32_t SceneReader::bump_texture(const Texture& heights, HeightChannel channel) {
  const auto key = std::make_tuple(heights.image, channel, heights.wrap_u, heights.wrap_v);
  auto known = gradients_.find(key);
  int32_t image;
  if (known != gradients_.end()) {
    image = known->second;
  } else {
    const auto start = Clock::now();
    Image gradient = height_gradient(scene_.images[static_cast<size_t>(heights.image)], channel, heights.wrap_u,
                                     heights.wrap_v);
    texture_seconds_ += seconds_since(start);
    image = static_cast<int32_t>(scene_.images.size());
    scene_.images.push_back(std::move(gradient));
    gradients_.emplace(key, image);
  }
  Texture t = heights;
  t.image = image;
  scene_.textures.push_back(t);
  return static_cast<int32_t>(scene_.textures.size() - 1);
}

int32_t SceneReader::image_file(const std::string& resolved, bool srgb, const std::string& referrer,
                                const std::string* embedded) {
  std::string why;
  int32_t index = image_at(resolved, srgb, why, embedded);
  if (index < 0) throw InputError(referrer + ": cannot read texture image '" + resolved + "' (" + why + ")");
  return index;
}

namespace {

// Reads an image file whole (a regular file within the image limit); false with the
// reason alone (the caller names the file).
bool read_image_file(const std::string& path, std::string& bytes, std::string& why) {
  try {
    bytes = read_input_file(path, input::kImage);
  } catch (const InputFileError& e) {
    why = e.reason;
    return false;
  }
  return true;
}

// The bytes of a file for stb, noting whether the decoder asked for more than the
// file holds. For Radiance data, what follows the file is a supply of newlines that
// never runs out: stb's Radiance decoder reads a run-length count of 0 at the end of
// a truncated file (its reads return 0 there) and loops without end. A newline ends
// the header's lines (an empty line ends the header), and as a run-length count
// (10) it always makes progress or an error, so the decoder ends. For the other
// formats nothing follows (stb ends on its own). (stb asks again only for a byte it
// needs: a short read ends its buffer where the file ends; but its format probes
// may ask past the end of a file of a few dozen bytes.)
struct StbBytes {
  std::string bytes;
  bool pad = false;  // newlines past the end (Radiance data)
  size_t at = 0;
  bool overran = false;    // asked for bytes with none left
  bool short_read = false;  // asked for more bytes than were left (a valid file's last read may be)

  static int read(void* user, char* data, int size) {
    auto& p = *static_cast<StbBytes*>(user);
    if (size <= 0) return 0;
    if (p.at < p.bytes.size()) {
      const size_t n = std::min(static_cast<size_t>(size), p.bytes.size() - p.at);
      std::memcpy(data, p.bytes.data() + p.at, n);
      p.at += n;
      p.short_read = p.short_read || (n < static_cast<size_t>(size) && p.at > n);  // not the first read
      return static_cast<int>(n);
    }
    p.overran = true;
    if (!p.pad) return 0;
    std::memset(data, '\n', static_cast<size_t>(size));
    return size;
  }
  static void skip(void* user, int n) {
    auto& p = *static_cast<StbBytes*>(user);
    const int64_t to = static_cast<int64_t>(p.at) + n;
    p.at = to < 0 ? 0 : static_cast<size_t>(to);
  }
  static int eof(void* user) {
    auto& p = *static_cast<StbBytes*>(user);
    return p.pad ? 0 : p.at >= p.bytes.size();
  }

  bool load(const std::string& path, std::string& why) {
    if (!read_image_file(path, bytes, why)) return false;
    take();
    return true;
  }
  // `bytes` set: notes whether they are Radiance data.
  void take() {
    pad = stbi_is_hdr_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()), static_cast<int>(std::min<size_t>(
                                                                                      bytes.size(), INT32_MAX))) != 0;
  }
};

// Decodes a file's bytes with one of stb's callback loaders (stbi_loadf_from_callbacks,
// stbi_load_from_callbacks) over StbBytes, in the file's own channels. Null with the
// reason when stb refuses the file, saying so where the file ended before the decoder
// was done, or where a Radiance decode needed bytes past its end.
template <class Texel>
Texel* decode_with_stb(StbBytes& file, Texel* (*load)(const stbi_io_callbacks*, void*, int*, int*, int*, int), int& w,
                       int& h, int& channels, std::string& why) {
  const stbi_io_callbacks callbacks{&StbBytes::read, &StbBytes::skip, &StbBytes::eof};
  Texel* data = load(&callbacks, &file, &w, &h, &channels, 0);
  if (!data) {
    // (A file that no decoder recognises may be shorter than their probes read.)
    const std::string reason = stbi_failure_reason();
    why = (file.overran || file.short_read) && reason != "unknown image type"
              ? "the file is cut short: it ends before its image does (" + reason + ")"
              : reason;
    return nullptr;
  }
  if (file.overran && file.pad) {
    stbi_image_free(data);
    why = "the file is cut short: it ends before its pixels do";
    return nullptr;
  }
  if (w < 1 || h < 1) {
    // (A BMP's header may claim a height of 0, which stb decodes as no rows.)
    stbi_image_free(data);
    why = "the image has no pixels (" + std::to_string(w) + " x " + std::to_string(h) + ")";
    return nullptr;
  }
  return data;
}

// A Radiance .hdr file through stb, widened to RGBA (alpha 1). False with the reason.
bool read_hdr(StbBytes& file, Image& im, std::string& why) {
  int w = 0, h = 0, channels = 0;
  float* data = decode_with_stb(file, &stbi_loadf_from_callbacks, w, h, channels, why);
  if (!data) return false;
  im.width = w;
  im.height = h;
  im.texels.resize(static_cast<size_t>(w) * h * 4);
  for (size_t p = 0; p < static_cast<size_t>(w) * h; ++p) {
    const float* texel = data + p * channels;
    for (int c = 0; c < 3; ++c) im.texels[4 * p + c] = texel[channels >= 3 ? c : 0];
    im.texels[4 * p + 3] = 1.0f;
  }
  stbi_image_free(data);
  return true;
}

// An 8-bit image through stb, in the file's own channels widened to RGBA here
// (stb 2.27, Debian bookworm, reads past its buffer when it converts a 16-bit PNM
// to 4 channels), decoded from sRGB where `srgb` says. Radiance data under another
// name (stb reads by content) is padded as read_hdr's is. False with the reason.
bool read_8bit(StbBytes& file, bool srgb, Image& im, std::string& why) {
  int w = 0, h = 0, channels = 0;
  stbi_uc* data = decode_with_stb(file, &stbi_load_from_callbacks, w, h, channels, why);
  if (!data) return false;
  im.width = w;
  im.height = h;
  im.texels.resize(static_cast<size_t>(w) * h * 4);
  for (size_t i = 0; i < im.texels.size(); ++i) {
    const stbi_uc* texel = data + i / 4 * channels;
    bool alpha = i % 4 == 3;
    // grey: g g g 1; grey + alpha: g g g a; RGB: r g b 1; RGBA.
    float v = alpha ? (channels % 2 == 0 ? texel[channels - 1] / 255.0f : 1.0f)
                    : texel[channels >= 3 ? i % 4 : 0] / 255.0f;
    im.texels[i] = srgb && !alpha ? decode_srgb(v) : v;
  }
  stbi_image_free(data);
  return true;
}

// OpenEXR's input stream over a file's bytes in memory (read_input_file).
class ExrBytes : public Imf::IStream {
 public:
  ExrBytes(const std::string& path, const std::string& bytes) : Imf::IStream(path.c_str()), bytes_(bytes) {}
  bool read(char c[], int n) override {
    if (n < 0 || static_cast<uint64_t>(n) > bytes_.size() - std::min<uint64_t>(at_, bytes_.size())) {
      throw Iex::InputExc("the file is cut short: it ends before its image does");
    }
    std::memcpy(c, bytes_.data() + at_, static_cast<size_t>(n));
    at_ += static_cast<uint64_t>(n);
    return at_ < bytes_.size();
  }
  uint64_t tellg() override { return at_; }
  void seekg(uint64_t pos) override { at_ = pos; }

 private:
  const std::string& bytes_;
  uint64_t at_ = 0;
};

// An OpenEXR file's RGBA through OpenEXR (missing channels read as 0, alpha as 1).
bool read_exr(const std::string& path, Image& im, std::string& why) {
  std::string bytes;
  if (!read_image_file(path, bytes, why)) return false;
  try {
    ExrBytes stream(path, bytes);
    Imf::RgbaInputFile file(stream);
    const Imath::Box2i window = file.dataWindow();
    const int64_t w64 = int64_t{window.max.x} - window.min.x + 1, h64 = int64_t{window.max.y} - window.min.y + 1;
    if (w64 <= 0 || h64 <= 0) {
      why = "the image is empty";
      return false;
    }
    // The texels are indexed with 32-bit sizes on the device, and a header of a few
    // bytes can claim any size: refuse more than 2^31 texels before allocating.
    if (w64 * h64 > (int64_t{1} << 31)) {
      why = "the image claims " + std::to_string(w64) + " x " + std::to_string(h64) +
            " texels, more than 2^31";
      return false;
    }
    const int w = static_cast<int>(w64), h = static_cast<int>(h64);
    Imf::Array2D<Imf::Rgba> pixels(h, w);
    file.setFrameBuffer(&pixels[0][0] - window.min.x - static_cast<ptrdiff_t>(window.min.y) * w, 1, w);
    file.readPixels(window.min.y, window.max.y);
    im.width = w;
    im.height = h;
    im.texels.resize(static_cast<size_t>(w) * h * 4);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const Imf::Rgba& p = pixels[y][x];
        float* t = &im.texels[4 * (static_cast<size_t>(y) * w + x)];
        t[0] = p.r;
        t[1] = p.g;
        t[2] = p.b;
        t[3] = p.a;
      }
    }
    return true;
  } catch (const std::exception& e) {
    why = e.what();
    for (char& c : why) c = c == '\n' ? ' ' : c;
    return false;
  }
}

// High-dynamic-range images are radiance: every value finite and not negative.
bool check_radiance(const Image& im, std::string& why) {
  for (size_t i = 0; i < im.texels.size(); ++i) {
    const float v = im.texels[i];
    if (!std::isfinite(v) || v < 0.0f || v > kMaxRadiance) {
      const size_t p = i / 4;
      why = "texel (" + std::to_string(p % im.width) + ", " + std::to_string(p / im.width) + ") holds " +
            (std::isfinite(v) ? std::to_string(v) : std::string(std::isnan(v) ? "NaN" : "an infinity")) +
            "; an image of radiance needs finite values in [0, 1e9]";
      return false;
    }
  }
  return true;
}

}  // namespace

int32_t SceneReader::image_at(const std::string& resolved, bool srgb, std::string& why, const std::string* embedded) {
  auto known = images_.find({resolved, srgb});
  if (known != images_.end()) return known->second;

  const auto start = Clock::now();
  Image im;
  im.path = resolved;
  // Radiance .hdr and OpenEXR files hold linear values, whatever the colorspace
  // says. An embedded image (a mesh file's) is 8-bit.
  const std::string ext = embedded ? std::string() : lower_extension(resolved);
  bool read;
  if (ext == ".exr") {
    read = read_exr(resolved, im, why) && check_radiance(im, why);
  } else {
    StbBytes file;
    if (embedded) {
      file.bytes = *embedded;
      file.take();
      read = true;
    } else {
      read = file.load(resolved, why);
    }
    read = read && (ext == ".hdr" ? read_hdr(file, im, why) && check_radiance(im, why) : read_8bit(file, srgb, im, why));
  }
  if (!read) return -1;
  im.srgb_decoded = srgb && ext != ".hdr" && ext != ".exr";
  texture_seconds_ += seconds_since(start);

  int32_t index = static_cast<int32_t>(scene_.images.size());
  scene_.images.push_back(std::move(im));
  images_.emplace(std::make_pair(resolved, srgb), index);
  return index;
}

}  // namespace wt

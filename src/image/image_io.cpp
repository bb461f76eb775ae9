#include "image/image_io.hpp"

#include <IexBaseExc.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfOutputFile.h>
#include <fcntl.h>
#include <half.h>
#include <zlib.h>

#include <cstdlib>

// stb writes the PNG (its filters, chunks and CRCs); zlib deflates it, through stb's
// hook for that (STBIW_ZLIB_COMPRESS), at its fastest level: 2.6x faster than stb's
// own deflate on a 1080p render and a fifth smaller (bench/RESULTS.md). Compiled
// here, static to this file, from the packaged header; the packaged libstb.a, built
// without the hook, still serves the other callers.
namespace {
unsigned char* deflate_for_png(unsigned char* data, int size, int* out_size, int /*quality*/) {
  uLongf bound = compressBound(static_cast<uLong>(size));
  auto* out = static_cast<unsigned char*>(std::malloc(bound));  // stb frees it with free()
  if (out == nullptr) return nullptr;
  if (compress2(out, &bound, data, static_cast<uLong>(size), Z_BEST_SPEED) != Z_OK) {
    std::free(out);
    return nullptr;
  }
  *out_size = static_cast<int>(bound);
  return out;
}
}  // namespace
#define STBIW_ZLIB_COMPRESS deflate_for_png
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <type_traits>
#include <utility>

#include "cpu/parallel.hpp"
#include "errors/errors.hpp"
#include "wavetrace/film.hpp"

namespace wt {

namespace fs = std::filesystem;

namespace {

enum class Format { Png, Pfm, Exr };

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

Format format_of(const std::string& path) {
  std::string ext = lower_extension(path);
  if (ext == ".png") return Format::Png;
  if (ext == ".pfm") return Format::Pfm;
  if (ext == ".exr") return Format::Exr;
  throw OutputError(path + ": unknown output format '" + ext + "' (use .png, .pfm or .exr)");
}

fs::path folder_of(const std::string& path) {
  fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

std::string temporary_name(const std::string& path) {
  return path + ".tmp." + std::to_string(::getpid());
}

std::string write_failure(const std::string& path, int err) {
  return path + ": cannot write (" + std::strerror(err) + ")";
}

}  // namespace

// Writes a file's bytes to its temporary file. A failed write is remembered, not
// thrown, so that the PNG encoder (C code) can call write(); finish() reports it.
class FileWriter {
 public:
  explicit FileWriter(const std::string& path) {
    staged_.path_ = path;
    staged_.tmp_ = temporary_name(path);
    fd_ = ::open(staged_.tmp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd_ < 0) {
      const int err = errno;
      staged_.tmp_.clear();  // not created: nothing to remove
      throw OutputWriteError(write_failure(path, err));
    }
  }
  ~FileWriter() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileWriter(const FileWriter&) = delete;
  FileWriter& operator=(const FileWriter&) = delete;

  // Writes all n bytes, or records why not (a short write is retried and then fails
  // with the reason: ENOSPC, EFBIG, EIO).
  void write(const void* data, size_t n) noexcept {
    const char* p = static_cast<const char*>(data);
    while (n > 0 && error_ == 0) {
      const ssize_t k = ::write(fd_, p, n);
      if (k < 0) {
        if (errno != EINTR) error_ = errno;
      } else {
        p += k;
        n -= static_cast<size_t>(k);
      }
    }
  }
  void fail(int err) noexcept {
    if (error_ == 0) error_ = err;
  }
  // Moves to byte `offset` of the file, for writers that go back to fill in a table.
  void seek(uint64_t offset) noexcept {
    if (error_ == 0 && ::lseek(fd_, static_cast<off_t>(offset), SEEK_SET) < 0) error_ = errno;
  }
  bool failed() const noexcept { return error_ != 0; }

  // Flushes to the disk and closes: errors that only show there (a full disk under
  // delayed allocation, a failed device, a network file system) are found here.
  StagedFile finish() {
    if (error_ == 0 && ::fsync(fd_) != 0) error_ = errno;
    if (::close(std::exchange(fd_, -1)) != 0 && error_ == 0) error_ = errno;
    if (error_ != 0) throw OutputWriteError(write_failure(staged_.path_, error_));  // ~StagedFile removes tmp
    return std::move(staged_);
  }

 private:
  StagedFile staged_;
  int fd_ = -1;
  int error_ = 0;
};

namespace {

void append_to_writer(void* context, void* data, int size) {
  static_cast<FileWriter*>(context)->write(data, static_cast<size_t>(size));
}

StagedFile stage_png(const std::string& path, int w, int h, const std::vector<float>& rgb, Encoding encoding) {
  // The transfer curve over the host's cores (a 1080p image is 6 M powf calls, a
  // tenth of a second on one core); each value as on one thread.
  std::vector<unsigned char> bytes(rgb.size());
  cpu::parallel_for(static_cast<int64_t>(rgb.size()), int64_t(1) << 18, std::min(8, cpu::thread_count(0)),
                    [&](int64_t begin, int64_t end, int) {
                      for (int64_t i = begin; i < end; ++i) {
                        const float v = encoding == Encoding::Srgb ? encode_srgb(rgb[i]) : encode_gamma2(rgb[i]);
                        bytes[i] = static_cast<unsigned char>(std::lround(v * 255.0f));
                      }
                    });
  FileWriter f(path);
  if (!stbi_write_png_to_func(append_to_writer, &f, w, h, 3, bytes.data(), w * 3)) f.fail(ENOMEM);  // encoder's malloc
  return f.finish();
}

// PFM: a text header ("PF" for 3 channels, "Pf" for 1), then little-endian floats,
// bottom row first.
StagedFile stage_pfm(const std::string& path, int w, int h, const std::vector<float>& values, int channels = 3) {
  FileWriter f(path);
  const std::string header =
      std::string(channels == 1 ? "Pf" : "PF") + "\n" + std::to_string(w) + " " + std::to_string(h) + "\n-1.0\n";
  f.write(header.data(), header.size());
  const size_t row = static_cast<size_t>(w) * channels;
  for (int y = h - 1; y >= 0; --y) f.write(values.data() + static_cast<size_t>(y) * row, sizeof(float) * row);
  return f.finish();
}

// OpenEXR's output stream over the file writer. A failed write is recorded rather than
// thrown: OpenEXR writes the table of row offsets from its OutputFile's destructor,
// which swallows exceptions, and finish() must still see that write's failure.
class ExrStream : public Imf::OStream {
 public:
  ExrStream(FileWriter& f, const std::string& path) : Imf::OStream(path.c_str()), f_(f) {}
  void write(const char c[], int n) override {
    f_.write(c, static_cast<size_t>(n));
    position_ += static_cast<uint64_t>(n);
  }
  uint64_t tellp() override { return position_; }
  void seekp(uint64_t position) override {
    f_.seek(position);
    position_ = position;
  }

 private:
  FileWriter& f_;
  uint64_t position_ = 0;
};

// One channel of an OpenEXR image: `values` holds it every `stride` floats, row
// after row from the top.
struct ExrChannel {
  std::string name;
  const float* values;
  size_t stride;
};

// The channels, and A (= 1), each of type T (float or half), ZIP-compressed, rows from
// the top (the header's default line order).
template <typename T>
void write_exr_pixels(Imf::OStream& stream, int w, int h, const std::vector<ExrChannel>& channels,
                      Imf::PixelType type) {
  Imf::Header header(w, h);
  Imf::FrameBuffer frame;
  const size_t pixels = static_cast<size_t>(w) * static_cast<size_t>(std::max(h, 0));
  // Float channels are read where they are (an output file only reads its frame
  // buffer); half ones are rounded to nearest into buffers of their own.
  std::vector<std::vector<T>> data;
  data.reserve(channels.size() + 1);
  for (const ExrChannel& c : channels) {
    header.channels().insert(c.name, Imf::Channel(type));
    if constexpr (std::is_same_v<T, float>) {
      char* const base = const_cast<char*>(reinterpret_cast<const char*>(c.values));
      frame.insert(c.name, Imf::Slice(type, base, sizeof(float) * c.stride, sizeof(float) * c.stride * w));
    } else {
      std::vector<T>& d = data.emplace_back(pixels);
      for (size_t i = 0; i < pixels; ++i) d[i] = T(c.values[i * c.stride]);
      frame.insert(c.name, Imf::Slice(type, reinterpret_cast<char*>(d.data()), sizeof(T), sizeof(T) * w));
    }
  }
  // One row of ones serves every row (a row stride of 0).
  std::vector<T>& alpha = data.emplace_back(static_cast<size_t>(std::max(w, 0)), T(1.0f));
  header.channels().insert("A", Imf::Channel(type));
  frame.insert("A", Imf::Slice(type, reinterpret_cast<char*>(alpha.data()), sizeof(T), 0));
  Imf::OutputFile file(stream, header);  // its destructor writes the row offsets
  file.setFrameBuffer(frame);
  file.writePixels(h);
}

std::string one_line(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

StagedFile stage_exr(const std::string& path, int w, int h, const std::vector<float>& rgb, ExrPixels pixels,
                     const std::vector<ImageLayer>& layers) {
  std::vector<ExrChannel> channels = {{"R", rgb.data(), 3}, {"G", rgb.data() + 1, 3}, {"B", rgb.data() + 2, 3}};
  for (const ImageLayer& layer : layers) {
    for (size_t c = 0; c < layer.channels.size(); ++c) {
      channels.push_back({layer.name + "." + layer.channels[c], layer.values->data() + c, layer.channels.size()});
    }
  }
  FileWriter f(path);
  try {
    ExrStream stream(f, path);
    if (pixels == ExrPixels::Float) {
      write_exr_pixels<float>(stream, w, h, channels, Imf::FLOAT);
    } else {
      write_exr_pixels<half>(stream, w, h, channels, Imf::HALF);  // rounded to nearest
    }
  } catch (const Iex::BaseExc& e) {
    // A failed write of the file's bytes is reported by finish(), with the system's
    // reason; any other refusal of the library's is reported with the library's.
    if (!f.failed()) throw OutputWriteError(path + ": cannot write (" + one_line(e.what()) + ")");
  }
  return f.finish();
}

}  // namespace

const char* nonfinite_pixels_written(const std::string& path) {
  return format_of(path) == Format::Png ? "the PNG holds them as 0 (NaN) and 255 (infinity)"
                                        : "the image holds them as they are";
}

void check_output_path(const std::string& path) {
  format_of(path);
  check_output_folder(path);
}

void check_output_folder(const std::string& path) {
  fs::path folder = folder_of(path);
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    throw OutputError(path + ": cannot write: folder '" + folder.string() + "' does not exist");
  }
  if (::access(folder.c_str(), W_OK) != 0) {
    throw OutputError(path + ": cannot write: folder '" + folder.string() + "' is not writable (" +
                      std::strerror(errno) + ")");
  }
  if (fs::is_directory(path, ec)) throw OutputError(path + ": cannot write: it is a folder");
}

StagedFile::~StagedFile() { discard(); }

StagedFile::StagedFile(StagedFile&& o) noexcept : path_(std::move(o.path_)), tmp_(std::exchange(o.tmp_, {})) {}

StagedFile& StagedFile::operator=(StagedFile&& o) noexcept {
  discard();
  path_ = std::move(o.path_);
  tmp_ = std::exchange(o.tmp_, {});
  return *this;
}

void StagedFile::discard() noexcept {
  if (!tmp_.empty()) ::unlink(tmp_.c_str());
  tmp_.clear();
}

void StagedFile::commit() {
  if (tmp_.empty()) return;
  if (::rename(tmp_.c_str(), path_.c_str()) != 0) {
    const int err = errno;
    discard();
    throw OutputWriteError(write_failure(path_, err));
  }
  tmp_.clear();
}

StagedFile stage_image(const std::string& path, int width, int height, const std::vector<float>& rgb,
                       Encoding encoding, ExrPixels exr, const std::vector<ImageLayer>& layers) {
  const Format format = format_of(path);
  if (!layers.empty() && format != Format::Exr) {
    throw std::logic_error(path + ": only an OpenEXR image holds layers");
  }
  switch (format) {
    case Format::Png: return stage_png(path, width, height, rgb, encoding);
    case Format::Pfm: return stage_pfm(path, width, height, rgb);
    case Format::Exr: return stage_exr(path, width, height, rgb, exr, layers);
  }
  throw OutputError(path + ": unknown output format");  // not reached: format_of names every format
}

StagedFile stage_pfm_image(const std::string& path, int width, int height, const std::vector<float>& values,
                           int channels) {
  if (channels != 1 && channels != 3) throw std::logic_error(path + ": a PFM holds 1 or 3 channels");
  return stage_pfm(path, width, height, values, channels);
}

StagedFile stage_file(const std::string& path, const std::string& text) {
  FileWriter f(path);
  f.write(text.data(), text.size());
  return f.finish();
}

void write_image(const std::string& path, int width, int height, const std::vector<float>& rgb, Encoding encoding,
                 ExrPixels exr) {
  stage_image(path, width, height, rgb, encoding, exr).commit();
}

void write_file(const std::string& path, const std::string& text) { stage_file(path, text).commit(); }

}  // namespace wt

#include "image/image_io.hpp"

#include <fcntl.h>
#include <stb/stb_image_write.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <utility>

#include "wavetrace/film.hpp"

namespace wt {

namespace fs = std::filesystem;

namespace {

enum class Format { Png, Pfm };

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

Format format_of(const std::string& path) {
  std::string ext = lower_extension(path);
  if (ext == ".png") return Format::Png;
  if (ext == ".pfm") return Format::Pfm;
  throw OutputError(path + ": unknown output format '" + ext + "' (use .png or .pfm)");
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
  std::vector<unsigned char> bytes(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) {
    float v = encoding == Encoding::Srgb ? encode_srgb(rgb[i]) : encode_gamma2(rgb[i]);
    bytes[i] = static_cast<unsigned char>(std::lround(v * 255.0f));
  }
  FileWriter f(path);
  if (!stbi_write_png_to_func(append_to_writer, &f, w, h, 3, bytes.data(), w * 3)) f.fail(ENOMEM);  // encoder's malloc
  return f.finish();
}

// PFM: a text header, then little-endian floats, bottom row first.
StagedFile stage_pfm(const std::string& path, int w, int h, const std::vector<float>& rgb) {
  FileWriter f(path);
  const std::string header = "PF\n" + std::to_string(w) + " " + std::to_string(h) + "\n-1.0\n";
  f.write(header.data(), header.size());
  for (int y = h - 1; y >= 0; --y) {
    f.write(rgb.data() + static_cast<size_t>(y) * w * 3, sizeof(float) * w * 3);
  }
  return f.finish();
}

}  // namespace

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
                       Encoding encoding) {
  return format_of(path) == Format::Png ? stage_png(path, width, height, rgb, encoding)
                                        : stage_pfm(path, width, height, rgb);
}

StagedFile stage_file(const std::string& path, const std::string& text) {
  FileWriter f(path);
  f.write(text.data(), text.size());
  return f.finish();
}

void write_image(const std::string& path, int width, int height, const std::vector<float>& rgb, Encoding encoding) {
  stage_image(path, width, height, rgb, encoding).commit();
}

void write_file(const std::string& path, const std::string& text) { stage_file(path, text).commit(); }

}  // namespace wt

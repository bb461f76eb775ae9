#include "scene/input_file.hpp"

#include <cctype>
#include <filesystem>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace wt {

namespace {

std::string size_text(uint64_t bytes) {
  char buf[64];
  if (bytes < input::kMiB) return std::to_string(bytes) + " bytes";
  if (bytes >= input::kGiB) {
    std::snprintf(buf, sizeof buf, "%.1f GiB", static_cast<double>(bytes) / input::kGiB);
  } else {
    std::snprintf(buf, sizeof buf, "%.1f MiB", static_cast<double>(bytes) / input::kMiB);
  }
  return buf;
}

}  // namespace

std::string not_a_regular_file(unsigned int mode) {
  if (S_ISREG(mode)) return "";
  if (S_ISDIR(mode)) return "it is a directory, not a file";
  if (S_ISFIFO(mode)) return "it is a FIFO (named pipe), not a regular file";
  if (S_ISCHR(mode)) return "it is a character device, not a regular file";
  if (S_ISBLK(mode)) return "it is a block device, not a regular file";
  if (S_ISSOCK(mode)) return "it is a socket, not a regular file";
  return "it is not a regular file";
}

namespace {

std::string too_large(uint64_t bytes, const InputKind& kind) {
  std::string held = size_text(bytes), limit = size_text(kind.max_bytes);
  if (held == limit) {  // rounded alike: the bytes themselves
    held = std::to_string(bytes) + " bytes";
    limit = std::to_string(kind.max_bytes) + " bytes";
  }
  return "it holds " + held + ", more than the " + limit + " a " + kind.what + " may hold";
}

InputFileError open_failure(const std::string& path, const InputKind& kind, int err) {
  const std::string reason = err == ELOOP ? "a loop of symbolic links" : std::strerror(err);
  return InputFileError(path + ": cannot open " + kind.what + " (" + reason + ")", "cannot open it (" + reason + ")");
}

InputFileError read_refusal(const std::string& path, const InputKind& kind, const std::string& why) {
  return InputFileError(path + ": cannot read " + kind.what + ": " + why, why);
}

}  // namespace

std::string read_input_file(const std::string& path, const InputKind& kind) {
  // O_NONBLOCK: opening a FIFO does not wait for a writer; the file is then checked
  // through its descriptor, so that what is read is what was checked.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    const int err = errno;
    // A socket cannot be opened (ENXIO): say what it is.
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
      throw read_refusal(path, kind, not_a_regular_file(st.st_mode));
    }
    throw open_failure(path, kind, err);
  }
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) throw open_failure(path, kind, errno);
  if (const std::string what = not_a_regular_file(st.st_mode); !what.empty()) throw read_refusal(path, kind, what);
  const uint64_t size = static_cast<uint64_t>(st.st_size);
  if (size > kind.max_bytes) throw read_refusal(path, kind, too_large(size, kind));
  std::string bytes;
  bytes.reserve(static_cast<size_t>(size));
  // Read to the end (the file may have changed size since fstat), never past the limit.
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string reason = std::strerror(errno);
      throw InputFileError(path + ": cannot read " + kind.what + " (" + reason + ")", "cannot read it (" + reason + ")");
    }
    if (n == 0) break;
    if (bytes.size() + static_cast<uint64_t>(n) > kind.max_bytes) {
      throw read_refusal(path, kind,
                         "it grew past the " + size_text(kind.max_bytes) + " a " + kind.what + " may hold as it was read");
    }
    bytes.append(buf, static_cast<size_t>(n));
  }
  return bytes;
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace wt

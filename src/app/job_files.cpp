#include "app/job_files.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>
#include <utility>

#include "errors/errors.hpp"
#include "image/image_io.hpp"
#include "scene/input_file.hpp"

namespace wt::app {

namespace fs = std::filesystem;

namespace {

// The path made absolute, the links of its existing part resolved.
std::string resolved_path(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec) p = fs::absolute(path, ec).lexically_normal();
  return p.string();
}

}  // namespace

std::string file_key(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    return "inode " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
  }
  return resolved_path(path);
}

std::string noisy_output(const Job& job) {
  if (!job.denoise || !job.keep_noisy || job.output.empty()) return "";
  const std::filesystem::path p(job.output);
  return (p.parent_path() / (p.stem().string() + ".noisy" + p.extension().string())).string();
}

std::vector<AovKind> job_aovs(const Job& job) {
  return job.aov.empty() ? std::vector<AovKind>{} : parse_aovs(job.aov);
}

bool job_asks_for(const Job& job, AovKind kind) {
  const std::vector<AovKind> kinds = job_aovs(job);
  return std::find(kinds.begin(), kinds.end(), kind) != kinds.end();
}

std::vector<JobFile> aov_outputs(const Job& job) {
  std::vector<JobFile> files;
  if (job.output.empty()) return files;
  const std::vector<AovKind> kinds = job_aovs(job);
  const std::filesystem::path p(job.output);
  if (p.extension() == ".exr") return files;
  for (AovKind k : kinds) {
    files.push_back({std::string(aov_name(k)) + " AOV",
                     (p.parent_path() / (p.stem().string() + "." + aov_name(k) + ".pfm")).string(), true});
  }
  return files;
}

std::vector<JobFile> job_files(const Job& job) {
  std::vector<JobFile> files;
  const auto add = [&](const char* field, const std::string& path, bool written) {
    if (!path.empty()) files.push_back({field, path, written});
  };
  add("output", job.output, true);
  add("noisy output", noisy_output(job), true);
  for (const JobFile& f : aov_outputs(job)) files.push_back(f);
  add("stats", job.stats, true);
  add("checkpoint", job.checkpoint, true);
  // Without --checkpoint the resume file is written back to.
  add("resume", job.resume, job.checkpoint.empty());
  add("scene", job.scene, false);
  return files;
}

void check_distinct_files(const Job& job) {
  const std::vector<JobFile> files = job_files(job);
  std::vector<std::string> keys;
  for (const JobFile& f : files) keys.push_back(file_key(f.path));
  for (size_t a = 0; a < files.size(); ++a) {
    for (size_t b = a + 1; b < files.size(); ++b) {
      if (keys[a] != keys[b] || !(files[a].written || files[b].written)) continue;
      // A checkpoint resumed and written to is one file, meant to be.
      if (files[a].field == std::string("checkpoint") && files[b].field == std::string("resume")) continue;
      throw OutputError(files[b].path + ": " + files[a].field + " and " + files[b].field +
                        " name the same file (" + files[a].path + " and " + files[b].path +
                        "); each of a render's files needs a file of its own");
    }
  }
}

void check_creatable(const std::string& path, const std::string& field) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISLNK(st.st_mode)) {
    throw OutputError(path + ": cannot write the " + field + ": " + not_a_regular_file(st.st_mode));
  }
  // The file is written beside its name and renamed into place (image_io.hpp): try that
  // name, and remove it at once.
  const std::string probe = path + ".tmp." + std::to_string(::getpid());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    if (errno == EEXIST) return;
    const int err = errno;
    throw OutputError(path + ": cannot write the " + field + " (" + std::strerror(err) + ")");
  }
  ::close(fd);
  ::unlink(probe.c_str());
}

CheckpointLock::CheckpointLock(const std::string& checkpoint) {
  const std::string lock_path = resolved_path(checkpoint) + ".lock";
  // The lock file's last holder removes it as it lets go: a lock taken on a file that
  // no longer has the name is let go, and the name tried again.
  for (int attempt = 0; attempt < 16; ++attempt) {
    const int fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) {
      const int err = errno;
      throw OutputError(checkpoint + ": cannot lock the checkpoint: cannot create " + lock_path + " (" +
                        std::strerror(err) + ")");
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      char pid[32] = {};
      const ssize_t n = ::pread(fd, pid, sizeof pid - 1, 0);
      ::close(fd);
      if (err == EWOULDBLOCK) {
        const std::string holder = n > 0 ? std::string(pid, static_cast<size_t>(n)) : std::string();
        throw OutputError(checkpoint + ": the checkpoint is in use by another render" +
                          (holder.empty()                            ? std::string()
                           : holder == std::to_string(::getpid()) ? std::string(" of this process")
                                                                  : " (wavetrace pid " + holder + ")") +
                          "; two renders cannot share one checkpoint");
      }
      throw OutputError(checkpoint + ": cannot lock the checkpoint (" + std::string(std::strerror(err)) + ")");
    }
    struct stat held {}, named {};
    if (::fstat(fd, &held) == 0 && ::stat(lock_path.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
        held.st_ino == named.st_ino) {
      const std::string pid = std::to_string(::getpid());
      if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) < 0) {
        // The pid is only for the message another process prints.
      }
      lock_path_ = lock_path;
      fd_ = fd;
      return;
    }
    ::close(fd);
  }
  throw OutputError(checkpoint + ": cannot lock the checkpoint: its lock file " + lock_path + " keeps changing");
}

CheckpointLock::~CheckpointLock() { release(); }

CheckpointLock::CheckpointLock(CheckpointLock&& o) noexcept
    : lock_path_(std::move(o.lock_path_)), fd_(std::exchange(o.fd_, -1)) {}

CheckpointLock& CheckpointLock::operator=(CheckpointLock&& o) noexcept {
  if (this != &o) {
    release();
    lock_path_ = std::move(o.lock_path_);
    fd_ = std::exchange(o.fd_, -1);
  }
  return *this;
}

void CheckpointLock::release() noexcept {
  if (fd_ < 0) return;
  // Removed while still held, so that no other process takes a lock on it meanwhile.
  ::unlink(lock_path_.c_str());
  ::close(fd_);
  fd_ = -1;
}

std::string colliding_jobs(const std::vector<Job>& jobs, const std::vector<bool>& refused) {
  // Every file a job writes, and every file it reads: a written file may be no other
  // job's file at all (written, or read: a scene, a resume file); files only read
  // may be shared. A job's own files are check_distinct_files's.
  struct Use {
    size_t job;
    std::string field;
    bool written;
  };
  std::map<std::string, std::vector<Use>> uses;  // file -> the jobs that use it, in order
  for (size_t i = 0; i < jobs.size(); ++i) {
    if (i < refused.size() && refused[i]) continue;
    for (const JobFile& f : job_files(jobs[i])) {
      std::vector<Use>& u = uses[file_key(f.path)];
      for (const Use& other : u) {
        if (other.job == i || !(other.written || f.written)) continue;
        const std::string a = std::to_string(other.job + 1), b = std::to_string(i + 1);
        return "jobs " + a + " and " + b + " would " + (other.written && f.written ? "write" : "write and read") +
               " the same file " + f.path + " (the " + other.field + " of job " + a + ", the " + f.field +
               " of job " + b + "); the batch is refused before any job runs";
      }
      u.push_back({i, f.field, f.written});
    }
  }
  return "";
}

}  // namespace wt::app

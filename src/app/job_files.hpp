// The files a job writes, checked before it renders: no two of them (and none of them
// and the scene it reads) may be one file, whatever links or relative paths name
// them; each must be creatable in its folder; and a checkpoint is held by one
// process at a time, through a lock kept for the render's life.
#pragma once

#include <string>
#include <vector>

#include "app/job.hpp"

namespace wt::app {

// One file of a job: what the job calls it ("output", "stats", "checkpoint",
// "resume", "scene") and its path as given.
struct JobFile {
  std::string field;
  std::string path;
  bool written = true;  // false: only read (the scene; a resume file that no checkpoint is written back to)
};

// The job's files: the image, the noisy image (--keep-noisy), the stats file, the
// checkpoint it writes (--checkpoint, or the --resume file written back to), the
// resume file it reads, and the scene.
std::vector<JobFile> job_files(const Job& job);

// Where a denoised job's render itself goes with --keep-noisy: NAME.noisy.EXT beside
// the output NAME.EXT. Empty where the job keeps none.
std::string noisy_output(const Job& job);

// The AOVs the job asks for (--aov), in its order; none where it names none. Throws
// InputError for a list --aov does not take.
std::vector<AovKind> job_aovs(const Job& job);
bool job_asks_for(const Job& job, AovKind kind);

// Where each AOV the job asks for goes, as its field ("albedo AOV") and path:
// NAME.<aov>.pfm beside an output NAME.EXT that is not OpenEXR, whose AOVs are its
// layers (none here). Throws InputError for a list --aov does not take.
std::vector<JobFile> aov_outputs(const Job& job);

// The same file for any two spellings of it: the absolute path with every link of
// its existing part resolved and "." and ".." removed, or for a file that exists its
// device and inode (hard links). Never throws.
std::string file_key(const std::string& path);

// Throws OutputError naming both fields where two of the job's files are one file and
// at least one of them is written (a checkpoint given as both --checkpoint and
// --resume is the one file it is meant to be).
void check_distinct_files(const Job& job);

// Throws OutputError naming the path where a file cannot be created in its folder
// (a missing, unwritable or read-only folder, or a name that is a folder): tried by
// creating and removing a file beside it, so that a run that passes can write it.
void check_creatable(const std::string& path, const std::string& field);

// A checkpoint held by this process: a lock on "<checkpoint>.lock" (flock, released
// by the kernel if the process dies), taken before the checkpoint is read and kept
// until the render's image is written. Throws OutputError naming the checkpoint
// where another process holds it. The lock file is removed when the lock ends.
class CheckpointLock {
 public:
  CheckpointLock() = default;
  explicit CheckpointLock(const std::string& checkpoint);
  ~CheckpointLock();
  CheckpointLock(CheckpointLock&& o) noexcept;
  CheckpointLock& operator=(CheckpointLock&& o) noexcept;
  CheckpointLock(const CheckpointLock&) = delete;
  CheckpointLock& operator=(const CheckpointLock&) = delete;

 private:
  void release() noexcept;
  std::string lock_path_;
  int fd_ = -1;
};

// A batch's jobs that would write one file (their images, stats or checkpoints), or
// of which one would write a file another reads (its scene, a resume file): one line
// naming both jobs (1-based, as the batch numbers them) and the file for the first
// such pair; empty where there is none. Jobs refused when they were read (`refused`)
// take no part.
std::string colliding_jobs(const std::vector<Job>& jobs, const std::vector<bool>& refused);

}  // namespace wt::app

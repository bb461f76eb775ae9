// Every file wavetrace reads (scene, jobs file, bench spec, mesh, MTL, texture and
// environment image, glTF buffer, checkpoint) is read through here, whole and into
// memory, before any library parses it: it must be a regular file (or a link to
// one), and no larger than its kind's stated limit. A directory, a FIFO, a device or
// a socket is refused at once with one line (never a hang: the file is opened
// without blocking and checked before a byte is read), and so is a file past its
// limit (never a read that grows without bound, as /dev/zero would).
#pragma once

#include <cstdint>
#include <string>

#include "errors/errors.hpp"
#include "scene/scene.hpp"

namespace wt {

// What read_input_file throws: the whole line, and its reason alone ("it is a
// directory, not a file", "cannot open it (No such file or directory)") for a caller
// that names the file in words of its own.
struct InputFileError : InputError {
  InputFileError(const std::string& line, std::string why) : InputError(line), reason(std::move(why)) {}
  std::string reason;
};

// The kind of an input file: its name in messages and the most bytes it may hold.
struct InputKind {
  const char* what;
  uint64_t max_bytes;
};

namespace input {
constexpr uint64_t kMiB = uint64_t{1} << 20;
constexpr uint64_t kGiB = uint64_t{1} << 30;
constexpr InputKind kScene{"scene file", 256 * kMiB};
constexpr InputKind kJobs{"jobs file", 64 * kMiB};
constexpr InputKind kBenchSpec{"bench spec", 16 * kMiB};
// tinygltf takes a file's size as an unsigned int: under 4 GiB.
constexpr InputKind kMesh{"mesh file", 4 * kGiB - 1};
constexpr InputKind kMaterialLibrary{"material library", 64 * kMiB};
constexpr InputKind kGltfBuffer{"glTF buffer", 4 * kGiB - 1};
constexpr InputKind kImage{"image", 2 * kGiB};
// The largest film the settings allow (16384 x 16384 x 3 floats) and its header.
constexpr InputKind kCheckpoint{"checkpoint", 3 * kGiB + 16 * kMiB};
}  // namespace input

// The whole file. Throws InputFileError "<path>: cannot open <what> (<reason>)", or
// "<path>: cannot read <what>: ..." for a file that is not regular or is too large.
std::string read_input_file(const std::string& path, const InputKind& kind);

// What a file of this st_mode is where it is not a regular file, in words ("it is a
// FIFO (named pipe), not a regular file"); empty for a regular file.
std::string not_a_regular_file(unsigned int mode);

// A file's extension in lower case, with its dot (".obj"); "" for none. Formats are
// told apart by it, whatever its case.
std::string lower_extension(const std::string& path);

}  // namespace wt

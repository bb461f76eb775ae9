// The errors a run reports, each with its exit code (docs/cli.md, "Faults during a
// job"), and the words their messages share. A leaf: every folder of src/ may
// include it, so that none depends on another for its errors.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace wt {

// Bad input: a scene, mesh, texture, jobs file or bench spec that is wrong, a setting
// out of range, an unknown kernel or device. One line naming the file and the field
// (the JSON path); exit 2, before anything is written.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// An output that cannot be written where it was asked for (an unknown extension, a
// missing or unwritable folder, two outputs that are one file); exit 2, found
// before the render.
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The output path passed its checks but the write failed: the disk filled up (ENOSPC),
// the file grew past a limit (EFBIG), the disk failed (EIO). A failure of the machine,
// not of the input (exit 1); the message names the file and the system's reason.
struct OutputWriteError : OutputError {
  using OutputError::OutputError;
};

// The machine failed, not the input: no device, a device or driver error, memory
// that ran out after the checks (exit 1).
struct DeviceError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "a, b, c": the choices a message lists.
inline std::string listed(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace wt

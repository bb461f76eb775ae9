// The error for failures of the machine rather than of the input.
#pragma once

#include <stdexcept>

namespace wt {

// The machine failed, not the input: no device, a device or driver error, memory
// that ran out after the checks. Bad input is SceneError (scene/scene.hpp).
struct DeviceError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace wt

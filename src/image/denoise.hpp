// Denoising with Intel Open Image Denoise (OIDN), loaded at run time: a render that
// does not denoise never needs it. Its C API is declared here from OIDN's
// documentation (the library ships without headers in the wheel the set-up script
// fetches), and the library is looked for, in this order, at
//   - $WAVETRACE_OIDN: a folder holding libOpenImageDenoise.so.2, or that file (where
//     it is set, nowhere else);
//   - oidn/ beside the running executable (a bundle carried with the binaries);
//   - the project's .deps/oidn/lib, where scripts/setup.sh unpacks the `pyoidn`
//     wheel's libraries;
//   - the system's library path.
// OIDN finds its device modules (CPU, CUDA) and TBB beside itself.
#pragma once

#include <string>
#include <vector>

namespace wt {

// OIDN's "RT" filter qualities that a final render takes.
enum class DenoiseQuality { High, Balanced };

// Where OIDN runs: on the CPU, or on a CUDA device (OIDN picks the first).
enum class DenoiseDevice { Cpu, Cuda };

// The filter's inputs: linear RGB, row-major, 3 floats a pixel, width x height
// each. The colour is HDR radiance; albedo (in [0, 1]) and normal (world space,
// unit or zero) are optional, the normal only with an albedo (OIDN's rule). Guides
// are taken as noisy: each is denoised on its own first (OIDN's prefiltering).
struct DenoiseImages {
  int width = 0, height = 0;
  const float* color = nullptr;
  const float* albedo = nullptr;
  const float* normal = nullptr;
};

// Whether OIDN could be loaded (once; later calls answer the same), and if not,
// why, in one line naming every place it was looked for.
bool oidn_available(std::string& why);

// The denoised colour, width x height x 3 floats: OIDN's "RT" filter with "hdr"
// on and the quality asked for. Throws InputError where OIDN cannot be loaded and
// DeviceError where OIDN fails (its own message, and the call that failed).
std::vector<float> denoise(const DenoiseImages& images, DenoiseQuality quality, DenoiseDevice device);

}  // namespace wt

#include "image/denoise.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "errors/errors.hpp"

#ifndef WT_OIDN_PROJECT_DIR
#define WT_OIDN_PROJECT_DIR ""
#endif

namespace wt {

namespace {

// OIDN's C API (OpenImageDenoise/oidn.h, version 2), as its documentation gives it:
// opaque handles, and the enumerators this file uses with their documented values.
using OIDNDevice = struct OIDNDeviceImpl*;
using OIDNFilter = struct OIDNFilterImpl*;
using OIDNBuffer = struct OIDNBufferImpl*;
constexpr int kOidnDeviceTypeCpu = 1, kOidnDeviceTypeCuda = 3;  // OIDNDeviceType
constexpr int kOidnErrorNone = 0;                                 // OIDNError
constexpr int kOidnFormatFloat3 = 3;                              // OIDNFormat
constexpr int kOidnQualityBalanced = 5, kOidnQualityHigh = 6;     // OIDNQuality

struct Oidn {
  OIDNDevice (*new_device)(int type);
  void (*commit_device)(OIDNDevice);
  int (*get_device_error)(OIDNDevice, const char** message);
  void (*release_device)(OIDNDevice);
  OIDNBuffer (*new_buffer)(OIDNDevice, size_t bytes);
  void (*write_buffer)(OIDNBuffer, size_t offset, size_t bytes, const void* source);
  void (*read_buffer)(OIDNBuffer, size_t offset, size_t bytes, void* destination);
  void (*release_buffer)(OIDNBuffer);
  OIDNFilter (*new_filter)(OIDNDevice, const char* type);
  void (*set_filter_image)(OIDNFilter, const char* name, OIDNBuffer, int format, size_t width, size_t height,
                           size_t byte_offset, size_t pixel_stride, size_t row_stride);
  void (*set_filter_bool)(OIDNFilter, const char* name, bool value);
  void (*set_filter_int)(OIDNFilter, const char* name, int value);
  void (*commit_filter)(OIDNFilter);
  void (*execute_filter)(OIDNFilter);
  void (*release_filter)(OIDNFilter);
};

std::string executable_dir() {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : self.parent_path().string();
}

// The library's candidates, in the order of denoise.hpp.
std::vector<std::string> candidates() {
  constexpr const char* kName = "libOpenImageDenoise.so.2";
  std::vector<std::string> out;
  // Where the environment names one, that one alone: a user may pin a version (or
  // name none, to render as a machine without it would).
  if (const char* env = std::getenv("WAVETRACE_OIDN"); env != nullptr && *env != '\0') {
    std::error_code ec;
    out.push_back(std::filesystem::is_directory(env, ec) ? (std::filesystem::path(env) / kName).string()
                                                         : std::string(env));
    return out;
  }
  if (const std::string dir = executable_dir(); !dir.empty()) out.push_back(dir + "/oidn/" + kName);
  if (*WT_OIDN_PROJECT_DIR != '\0') out.push_back(std::string(WT_OIDN_PROJECT_DIR) + "/" + kName);
  out.push_back(kName);  // the system's search path
  return out;
}

struct Loaded {
  Oidn api{};
  bool ok = false;
  std::string why;
};

const Loaded& loaded() {
  static Loaded l;
  static std::once_flag once;
  std::call_once(once, [] {
    void* handle = nullptr;
    std::string tried;
    for (const std::string& c : candidates()) {
      handle = dlopen(c.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (handle) break;
      const char* e = dlerror();
      tried += (tried.empty() ? "" : "; ") + (e ? std::string(e) : c);
    }
    if (!handle) {
      l.why = "Open Image Denoise is not installed (run scripts/setup.sh, or set WAVETRACE_OIDN to the folder of "
              "libOpenImageDenoise.so.2): " + tried;
      return;
    }
    bool all = true;
    std::string missing;
    auto bind = [&](auto& fn, const char* name) {
      void* sym = dlsym(handle, name);
      if (!sym) {
        all = false;
        missing += (missing.empty() ? "" : ", ") + std::string(name);
      }
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(sym);
    };
    Oidn& a = l.api;
    bind(a.new_device, "oidnNewDevice");
    bind(a.commit_device, "oidnCommitDevice");
    bind(a.get_device_error, "oidnGetDeviceError");
    bind(a.release_device, "oidnReleaseDevice");
    bind(a.new_buffer, "oidnNewBuffer");
    bind(a.write_buffer, "oidnWriteBuffer");
    bind(a.read_buffer, "oidnReadBuffer");
    bind(a.release_buffer, "oidnReleaseBuffer");
    bind(a.new_filter, "oidnNewFilter");
    bind(a.set_filter_image, "oidnSetFilterImage");
    bind(a.set_filter_bool, "oidnSetFilterBool");
    bind(a.set_filter_int, "oidnSetFilterInt");
    bind(a.commit_filter, "oidnCommitFilter");
    bind(a.execute_filter, "oidnExecuteFilter");
    bind(a.release_filter, "oidnReleaseFilter");
    if (!all) {
      l.why = "Open Image Denoise was found but is not version 2 (it lacks " + missing + ")";
      return;
    }
    l.ok = true;
  });
  return l;
}

}  // namespace

bool oidn_available(std::string& why) {
  const Loaded& l = loaded();
  if (!l.ok) why = l.why;
  return l.ok;
}

std::vector<float> denoise(const DenoiseImages& in, DenoiseQuality quality, DenoiseDevice where) {
  const Loaded& l = loaded();
  if (!l.ok) throw InputError("--denoise: " + l.why);
  if (in.width <= 0 || in.height <= 0 || in.color == nullptr || (in.normal != nullptr && in.albedo == nullptr)) {
    throw std::invalid_argument("denoise: a colour image of positive size, and a normal only with an albedo");
  }
  const Oidn& a = l.api;
  const size_t w = static_cast<size_t>(in.width), h = static_cast<size_t>(in.height), bytes = w * h * 3 * sizeof(float);
  // Every object is released on the way out, whatever throws.
  struct Objects {
    const Oidn& a;
    OIDNDevice device = nullptr;
    std::vector<OIDNFilter> filters;
    std::vector<OIDNBuffer> buffers;
    ~Objects() {
      for (OIDNFilter f : filters) a.release_filter(f);
      for (OIDNBuffer b : buffers) a.release_buffer(b);
      if (device) a.release_device(device);
    }
  } o{a, nullptr, {}, {}};
  auto check = [&](const char* call) {
    const char* message = nullptr;
    if (o.device && a.get_device_error(o.device, &message) != kOidnErrorNone) {
      throw DeviceError(std::string("denoise: Open Image Denoise failed in ") + call + ": " +
                        (message ? message : "no message"));
    }
  };
  o.device = a.new_device(where == DenoiseDevice::Cuda ? kOidnDeviceTypeCuda : kOidnDeviceTypeCpu);
  if (!o.device) {
    throw DeviceError(std::string("denoise: Open Image Denoise has no ") + (where == DenoiseDevice::Cuda ? "CUDA" : "CPU") +
                      " device here");
  }
  a.commit_device(o.device);
  check("oidnCommitDevice");
  auto buffer = [&](const float* data) {
    OIDNBuffer b = a.new_buffer(o.device, bytes);
    check("oidnNewBuffer");
    o.buffers.push_back(b);
    if (data) {
      a.write_buffer(b, 0, bytes, data);
      check("oidnWriteBuffer");
    }
    return b;
  };
  auto filter = [&](const std::vector<std::pair<const char*, OIDNBuffer>>& images, bool hdr, bool clean_aux) {
    OIDNFilter f = a.new_filter(o.device, "RT");
    check("oidnNewFilter");
    o.filters.push_back(f);
    for (const auto& [name, b] : images) {
      a.set_filter_image(f, name, b, kOidnFormatFloat3, w, h, 0, 0, 0);
      check("oidnSetFilterImage");
    }
    if (hdr) a.set_filter_bool(f, "hdr", true);
    if (clean_aux) a.set_filter_bool(f, "cleanAux", true);
    a.set_filter_int(f, "quality", quality == DenoiseQuality::High ? kOidnQualityHigh : kOidnQualityBalanced);
    a.commit_filter(f);
    check("oidnCommitFilter");
    a.execute_filter(f);
    check("oidnExecuteFilter");
  };
  // The guides are Monte Carlo estimates too: each is denoised in place first, by
  // the RT filter given it alone, and the colour's filter then takes them as clean
  // (OIDN's documented prefiltering, for the highest quality).
  std::vector<std::pair<const char*, OIDNBuffer>> images = {{"color", buffer(in.color)}};
  if (in.albedo) {
    const OIDNBuffer albedo = buffer(in.albedo);
    filter({{"albedo", albedo}, {"output", albedo}}, false, false);
    images.push_back({"albedo", albedo});
  }
  if (in.normal) {
    const OIDNBuffer normal = buffer(in.normal);
    filter({{"normal", normal}, {"output", normal}}, false, false);
    images.push_back({"normal", normal});
  }
  const OIDNBuffer output = buffer(nullptr);
  images.push_back({"output", output});
  filter(images, true, in.albedo != nullptr);
  std::vector<float> out(w * h * 3);
  a.read_buffer(output, 0, bytes, out.data());
  check("oidnReadBuffer");
  return out;
}

}  // namespace wt

// What the whole-render tests share: every (backend, kernel) pair as a test
// parameter, the options of a small render, and image statistics.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <ostream>
#include <string>
#include <vector>

#include "render/renderer.hpp"

namespace wt::test {

struct Variant {
  Backend backend;
  Kernel kernel;
};

inline void PrintTo(const Variant& v, std::ostream* os) {
  *os << backend_name(v.backend) << "/" << kernel_name(v.kernel);
}

// "cuda_wavefront_unsorted": a test name's suffix.
inline std::string variant_name(const testing::TestParamInfo<Variant>& info) {
  std::string n = std::string(backend_name(info.param.backend)) + "_" + kernel_name(info.param.kernel);
  for (char& c : n) c = c == '-' ? '_' : c;
  return n;
}

// Every kernel on every backend that runs it (the CUDA ones skip without a device).
inline std::vector<Variant> all_variants() {
  return {{Backend::Cpu, Kernel::Megakernel},           {Backend::Cpu, Kernel::Wavefront},
          {Backend::Cpu, Kernel::WavefrontUnsorted},    {Backend::Cuda, Kernel::Megakernel},
          {Backend::Cuda, Kernel::MegakernelConstant},  {Backend::Cuda, Kernel::Wavefront},
          {Backend::Cuda, Kernel::WavefrontUnsorted}};
}

inline RenderOptions options_for(Backend b, Kernel k, int w, int h, int spp, int depth, int roulette,
                                 uint32_t seed) {
  RenderOptions o;
  o.backend = b;
  o.kernel = k;
  o.params = RenderParams{w, h, spp, depth, roulette, seed};
  o.wave_size = 4096;  // several waves even for small images: regeneration is exercised
  return o;
}

inline double mean(const std::vector<float>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / v.size(); }

inline double mean_abs_diff(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += std::fabs(static_cast<double>(a[i]) - b[i]);
  return s / a.size();
}

}  // namespace wt::test

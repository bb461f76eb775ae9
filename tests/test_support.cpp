#include "test_support.hpp"

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "cuda/device.hpp"

namespace wt::test {

std::string repo_root() {
  if (const char* env = std::getenv("WAVETRACE_ROOT")) return env;
  namespace fs = std::filesystem;
  for (fs::path p = fs::current_path(); !p.empty(); p = p.parent_path()) {
    if (fs::exists(p / "scenes" / "quick.json")) return p.string();
    if (p == p.root_path()) break;
  }
  return ".";
}

std::string repo_path(const std::string& relative) { return repo_root() + "/" + relative; }

bool cuda_available() { return wt::cuda::device_count() > 0; }

// "PF", width, height, -1.0 (little-endian), then the rows bottom first.
std::vector<float> read_pfm(const std::string& path, int width, int height) {
  std::ifstream f(path, std::ios::binary);
  std::string magic;
  int w = 0, h = 0;
  float scale = 0;
  f >> magic >> w >> h >> scale;
  f.get();
  if (!f || magic != "PF" || w != width || h != height || scale != -1.0f) {
    ADD_FAILURE() << path << ": not a " << width << "x" << height << " little-endian PFM";
    return {};
  }
  std::vector<float> rgb(static_cast<size_t>(w) * h * 3);
  for (int y = h - 1; y >= 0; --y) {
    f.read(reinterpret_cast<char*>(rgb.data() + static_cast<size_t>(y) * w * 3), sizeof(float) * w * 3);
  }
  if (!f) ADD_FAILURE() << path << ": short file";
  return rgb;
}

}  // namespace wt::test

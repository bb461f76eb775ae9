#include "test_support.hpp"

#include <cstdlib>
#include <filesystem>

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

}  // namespace wt::test

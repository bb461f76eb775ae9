#include "test_support.hpp"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "device/device.hpp"

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

std::string models_dir() {
  if (const char* env = std::getenv("WAVETRACE_MODELS")) return env;
  return (std::filesystem::path(repo_root()) / ".." / "shared" / "models").lexically_normal().string();
}

TestFolder::TestFolder() {
  const testing::TestInfo* test = testing::UnitTest::GetInstance()->current_test_info();
  std::string name = std::string("wavetrace_") + test->test_suite_name() + "_" + test->name() + "_" +
                     std::to_string(::getpid());
  for (char& c : name) c = (c == '/') ? '_' : c;
  root_ = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(root_);
  std::filesystem::create_directories(root_);
}

TestFolder::~TestFolder() {
  std::error_code ignored;
  std::filesystem::remove_all(root_, ignored);
}

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

std::string in_child_process(const std::function<std::string()>& fn) {
  int fds[2];
  if (::pipe(fds) != 0) return "child process failed: pipe";
  const pid_t pid = ::fork();
  if (pid < 0) return "child process failed: fork";
  if (pid == 0) {
    ::close(fds[0]);
    std::string text;
    try {
      text = fn();
    } catch (const std::exception& e) {
      text = std::string("child process failed: threw ") + e.what();
    }
    for (size_t done = 0; done < text.size();) {
      const ssize_t k = ::write(fds[1], text.data() + done, text.size() - done);
      if (k <= 0) ::_exit(3);
      done += static_cast<size_t>(k);
    }
    ::_exit(0);  // no atexit handlers or gtest teardown in the child
  }
  ::close(fds[1]);
  std::string text;
  char buf[4096];
  for (ssize_t k; (k = ::read(fds[0], buf, sizeof buf)) != 0;) {
    if (k > 0) text.append(buf, static_cast<size_t>(k));
    else if (errno != EINTR) break;
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    return "child process failed: status " + std::to_string(status) + " after \"" + text + "\"";
  }
  return text;
}

bool limit_file_size(unsigned long long bytes) {
  std::signal(SIGXFSZ, SIG_IGN);
  const rlimit r{static_cast<rlim_t>(bytes), static_cast<rlim_t>(bytes)};
  return ::setrlimit(RLIMIT_FSIZE, &r) == 0;
}

Watchdog::Watchdog(std::chrono::seconds limit, std::string what) {
  thread_ = std::thread([this, limit, what = std::move(what)] {
    std::unique_lock<std::mutex> lock(m_);
    if (cv_.wait_for(lock, limit, [this] { return done_; })) return;
    std::fprintf(stderr, "watchdog: %s did not finish within %lld s; the test process is ended (exit 124)\n",
                 what.c_str(), static_cast<long long>(limit.count()));
    std::fflush(stderr);
    std::_Exit(124);
  });
}

Watchdog::~Watchdog() {
  {
    std::lock_guard<std::mutex> lock(m_);
    done_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

}  // namespace wt::test

#include "app/process.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

extern char** environ;

namespace wt::app {

namespace {

volatile std::sig_atomic_t g_caught = 0;
// The children running (a batch runs several at once), each in a slot: its pid (0:
// free), and whether g_caught was passed on to it.
constexpr int kMaxChildren = 64;
volatile pid_t g_children[kMaxChildren] = {};
volatile std::sig_atomic_t g_forwarded[kMaxChildren] = {};
std::mutex g_slots;
bool g_slot_taken[kMaxChildren] = {};

void forward(int sig) {
  g_caught = sig;
  for (int i = 0; i < kMaxChildren; ++i) {
    const pid_t child = g_children[i];
    if (child > 0) {
      ::kill(child, sig);
      g_forwarded[i] = 1;
    }
  }
}

int take_slot() {
  std::lock_guard<std::mutex> lock(g_slots);
  for (int i = 0; i < kMaxChildren; ++i) {
    if (!g_slot_taken[i]) {
      g_slot_taken[i] = true;
      return i;
    }
  }
  throw std::runtime_error("more than " + std::to_string(kMaxChildren) + " jobs at once");
}

void free_slot(int slot) {
  std::lock_guard<std::mutex> lock(g_slots);
  g_slot_taken[slot] = false;
}

struct sigaction g_previous_int {}, g_previous_term {};

void catch_unless_ignored(int sig, struct sigaction& previous) {
  sigaction(sig, nullptr, &previous);
  if (previous.sa_handler == SIG_IGN) return;
  struct sigaction action {};
  action.sa_handler = forward;
  sigemptyset(&action.sa_mask);
  sigaction(sig, &action, nullptr);
}

sigset_t int_and_term() {
  sigset_t both;
  sigemptyset(&both);
  sigaddset(&both, SIGINT);
  sigaddset(&both, SIGTERM);
  return both;
}

// Sets the child of `slot` that signals go to (0: none), and passes on one caught
// before it was known. The two signals are blocked in this thread meanwhile; one
// that another thread takes meanwhile may reach the child twice, which a render
// answers as once.
void set_child(int slot, pid_t pid) {
  const sigset_t both = int_and_term();
  sigset_t previous;
  pthread_sigmask(SIG_BLOCK, &both, &previous);
  if (pid == 0) g_forwarded[slot] = 0;
  g_children[slot] = pid;
  if (pid > 0 && g_caught != 0 && !g_forwarded[slot]) {
    ::kill(pid, g_caught);
    g_forwarded[slot] = 1;
  }
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
}

void write_all(int fd, const char* data, size_t n) {
  while (n > 0) {
    const ssize_t k = ::write(fd, data, n);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return;  // our stderr is gone: nothing to forward to
    data += k;
    n -= static_cast<size_t>(k);
  }
}

// Forwards a child's stderr line by line, holding back the latest "wavetrace: " line
// until another line follows it.
class StderrFilter {
 public:
  void feed(const char* data, size_t n) {
    for (size_t i = 0; i < n; ++i) {
      line_ += data[i];
      if (data[i] == '\n') end_line();
    }
  }
  // At the end of the stream: the held-back line's text.
  std::string finish() {
    if (!line_.empty()) end_line();  // a last line without its newline
    return held_.empty() ? "" : held_.substr(kPrefix.size(), held_.size() - kPrefix.size() - 1);
  }

 private:
  void end_line() {
    // A progress line redraws itself after '\r': the line is what follows the last one.
    const size_t cr = line_.find_last_of('\r', line_.size() - 1);
    const std::string shown = cr == std::string::npos ? line_ : line_.substr(cr + 1);
    if (!held_.empty()) write_all(2, held_.data(), held_.size());
    held_.clear();
    if (shown.compare(0, kPrefix.size(), kPrefix) == 0) {
      write_all(2, line_.data(), cr == std::string::npos ? 0 : cr + 1);
      held_ = shown.back() == '\n' ? shown : shown + "\n";
    } else {
      write_all(2, line_.data(), line_.size());
    }
    line_.clear();
  }

  static inline const std::string kPrefix = "wavetrace: ";
  std::string line_, held_;
};

}  // namespace

SignalForwarder::SignalForwarder() {
  g_caught = 0;
  for (int i = 0; i < kMaxChildren; ++i) {
    g_forwarded[i] = 0;
    g_children[i] = 0;
  }
  catch_unless_ignored(SIGINT, g_previous_int);
  catch_unless_ignored(SIGTERM, g_previous_term);
}

SignalForwarder::~SignalForwarder() {
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
}

int SignalForwarder::caught() const { return g_caught; }

ChildEnd run_child(const std::string& executable, const std::vector<std::string>& args) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("cannot make a pipe: ") + std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDERR_FILENO);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);

  std::vector<std::string> argv_text = {"wavetrace"};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);

  pid_t pid = 0;
  const int err = ::posix_spawn(&pid, executable.c_str(), &actions, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  ::close(fds[1]);
  if (err != 0) {
    ::close(fds[0]);
    throw std::runtime_error("cannot start " + executable + ": " + std::strerror(err));
  }
  const int slot = take_slot();
  set_child(slot, pid);

  StderrFilter filter;
  char buf[4096];
  for (ssize_t k; (k = ::read(fds[0], buf, sizeof buf)) != 0;) {
    if (k > 0) filter.feed(buf, static_cast<size_t>(k));
    else if (errno != EINTR) break;
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  set_child(slot, 0);
  free_slot(slot);

  ChildEnd end;
  end.last_line = filter.finish();
  end.exited = WIFEXITED(status);
  end.exit_code = end.exited ? WEXITSTATUS(status) : 0;
  end.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  return end;
}

}  // namespace wt::app

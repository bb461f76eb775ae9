#include "app/process.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

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

namespace {

// A pipe whose ends are at descriptors 10 and up, close-on-exec: a child gets an end
// only where it is dup2'ed into place (which clears close-on-exec there; an end that
// already sat at the target descriptor would keep it).
std::array<int, 2> high_pipe() {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("cannot make a pipe: ") + std::strerror(errno));
  std::array<int, 2> out{};
  for (int i = 0; i < 2; ++i) {
    out[i] = ::fcntl(fds[i], F_DUPFD_CLOEXEC, 10);
    const int err = errno;
    ::close(fds[i]);
    if (out[i] < 0) {
      if (i == 1) ::close(out[0]);
      throw std::runtime_error(std::string("cannot make a pipe: ") + std::strerror(err));
    }
  }
  return out;
}

// Starts `executable` with `args` (argv[0] "wavetrace") in a process group of its own,
// with `moves` (from, to) dup2'ed into place and SIGPIPE at its default; its pid.
pid_t spawn(const std::string& executable, const std::vector<std::string>& args,
            const std::vector<std::pair<int, int>>& moves) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  for (const auto& [from, to] : moves) posix_spawn_file_actions_adddup2(&actions, from, to);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF);
  posix_spawnattr_setpgroup(&attr, 0);
  sigset_t defaults;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGPIPE);
  posix_spawnattr_setsigdefault(&attr, &defaults);

  std::vector<std::string> argv_text = {"wavetrace"};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);

  pid_t pid = 0;
  const int err = ::posix_spawn(&pid, executable.c_str(), &actions, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (err != 0) throw std::runtime_error("cannot start " + executable + ": " + std::strerror(err));
  return pid;
}

// Waits for `pid`; how it ended.
ChildEnd wait_for(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  ChildEnd end;
  end.exited = WIFEXITED(status);
  end.exit_code = end.exited ? WEXITSTATUS(status) : 0;
  end.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  return end;
}

// Writes all of `text` to `fd`; false if the reader is gone (EPIPE, whose SIGPIPE is
// held back from this thread and taken here, so that it ends nothing).
bool write_or_gone(int fd, const std::string& text) {
  sigset_t pipe_signal, previous;
  sigemptyset(&pipe_signal);
  sigaddset(&pipe_signal, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_signal, &previous);
  bool gone = false;
  for (size_t at = 0; at < text.size();) {
    const ssize_t k = ::write(fd, text.data() + at, text.size() - at);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) {
      gone = true;
      break;
    }
    at += static_cast<size_t>(k);
  }
  if (gone && !sigismember(&previous, SIGPIPE)) {
    const timespec now{0, 0};
    while (sigtimedwait(&pipe_signal, nullptr, &now) == SIGPIPE) {
    }
  }
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  return !gone;
}

}  // namespace

ChildEnd run_child(const std::string& executable, const std::vector<std::string>& args) {
  const std::array<int, 2> fds = high_pipe();
  pid_t pid = 0;
  try {
    pid = spawn(executable, args, {{fds[1], STDERR_FILENO}});
  } catch (...) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw;
  }
  ::close(fds[1]);
  const int slot = take_slot();
  set_child(slot, pid);

  StderrFilter filter;
  char buf[4096];
  for (ssize_t k; (k = ::read(fds[0], buf, sizeof buf)) != 0;) {
    if (k > 0) filter.feed(buf, static_cast<size_t>(k));
    else if (errno != EINTR) break;
  }
  ::close(fds[0]);
  ChildEnd end = wait_for(pid);
  set_child(slot, 0);
  free_slot(slot);
  end.last_line = filter.finish();
  return end;
}

WorkerProcess::WorkerProcess(std::string executable) : executable_(std::move(executable)) {}

WorkerProcess::~WorkerProcess() { stop(); }

void WorkerProcess::start() {
  const int slot = take_slot();
  std::array<int, 2> to{-1, -1}, from{-1, -1};
  try {
    to = high_pipe();
    from = high_pipe();
    pid_ = spawn(executable_, {"worker"}, {{to[0], STDIN_FILENO}, {from[1], 3}});
  } catch (...) {
    for (int fd : {to[0], to[1], from[0], from[1]}) {
      if (fd >= 0) ::close(fd);
    }
    free_slot(slot);
    throw;
  }
  ::close(to[0]);
  ::close(from[1]);
  to_ = to[1];
  from_ = from[0];
  pending_.clear();
  slot_ = slot;
  set_child(slot_, pid_);
}

std::optional<std::string> WorkerProcess::ask(const std::string& question, ChildEnd& end) {
  // A worker that died while it waited (killed from outside) is replaced: the
  // question has not reached it. So is one gone before it read the question.
  int status = 0;
  if (pid_ != 0 && ::waitpid(pid_, &status, WNOHANG) == pid_) release();
  if (pid_ != 0 && to_ < 0) stop();  // finished: it is ending
  if (pid_ == 0) start();
  bool sent = write_or_gone(to_, question + "\n");
  if (!sent) {
    stop();
    start();
    sent = write_or_gone(to_, question + "\n");
  }
  if (sent) {
    char buf[4096];
    for (;;) {
      const size_t newline = pending_.find('\n');
      if (newline != std::string::npos) {
        std::string answer = pending_.substr(0, newline);
        pending_.erase(0, newline + 1);
        return answer;
      }
      const ssize_t k = ::read(from_, buf, sizeof buf);
      if (k > 0) {
        pending_.append(buf, static_cast<size_t>(k));
      } else if (k == 0 || errno != EINTR) {
        break;
      }
    }
  }
  end = stop();
  return std::nullopt;
}

void WorkerProcess::finish() {
  if (to_ >= 0) ::close(to_);
  to_ = -1;
}

ChildEnd WorkerProcess::stop() {
  if (pid_ == 0) return {};
  // Its input closed, it exits; its answers, closed, cannot hold it up.
  finish();
  ::close(from_);
  from_ = -1;
  const ChildEnd end = wait_for(pid_);
  release();
  return end;
}

void WorkerProcess::release() {
  for (int fd : {to_, from_}) {
    if (fd >= 0) ::close(fd);
  }
  set_child(slot_, 0);
  free_slot(slot_);
  pid_ = 0;
  slot_ = to_ = from_ = -1;
}

}  // namespace wt::app

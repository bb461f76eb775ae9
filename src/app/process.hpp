// Jobs in processes of their own: `wavetrace batch` runs its jobs in child processes,
// a worker per lane that renders job after job (its CUDA context set up once), or a
// `render` process for each job; a job that loses the worker's CUDA context (a
// sticky CUDA error poisons the context of the process it happens in, for good) or
// kills it ends that worker, and the next job starts a new one.
#pragma once

#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

namespace wt::app {

// While one lives, SIGINT and SIGTERM sent to this process are caught and passed on to
// the child that run_child is running, if any. Signals this process ignored when it
// was constructed stay ignored. One at a time.
class SignalForwarder {
 public:
  SignalForwarder();
  ~SignalForwarder();
  SignalForwarder(const SignalForwarder&) = delete;
  SignalForwarder& operator=(const SignalForwarder&) = delete;

  // The last signal caught since construction, or 0.
  int caught() const;
};

struct ChildEnd {
  bool exited = false;    // it exited, with exit_code; otherwise a signal killed it
  int exit_code = 0;
  int signal = 0;         // the signal that killed it
  // The last line it wrote to stderr that starts with "wavetrace: ", without that
  // prefix; empty if none. That line is not forwarded (the caller reports it).
  std::string last_line;
};

// Runs `executable` with `args` (argv[0] is "wavetrace") in a process group of its own,
// so that a terminal's Ctrl-C reaches it once, through the SignalForwarder. Its stdout
// is ours; its stderr is forwarded to ours as it comes, but for the last line that
// starts with "wavetrace: ", returned. Waits for it. Throws std::runtime_error if it
// cannot be started.
ChildEnd run_child(const std::string& executable, const std::vector<std::string>& args);

// `executable worker` in a process group of its own, started at the first question:
// it answers questions one at a time, each a line to its stdin answered by a line on
// its descriptor 3; its stdout and stderr are ours. While it lives, the
// SignalForwarder passes SIGINT and SIGTERM on to it. One thread at a time asks it.
class WorkerProcess {
 public:
  explicit WorkerProcess(std::string executable);
  ~WorkerProcess();  // stop()
  WorkerProcess(const WorkerProcess&) = delete;
  WorkerProcess& operator=(const WorkerProcess&) = delete;

  // Sends `question` (one line, without its newline) and waits for the answer. No
  // answer: the process ended first (how: in `end`), and the next question starts a
  // new one. A process found ended before it got the question is replaced at once.
  // Throws std::runtime_error if it cannot be started.
  std::optional<std::string> ask(const std::string& question, ChildEnd& end);
  // Closes its input, which ends it, and waits for it to exit; its end.
  ChildEnd stop();
  // Closes its input, which ends it, without waiting (stop() waits): a lane done with
  // its worker lets it end while the other lanes work.
  void finish();
  // Its process id while it runs, else 0.
  pid_t pid() const { return pid_; }

 private:
  void start();
  // Forgets the process (its exit already waited for): its pipes and signal slot.
  void release();
  std::string executable_;
  pid_t pid_ = 0;
  int slot_ = -1;
  int to_ = -1, from_ = -1;  // its stdin, its answers
  std::string pending_;      // read past the last answer
};

}  // namespace wt::app

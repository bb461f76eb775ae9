// Jobs in processes of their own: `wavetrace batch` runs each job as a `render` of a
// child process, so that every job starts on a clean CUDA context (a sticky CUDA
// error poisons the context of the process it happens in, for good) and no job's
// memory or descriptors can outlive it.
#pragma once

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

}  // namespace wt::app

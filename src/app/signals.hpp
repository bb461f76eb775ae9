// Catches SIGINT and SIGTERM while a checkpointed render runs, so that it can write
// a last checkpoint and stop at the end of its pass. A second signal is not caught:
// it ends the process at once, as it would without a checkpoint. The calling
// thread (and the threads it starts) receive the two signals while a catcher lives,
// even if they were blocked, so one that was pending is caught at once.
#pragma once

#include <csignal>
#include <string>

namespace wt::app {

// "SIGINT", "SIGTERM", or "signal N (its description)".
std::string signal_name(int sig);

class SignalCatcher {
 public:
  SignalCatcher();
  ~SignalCatcher();
  SignalCatcher(const SignalCatcher&) = delete;
  SignalCatcher& operator=(const SignalCatcher&) = delete;

  // The signal caught since construction, or 0.
  int caught() const;

 private:
  struct sigaction previous_int_ {}, previous_term_ {};
  sigset_t previous_mask_{};
};

}  // namespace wt::app

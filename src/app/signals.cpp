#include "app/signals.hpp"

#include <pthread.h>

#include <cstring>

namespace wt::app {

namespace {

volatile std::sig_atomic_t g_caught = 0;

void on_signal(int sig) {
  g_caught = sig;
  std::signal(sig, SIG_DFL);  // a second one ends the process
}

}  // namespace

SignalCatcher::SignalCatcher() {
  g_caught = 0;
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &previous_int_);
  sigaction(SIGTERM, &action, &previous_term_);
  sigset_t both;
  sigemptyset(&both);
  sigaddset(&both, SIGINT);
  sigaddset(&both, SIGTERM);
  pthread_sigmask(SIG_UNBLOCK, &both, &previous_mask_);
}

SignalCatcher::~SignalCatcher() {
  pthread_sigmask(SIG_SETMASK, &previous_mask_, nullptr);
  sigaction(SIGINT, &previous_int_, nullptr);
  sigaction(SIGTERM, &previous_term_, nullptr);
}

int SignalCatcher::caught() const { return g_caught; }

std::string signal_name(int sig) {
  if (sig == SIGINT) return "SIGINT";
  if (sig == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(sig) + " (" + strsignal(sig) + ")";
}

}  // namespace wt::app

// SPDX-License-Identifier: MIT
#pragma once

// Ctrl-C / SIGTERM for the rig commands (`record`, `live`): the first signal
// asks the loop to stop (so the sensor's stream is stopped and what was
// recorded is reported), a second one kills as usual.

#include <signal.h>

namespace iclap::cli {

inline volatile sig_atomic_t g_stop_signal = 0;
extern "C" inline void iclap_cli_on_stop_signal(int sig) { g_stop_signal = sig; }

class StopSignals {
 public:
  StopSignals() {
    struct sigaction sa {};
    sa.sa_handler = iclap_cli_on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = static_cast<int>(SA_RESETHAND);  // no SA_RESTART: a blocking poll returns EINTR
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~StopSignals() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;
  static bool requested() { return g_stop_signal != 0; }
  /// The exit status of a run ended by the signal: 128 + its number.
  static int exit_status() { return 128 + static_cast<int>(g_stop_signal); }

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

}  // namespace iclap::cli

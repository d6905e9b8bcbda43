// SPDX-License-Identifier: MIT
// CPU time for the benchmark programs (POSIX).
#pragma once

#include <ctime>

namespace iclap::bench {

/// CPU time of the calling thread in seconds: unlike wall time it does not
/// count the time the thread waits for a core on a loaded machine.
inline double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace iclap::bench

// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <functional>
#include <mutex>
#include <utility>

namespace iclap {

/// Progress of a long computation: called with (done, total) units of work,
/// `done` non-decreasing, from the calling thread or, for parallel work, from
/// any worker thread (so implementations must be thread-safe). The library
/// never prints; tools pass a callback that does. An empty function is a
/// valid "no progress wanted".
using ProgressCallback = std::function<void(std::size_t done, std::size_t total)>;

/// Counts finished units of work from any number of threads and reports
/// each to a ProgressCallback as (units done, `total`), one call at a time,
/// so that `done` never decreases. With an empty callback it does nothing.
class ProgressCounter {
 public:
  ProgressCounter(ProgressCallback progress, std::size_t total) : progress_(std::move(progress)), total_(total) {}

  /// One more unit done.
  void tick() {
    if (!progress_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    progress_(++done_, total_);
  }

 private:
  ProgressCallback progress_;
  std::size_t total_;
  std::size_t done_ = 0;
  std::mutex mutex_;
};

}  // namespace iclap

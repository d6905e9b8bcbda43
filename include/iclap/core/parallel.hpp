// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace iclap::detail {

/// Threads used for `count` items: `threads` (0: all cores), at most one per
/// item, at least one.
inline unsigned worker_count(unsigned threads, std::size_t count) {
  const unsigned n = threads > 0 ? threads : std::thread::hardware_concurrency();
  return std::max(1u, static_cast<unsigned>(std::min<std::size_t>(n, std::max<std::size_t>(1, count))));
}

/// Calls body(i, worker) for every i in [0, count), handed out one at a time
/// to worker_count(threads, count) threads, the calling one included
/// (worker < worker_count). After the first exception no new item starts;
/// once every thread has stopped, the exception of the smallest item index
/// that threw is rethrown. Items are handed out in index order, so every
/// item before the first one to fail (in index order) has run: for items
/// that fail depending only on i, that is the exception a single thread
/// would throw, whatever the thread count and timing. Items must write
/// only their own state (or synchronise); results that depend only on i
/// are then identical for any thread count. When the system refuses to
/// start a thread, the items run on the threads already started (at least
/// the calling one).
template <typename Body>
void parallel_for(std::size_t count, unsigned threads, Body&& body) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::size_t error_item = 0;
  std::mutex error_mutex;
  auto worker = [&](unsigned id) {
    for (;;) {
      // Claimed only below count: an unconditional next++ went on past
      // count (set to it after a failure) and wrapped to item 0 again for a
      // count near SIZE_MAX.
      std::size_t i = next.load();
      do {
        if (i >= count) return;
      } while (!next.compare_exchange_weak(i, i + 1));
      try {
        body(i, id);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error || i < error_item) {
          error = std::current_exception();
          error_item = i;
        }
        next = count;
        return;
      }
    }
  };
  const unsigned n = worker_count(threads, count);
  std::vector<std::thread> pool;
  pool.reserve(n - 1);
  try {
    for (unsigned id = 1; id < n; ++id) pool.emplace_back(worker, id);
  } catch (...) {
    // The system refused a thread (no memory for its stack or its state,
    // std::bad_alloc; a process limit, std::system_error): the items run on
    // the threads already started. Letting the exception leave would destroy
    // joinable threads (std::terminate).
  }
  worker(0);
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace iclap::detail

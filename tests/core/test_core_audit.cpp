// SPDX-License-Identifier: MIT
// Contract audit of include/iclap/core (session 56): parallel_for's
// defects, one case each; both failed before their fix. Its own executable:
// it replaces the global operator new (plain malloc/free unless a test arms
// the countdown), which the other core tests should not run under.

#include <doctest/doctest.h>

#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <limits>
#include <new>
#include <stdexcept>
#include <thread>

#include "iclap/core/parallel.hpp"

// ---------------------------------------------------------------------------
// A replaceable global allocator that can be told to fail, on the calling
// thread only, after a given number of further allocations. With the
// countdown at -1 (the default, and on every thread but the one that sets
// it) it is plain malloc / free, so it changes nothing for the other tests
// of the executable. Every non-aligned form is replaced, so that new and
// delete always pair up (no ASan alloc-dealloc-mismatch).
namespace {
thread_local long audit_new_countdown = -1;

void* audit_allocate(std::size_t size) {
  if (audit_new_countdown == 0) {
    audit_new_countdown = -1;
    throw std::bad_alloc();
  }
  if (audit_new_countdown > 0) --audit_new_countdown;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t size) { return audit_allocate(size); }
void* operator new[](std::size_t size) { return audit_allocate(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return audit_allocate(size);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return audit_allocate(size);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

using namespace iclap;

// Input: parallel_for(3, 3, body) while the allocation of the second
// std::thread's state fails with std::bad_alloc (memory exhausted: the
// system refusing a thread just as surely as EAGAIN does).
// Before: the process died in std::terminate (libstdc++ prints "terminate
// called without an active exception", then SIGABRT): only
// std::system_error is caught around the thread starts, so the bad_alloc
// leaves parallel_for while the first worker thread is still joinable, and
// ~vector<std::thread> (~thread of a joinable thread) calls std::terminate.
// The test runs the call in a forked child, which died of signal 6.
// Should: as the doc comment says for a refused thread, run the items on the
// threads already started (or at worst let the bad_alloc propagate after
// joining them), never terminate the process.
// Cause (fixed): parallel.hpp caught only std::system_error around the
// thread starts.
TEST_CASE("parallel_for: a thread start failing with bad_alloc does not terminate the process") {
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    std::signal(SIGABRT, SIG_DFL);  // die of the signal, not doctest's report
    int code = 0;
    try {
      std::atomic<int> ran{0};
      // Allocations on the calling thread: pool.reserve (1), the first
      // thread's state (2), the second thread's state (3: fails).
      audit_new_countdown = 2;
      detail::parallel_for(3, 3, [&](std::size_t, unsigned) { ++ran; });
      audit_new_countdown = -1;
      code = ran.load() == 3 ? 0 : 1;
    } catch (const std::bad_alloc&) {
      code = 0;  // acceptable too: reported, not a crash
    } catch (...) {
      code = 2;
    }
    _exit(code);
  }
  int status = 0;
  REQUIRE(waitpid(pid, &status, 0) == pid);
  INFO("child signalled: " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0));
  CHECK(WIFEXITED(status));
  CHECK((WIFEXITED(status) && WEXITSTATUS(status) == 0));
}

// Input: parallel_for(count = SIZE_MAX, 3 threads, body) where item 0
// throws at once and items 1 and 2 take 100 ms (a "run until an item fails"
// loop over an unbounded index).
// Before: item 0 ran twice (CHECK( 2 == 1 )): after the failure the counter
// is set to count, the two other threads each do one more next++ before
// they stop, the first gets SIZE_MAX (stop), and the second wraps the
// counter to 0 and starts item 0 again, against "after the first exception
// no new item starts". For count > SIZE_MAX - threads the same wrap re-runs items
// from 0 even without an exception.
// Should: every item starts at most once; after the failure no item starts.
// Cause (fixed): parallel.hpp's worker took `next++` unconditionally and a
// failure set next = count, so the counter went past count without bound.
TEST_CASE("parallel_for: the item counter does not wrap around for a count near SIZE_MAX") {
  std::atomic<int> calls{0}, item0_calls{0};
  CHECK_THROWS_WITH_AS(detail::parallel_for(std::numeric_limits<std::size_t>::max(), 3,
                                            [&](std::size_t i, unsigned) {
                                              ++calls;
                                              if (i == 0) {
                                                ++item0_calls;
                                                throw std::runtime_error("item 0");
                                              }
                                              std::this_thread::sleep_for(std::chrono::milliseconds(100));
                                            }),
                       "item 0", std::runtime_error);
  CHECK(item0_calls.load() == 1);
  CHECK(calls.load() <= 3);
}

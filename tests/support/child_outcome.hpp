// SPDX-License-Identifier: MIT
#pragma once

// Running a call that may crash (an Eigen assertion, a bad read) in a child
// process, so that a regression fails a check instead of the whole test
// binary.

#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <string>
#include <type_traits>

#include <doctest/doctest.h>

#include "iclap/core/error.hpp"

namespace iclap::test {

/// Runs `f` in a child process and returns what happened there: what `f`
/// returns (a short description), or "(no error)" for an `f` returning
/// void; "DimensionMismatch NAME" / "InvalidArgument NAME" for an iclap
/// error naming NAME; "other exception"; or "signal N" when the child died.
template <typename F>
std::string outcome_in_child(F&& f) {
  std::fflush(nullptr);  // nothing buffered is written twice
  int fds[2];
  REQUIRE(::pipe(fds) == 0);
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    std::signal(SIGABRT, SIG_DFL);  // doctest's handlers would report the child's crash as well
    std::signal(SIGSEGV, SIG_DFL);
    ::close(fds[0]);
    std::string outcome;
    try {
      if constexpr (std::is_void_v<decltype(f())>) {
        f();
        outcome = "(no error)";
      } else {
        outcome = f();
      }
    } catch (const DimensionMismatch& e) {
      outcome = "DimensionMismatch " + e.argument();
    } catch (const InvalidArgument& e) {
      outcome = "InvalidArgument " + e.argument();
    } catch (...) {
      outcome = "other exception";
    }
    const ssize_t written = ::write(fds[1], outcome.data(), outcome.size());
    ::_exit(written == static_cast<ssize_t>(outcome.size()) ? 0 : 1);
  }
  ::close(fds[1]);
  std::string outcome;
  char buf[256];
  for (ssize_t got; (got = ::read(fds[0], buf, sizeof buf)) > 0;) outcome.append(buf, static_cast<std::size_t>(got));
  ::close(fds[0]);
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  if (WIFSIGNALED(status)) return "signal " + std::to_string(WTERMSIG(status));
  return outcome;
}

}  // namespace iclap::test

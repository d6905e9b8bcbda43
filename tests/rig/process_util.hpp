// SPDX-License-Identifier: MIT
#pragma once
// Runs the real `iclap` binary from tests: spawn with stdout/stderr in
// files, wait with a deadline, read files back; doctest checks of usage errors.

#include <signal.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <doctest/doctest.h>

#include "../support/temporaries.hpp"

extern char** environ;

namespace iclap::rig::test {

/// Starts `argv` with stdout and stderr redirected to files; returns the pid.
inline pid_t spawn_process(const std::vector<std::string>& argv, const std::string& out_path,
                           const std::string& err_path) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error("cannot start " + argv[0]);
  return pid;
}

/// Waits for `pid`; returns its exit status, 128 + signal if killed, or -1
/// after killing it when `timeout` passes.
inline int wait_process(pid_t pid, std::chrono::milliseconds timeout = std::chrono::milliseconds(30000)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int status = 0;
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) {
      if (WIFEXITED(status)) return WEXITSTATUS(status);
      if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
    }
    if (r < 0) return -1;
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Result of running a command to completion.
struct ProcessResult {
  int status = -1;
  std::string out;
  std::string err;
};

inline ProcessResult run_process(const std::vector<std::string>& argv, const std::string& scratch_prefix,
                                 std::chrono::milliseconds timeout = std::chrono::milliseconds(30000)) {
  const std::string out = scratch_prefix + ".stdout", err = scratch_prefix + ".stderr";
  const pid_t pid = spawn_process(argv, out, err);
  ProcessResult r;
  r.status = wait_process(pid, timeout);
  r.out = read_text(out);
  r.err = read_text(err);
  return r;
}

/// A scratch directory (::iclap::test::TempDir) whose `scratch("name")` is
/// the path of a file in it.
struct ScratchDir : ::iclap::test::TempDir {
  using TempDir::TempDir;
  std::string operator()(const std::string& name) const { return file(name); }
};

#ifdef ICLAP_CLI_PATH
/// Runs the iclap binary under test with `args`; its output goes to files in
/// `scratch`, and it is killed after `timeout`.
inline ProcessResult run_iclap(const std::vector<std::string>& args, const ScratchDir& scratch,
                               std::chrono::milliseconds timeout = std::chrono::milliseconds(60000)) {
  std::vector<std::string> argv{ICLAP_CLI_PATH};
  argv.insert(argv.end(), args.begin(), args.end());
  return run_process(argv, scratch("run"), timeout);
}

/// Command lines (arguments after `iclap`) and what stderr must name.
using UsageCases = std::vector<std::pair<std::vector<std::string>, std::string>>;

/// Each case must fail as a usage error: exit status 2, the needle on stderr.
inline void check_usage_errors(const UsageCases& cases, const ScratchDir& scratch) {
  for (const auto& usage_case : cases) {
    // Not a structured binding: CAPTURE's lambda may not capture one in C++17.
    const std::vector<std::string>& args = usage_case.first;
    const std::string& needle = usage_case.second;
    CAPTURE(needle);
    const auto r = run_iclap(args, scratch);
    INFO(r.err);
    CHECK(r.status == 2);
    CHECK(r.err.find(needle) != std::string::npos);
  }
}
#endif

}  // namespace iclap::rig::test

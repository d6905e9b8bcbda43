// SPDX-License-Identifier: MIT
//
// `iclap`: the example command-line program. Each subcommand is registered
// from its own cmd_<name>.cpp file; this file only dispatches and turns
// exceptions into messages and exit statuses.

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "cli.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/version.hpp"

namespace {

void print_help(std::FILE* out) {
  auto commands = iclap::cli::registry();
  std::sort(commands.begin(), commands.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  std::fprintf(out,
               "iclap %s: haptic object recognition (Iterative Closest Labeled Point)\n\n"
               "usage: iclap COMMAND [ARGS...]\n       iclap COMMAND --help\n\ncommands:\n",
               ICLAP_VERSION_STRING);
  for (const auto& c : commands) std::fprintf(out, "  %-10s %s\n", c.name.c_str(), c.summary.c_str());
}

/// `status`, or kExitFailure with a message when what was printed to stdout
/// did not reach its destination (a full disk behind `> out.json` is a
/// failed run, not a silent success; `iclap --help > /dev/full` too).
int flushed(const std::string& who, int status) {
  if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return status;
  const int err = errno;
  std::fprintf(stderr, "%s: <stdout>: write failed: %s\n", who.c_str(), std::strerror(err));
  return iclap::cli::kExitFailure;
}

/// The synopsis of a command's usage text: its lines up to the first blank
/// one (the "usage: iclap NAME ..." lines).
std::string synopsis(const std::string& usage) {
  const auto blank = usage.find("\n\n");
  return blank == std::string::npos ? usage : usage.substr(0, blank);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace iclap::cli;
#ifdef SIGXFSZ
  // A file size limit (ulimit -f) makes a write fail with EFBIG, a
  // WriteError whose handling removes what was half written (temporary
  // files, the staging directory, a recording's header-only file), instead
  // of killing the process with SIGXFSZ and leaving them behind. For the
  // whole process: the error message itself may go to a file under the
  // same limit.
  std::signal(SIGXFSZ, SIG_IGN);
#endif
  if (argc < 2) {
    print_help(stderr);
    return kExitBadInput;
  }
  const std::string name = argv[1];
  if (name == "help" || name == "--help" || name == "-h") {
    print_help(stdout);
    return flushed("iclap", kExitOk);
  }
  if (name == "--version") {
    std::printf("iclap %s\n", ICLAP_VERSION_STRING);
    return flushed("iclap", kExitOk);
  }
  const auto& commands = registry();
  const auto it = std::find_if(commands.begin(), commands.end(),
                               [&](const Command& c) { return c.name == name; });
  if (it == commands.end()) {
    std::fprintf(stderr, "iclap: unknown command '%s' (see 'iclap help')\n", name.c_str());
    return kExitBadInput;
  }
  const Args args(argv + 2, argv + argc);
  try {
    return flushed("iclap " + name, it->run(args));
  } catch (const HelpRequested&) {
    // --help or -h (as after the program's name) among the options, found by
    // the command's Options: not the value of an option (`--out -h`), nor
    // an operand after "--".
    std::printf("%s\n", it->usage.c_str());
    return flushed("iclap " + name, kExitOk);
  } catch (const UsageError& e) {
    // The message, then only the synopsis: the whole option list would
    // scroll the message off the terminal.
    std::fprintf(stderr, "iclap %s: %s\n%s\n(every option: iclap %s --help)\n", name.c_str(), e.what(),
                 synopsis(it->usage).c_str(), name.c_str());
    return kExitBadInput;
  } catch (const iclap::ParseError& e) {
    std::fprintf(stderr, "%s\n", e.what());  // FILE:LINE: reason
    return kExitBadInput;
  } catch (const iclap::InvalidArgument& e) {
    std::fprintf(stderr, "iclap %s: %s\n", name.c_str(), e.what());
    return kExitBadInput;
  } catch (const iclap::WriteError& e) {  // the input was fine; writing the output failed
    std::fprintf(stderr, "iclap %s: %s\n", name.c_str(), e.what());
    return kExitFailure;
  } catch (const iclap::IoError& e) {
    std::fprintf(stderr, "iclap %s: %s\n", name.c_str(), e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "iclap %s: error: %s\n", name.c_str(), e.what());
    return kExitFailure;
  }
}

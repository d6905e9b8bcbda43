// SPDX-License-Identifier: MIT
#pragma once

// Shared plumbing of the `iclap` example program: the subcommand registry,
// option parsing with errors that name the option and value, exit codes and
// terminal progress. Each subcommand lives in its own cmd_<name>.cpp and
// registers itself with ICLAP_COMMAND.

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "iclap/core/error.hpp"

namespace iclap::cli {

/// Exit statuses of the `iclap` program.
enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,     ///< a run that could not complete (e.g. a write failed)
  kExitBadInput = 2,    ///< bad usage, unreadable or malformed input
  kExitDeviceLost = 3,  ///< the device went away mid-run (rig commands)
};

/// A usage error: unknown option, missing or malformed value. Exit status 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// `--help` or `-h` among a command's options: thrown by Options, before
/// any other check of the line; the program prints the command's usage and
/// exits with status 0.
class HelpRequested : public std::exception {
 public:
  const char* what() const noexcept override { return "help requested"; }
};

using Args = std::vector<std::string>;

/// A subcommand: `iclap NAME ARGS...`.
struct Command {
  std::string name;
  std::string summary;  ///< one line for `iclap help`
  std::string usage;    ///< full usage text for `iclap NAME --help`
  int (*run)(const Args& args);
};

/// All registered commands (function-local static: no init-order issues).
inline std::vector<Command>& registry() {
  static std::vector<Command> commands;
  return commands;
}

struct Registrar {
  explicit Registrar(Command c) { registry().push_back(std::move(c)); }
};

#define ICLAP_CLI_CONCAT_(a, b) a##b
#define ICLAP_CLI_CONCAT(a, b) ICLAP_CLI_CONCAT_(a, b)
/// Registers a subcommand from its cmd_<name>.cpp file.
#define ICLAP_COMMAND(name, summary, usage, fn) \
  static const ::iclap::cli::Registrar ICLAP_CLI_CONCAT(iclap_command_, __LINE__)({name, summary, usage, fn})

/// Parsed options of one subcommand. Options are `--name VALUE`,
/// `--name=VALUE` or, for flags, `--name`; everything else is positional
/// (`--` ends the options). Unknown options, and a value option given twice,
/// are a UsageError that names them (a flag may be repeated). `--help` or
/// `-h` where an option may stand throws HelpRequested, whatever else the
/// line holds; as the value of an option (`--out -h`) or after `--` it is
/// no request for help.
class Options {
 public:
  Options(const Args& args, const std::set<std::string>& value_options,
          const std::set<std::string>& flags = {}) {
    if (asks_for_help(args, value_options)) throw HelpRequested();
    bool options_done = false;
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      if (options_done || a.size() < 3 || a.compare(0, 2, "--") != 0) {
        if (a == "--") {
          options_done = true;
          continue;
        }
        positional_.push_back(a);
        continue;
      }
      std::string name = a.substr(2);
      std::string value;
      bool has_value = false;
      const auto eq = name.find('=');
      if (eq != std::string::npos) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
        has_value = true;
      }
      if (flags.count(name)) {
        if (has_value) throw UsageError("option --" + name + " takes no value (got " + quote_text(value, 60) + ")");
        flags_.insert(name);
      } else if (value_options.count(name)) {
        if (!has_value) {
          if (i + 1 >= args.size()) throw UsageError("option --" + name + " needs a value");
          value = args[++i];
          // No value starts with "--": `--k --out DIR` forgot the value of --k.
          if (value.size() > 2 && value.compare(0, 2, "--") == 0)
            throw UsageError("option --" + name + " needs a value (got the option " + quote_text(value, 60) + ")");
        }
        if (value.empty()) throw UsageError("option --" + name + ": empty value");
        // Given twice, one of the values would be lost without a word.
        const auto [it, added] = values_.emplace(name, value);
        if (!added)
          throw UsageError("option --" + name + " given twice (" + quote_text(it->second, 60) + " and " +
                           quote_text(value, 60) + ")");
      } else {
        throw UsageError("unknown option --" + name);
      }
    }
  }

  bool flag(const std::string& name) const { return flags_.count(name) > 0; }
  bool has(const std::string& name) const { return values_.count(name) > 0; }
  const std::vector<std::string>& positional() const { return positional_; }

  /// Requires between `min` and `max` positional arguments, described by `what`.
  void expect_positional(std::size_t min, std::size_t max, const std::string& what) const {
    if (positional_.size() < min || positional_.size() > max)
      throw UsageError("expected " + what + ", got " + std::to_string(positional_.size()) +
                       " positional argument(s)");
  }

  std::string string(const std::string& name, const std::string& fallback = "") const {
    const auto it = values_.find(name);
    return it == values_.end() ? fallback : it->second;
  }

  /// A string value that must be one of `choices`.
  std::string choice(const std::string& name, const std::vector<std::string>& choices,
                     const std::string& fallback) const {
    const std::string v = string(name, fallback);
    if (std::find(choices.begin(), choices.end(), v) == choices.end()) {
      throw UsageError("option --" + name + ": " + quote_text(v, 60) + " is not one of " + join(choices, "|"));
    }
    return v;
  }

  long long integer(const std::string& name, long long fallback,
                    long long min = std::numeric_limits<long long>::min(),
                    long long max = std::numeric_limits<long long>::max()) const {
    if (!has(name)) return fallback;
    return parse_integer(string(name), "--" + name, min, max);
  }

  double number(const std::string& name, double fallback,
                double min = -std::numeric_limits<double>::infinity(),
                double max = std::numeric_limits<double>::infinity()) const {
    if (!has(name)) return fallback;
    return parse_number(string(name), "--" + name, min, max);
  }

  /// A comma-separated list of numbers, e.g. `--weights 1,1,1,0.01`.
  std::vector<double> numbers(const std::string& name,
                              double min = -std::numeric_limits<double>::infinity(),
                              double max = std::numeric_limits<double>::infinity()) const {
    std::vector<double> out;
    if (!has(name)) return out;
    for (const auto& item : split(string(name), ','))
      out.push_back(parse_number(item, "--" + name, min, max));
    return out;
  }

  /// `items` joined by `sep`: join({"a", "b"}, ", ") == "a, b".
  static std::string join(const std::vector<std::string>& items, const std::string& sep) {
    std::string out;
    for (const auto& item : items) out += (out.empty() ? "" : sep) + item;
    return out;
  }

  static std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> parts;
    std::string cur;
    for (char c : s) {
      if (c == sep) {
        parts.push_back(cur);
        cur.clear();
      } else {
        cur += c;
      }
    }
    parts.push_back(cur);
    return parts;
  }

  static long long parse_integer(const std::string& text, const std::string& what, long long min,
                                 long long max) {
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(text.c_str(), &end, 10);
    // strtoll skips leading white space; a value is the whole text.
    if (text.empty() || starts_with_space(text) || end != text.c_str() + text.size() || errno == ERANGE)
      throw UsageError(what + ": " + quote_text(text, 60) + " is not an integer");
    if (v < min || v > max) throw UsageError(what + ": " + text + " is " + range_text(min, max));
    return v;
  }

  static double parse_number(const std::string& text, const std::string& what, double min, double max) {
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || starts_with_space(text) || end != text.c_str() + text.size())
      throw UsageError(what + ": " + quote_text(text, 60) + " is not a number");
    if (!std::isfinite(v)) throw UsageError(what + ": " + quote_text(text, 60) + " is not finite");
    // strtod rounds a value too small for a double to 0 (or a subnormal) and
    // sets ERANGE: 1e-400 must not pass as 0.
    if (errno == ERANGE && std::abs(v) < std::numeric_limits<double>::min())
      throw UsageError(what + ": " + quote_text(text, 60) + " is too small for a double (it would be " +
                       format_value(v) + ")");
    if (v < min || v > max) throw UsageError(what + ": " + text + " is " + range_text(min, max));
    return v;
  }

  /// How a value outside [min, max] misses it: "outside [0, 1]", or
  /// "below 0" / "above 5" when the other bound is open: infinite for a
  /// number, the type's own limit for an integer (no one asked for a value
  /// up to 9223372036854775807). Bounds are written exactly.
  template <typename T>
  static std::string range_text(T min, T max) {
    static_assert(std::is_same_v<T, double> || std::is_same_v<T, long long>, "range_text: double or long long");
    std::string low, high;
    bool open_low = false, open_high = false;
    if constexpr (std::is_same_v<T, double>) {
      low = format_exact(min), high = format_exact(max);
      open_low = std::isinf(min), open_high = std::isinf(max);
    } else {
      low = std::to_string(min), high = std::to_string(max);
      open_low = min == std::numeric_limits<T>::min(), open_high = max == std::numeric_limits<T>::max();
    }
    if (open_high && !open_low) return "below " + low;
    if (open_low && !open_high) return "above " + high;
    return "outside [" + low + ", " + high + "]";
  }

 private:
  // Is --help or -h among the options? The argument after `--name` (a value
  // option, without "=") is its value, as the parse below takes it: `-h`
  // there is a value, `--help` a missing value (no value starts with "--").
  static bool asks_for_help(const Args& args, const std::set<std::string>& value_options) {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      if (a == "--") return false;
      if (a == "--help" || a == "-h") return true;
      if (a.size() > 2 && a.compare(0, 2, "--") == 0 && a.find('=') == std::string::npos &&
          value_options.count(a.substr(2)))
        ++i;
    }
    return false;
  }

  static bool starts_with_space(const std::string& text) {
    return !text.empty() && std::isspace(static_cast<unsigned char>(text.front())) != 0;
  }

  std::vector<std::string> positional_;
  std::map<std::string, std::string> values_;
  std::set<std::string> flags_;
};

/// UsageError naming option `name` (its value as given, `text`) when `v`,
/// read into a float (an ICP of --scalar float), would not mean what it
/// says: beyond the float range it becomes inf, and a nonzero value below
/// the smallest float becomes 0 (for --relative-tolerance, "no relative
/// stop"). 0 itself passes; so do float subnormals, which keep a value.
inline void check_float_value(const std::string& name, const std::string& text, double v) {
  if (std::abs(v) > static_cast<double>(std::numeric_limits<float>::max()))
    throw UsageError("--" + name + ": " + text + " is beyond the range of --scalar float (|v| <= " +
                     format_value(static_cast<double>(std::numeric_limits<float>::max())) +
                     "); use --scalar double");
  if (v != 0 && static_cast<float>(v) == 0)
    throw UsageError("--" + name + ": " + text + " is too small for --scalar float (it would be 0); give 0 for 0, " +
                     "or use --scalar double");
}

/// A thread-safe progress line on stderr, shown only when stderr is a
/// terminal (so logs and CI output stay clean). Use as an
/// iclap::ProgressCallback.
class Progress {
 public:
  explicit Progress(std::string label) : label_(std::move(label)), tty_(isatty(2) != 0) {}
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  ~Progress() { finish(); }

  void operator()(std::size_t done, std::size_t total) {
    if (!tty_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    if (done < total && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const double pct = total ? 100.0 * static_cast<double>(done) / static_cast<double>(total) : 100.0;
    std::fprintf(stderr, "\r%s: %zu/%zu (%.0f%%)   ", label_.c_str(), done, total, pct);
    std::fflush(stderr);
    shown_ = true;
  }

  /// Ends the progress line (idempotent).
  void finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shown_) std::fprintf(stderr, "\n");
    shown_ = false;
  }

 private:
  std::string label_;
  bool tty_;
  bool shown_ = false;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point last_{};
};

/// `--search auto|kdtree|brute` applied to `AdaptiveSearch` settings (the
/// one search type the commands instantiate): auto keeps them (brute force
/// up to their limit, a kd-tree above), kdtree always builds the tree,
/// brute always scans.
template <typename AdaptiveSettings>
void apply_search_choice(const std::string& choice, AdaptiveSettings& settings) {
  if (choice == "kdtree") settings.brute_force_max_coordinates = 0;
  if (choice == "brute") settings.brute_force_max_coordinates = std::numeric_limits<std::size_t>::max();
}

}  // namespace iclap::cli

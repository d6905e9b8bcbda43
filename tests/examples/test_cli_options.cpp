// SPDX-License-Identifier: MIT
// The option parsing of the example programs (examples/iclap/cli.hpp,
// touch_counts.hpp, sim_options.hpp): what is accepted, and that what is
// refused is a UsageError naming the option and the value as given.

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "cli.hpp"
#include "iclap/search/adaptive.hpp"
#include "sim_options.hpp"
#include "touch_counts.hpp"
#include "../support/errors.hpp"

namespace {

using iclap::cli::Args;
using iclap::cli::Options;
using iclap::cli::UsageError;
using iclap::test::what_of;

// The refusal of `args` by an Options that knows --k, --out and --weights
// (values) and --json (a flag).
std::string refusal(const Args& args) {
  return what_of<UsageError>([&] { const Options o(args, {"k", "out", "weights"}, {"json"}); });
}

// The refusal of option --name given `value`, read by `read`.
template <typename Read>
std::string refusal_of(const std::string& name, const std::string& value, Read&& read) {
  return what_of<UsageError>([&] {
    const Options o({"--" + name, value}, {name});
    read(o);
  });
}

std::string touches_error(const std::string& text) {
  return what_of<UsageError>([&] { iclap::cli::parse_touches(text); });
}

// The exploration settings that `args` (simulation options) give, from the
// library's defaults.
iclap::ExplorationSettings simulated(const Args& args) {
  const Options o(args, iclap::cli::simulation_option_names());
  iclap::ExplorationSettings ex;
  iclap::cli::parse_simulation_options(o, ex);
  return ex;
}

std::string simulation_error(const Args& args) {
  return what_of<UsageError>([&] { simulated(args); });
}

}  // namespace

TEST_CASE("options: --name VALUE, --name=VALUE and flags; '--' ends the options") {
  const Options o({"a.txt", "--k", "5", "--out=dir", "--json", "--weights=1,2", "--", "--k", "b.txt"},
                  {"k", "out", "weights"}, {"json"});
  CHECK(o.string("k") == "5");
  CHECK(o.string("out") == "dir");
  CHECK(o.string("weights") == "1,2");
  CHECK(o.flag("json"));
  // After "--" everything is positional, also what looks like an option.
  CHECK(o.positional() == std::vector<std::string>{"a.txt", "--k", "b.txt"});
  // A value after '=' may hold '=' itself (--trim patch=0.5).
  const Options eq({"--trim=patch=0.5"}, {"trim"});
  CHECK(eq.string("trim") == "patch=0.5");
  // A value option given last, with its value, is complete.
  CHECK(Options({"x", "--k", "7"}, {"k"}).string("k") == "7");
  // A single dash is no option: a negative number is a value.
  CHECK(Options({"--k", "-3"}, {"k"}).string("k") == "-3");
  CHECK_FALSE(o.has("missing"));
  CHECK(o.string("missing", "fallback") == "fallback");
}

TEST_CASE("options: unknown options, missing and empty values are refused, naming the option") {
  CHECK(refusal({"--kk", "5"}) == "unknown option --kk");
  CHECK(refusal({"--json=yes"}) == "option --json takes no value (got 'yes')");
  CHECK(refusal({"a", "--k"}) == "option --k needs a value");
  // The next option is no value: `--out --k 5` forgot the value of --out.
  CHECK(refusal({"--out", "--k", "5"}) == "option --out needs a value (got the option '--k')");
  CHECK(refusal({"--out="}) == "option --out: empty value");
  CHECK(refusal({"--out", ""}) == "option --out: empty value");
  CHECK(refusal({"--k", "1", "--out", "d"}) == "(no error)");
}

// Input: `--out -h` and `--out --help` (also the `iclap` runs in
// tests/examples/CMakeLists.txt, cli_help_as_option_value and neighbours).
// Was: main took any -h or --help before "--" for a request for help:
// usage printed, exit status 0, the run not done.
// Now: Options decides. The argument after a value option is its value:
// -h is one (as -3 is), --help a missing value, as --k is; -h or --help
// where an option may stand asks for help (HelpRequested), whatever else
// the line holds; after "--" they are operands.
TEST_CASE("options: -h as the value of an option is its value; -h or --help elsewhere asks for help") {
  using iclap::cli::HelpRequested;
  CHECK(Options({"--out", "-h"}, {"out"}).string("out") == "-h");
  CHECK(Options({"a.csv", "--out", "-h", "--k", "2"}, {"out", "k"}).string("out") == "-h");
  CHECK(refusal({"--out", "--help"}) == "option --out needs a value (got the option '--help')");
  CHECK(Options({"--out=--help"}, {"out"}).string("out") == "--help");
  CHECK(Options({"--", "-h", "--help"}, {"out"}).positional() == std::vector<std::string>{"-h", "--help"});
  const std::set<std::string> values = {"out", "k"};
  for (const Args& args : std::vector<Args>{{"-h"},
                                            {"--help"},
                                            {"a.csv", "--out", "d", "-h"},
                                            {"--out", "-h", "--help"},
                                            {"--json", "-h"},
                                            {"--no-such-option", "-h"},  // help first, the error after
                                            {"--k", "x", "--help", "--", "b"}}) {
    const std::string line = Options::join(args, " ");
    CAPTURE(line);
    CHECK_THROWS_AS(Options(args, values, {"json"}), HelpRequested);
  }
}

TEST_CASE("options: a value option given twice is refused, naming both values; a flag may repeat") {
  // Keeping either value would lose the other without a word (`--trim
  // patch=0.5 --trim icp=0.7` ran with icp's trim alone).
  CHECK(refusal({"--k", "3", "--k", "50"}) == "option --k given twice ('3' and '50')");
  CHECK(refusal({"--out=a", "x", "--out", "a"}) == "option --out given twice ('a' and 'a')");
  CHECK(refusal({"--k", "3", "--", "--k", "50"}) == "(no error)");  // the second is positional
  const Options flags({"--json", "--json", "--k", "3"}, {"k"}, {"json"});
  CHECK(flags.flag("json"));
  CHECK(flags.string("k") == "3");
}

TEST_CASE("options: the number of positional arguments is checked, naming what is expected") {
  const Options two({"model.txt", "test.txt"}, {});
  auto expect = [&](std::size_t min, std::size_t max) {
    return what_of<UsageError>([&] { two.expect_positional(min, max, "MODEL TEST"); });
  };
  // Two is within [2, 2], [1, 2] and [2, 3] ...
  CHECK(expect(2, 2) == "(no error)");
  CHECK(expect(1, 2) == "(no error)");
  CHECK(expect(2, 3) == "(no error)");
  // ... and neither within [3, 4] nor within [0, 1].
  CHECK(expect(3, 4) == "expected MODEL TEST, got 2 positional argument(s)");
  CHECK(expect(0, 1) == "expected MODEL TEST, got 2 positional argument(s)");
}

TEST_CASE("--search: kdtree always builds the tree, brute always scans, auto keeps the settings") {
  using Settings = iclap::AdaptiveSearch<double>::Settings;
  const Settings defaults;
  Settings s;
  iclap::cli::apply_search_choice("kdtree", s);
  CHECK(s.brute_force_max_coordinates == 0);
  s = Settings{};
  iclap::cli::apply_search_choice("brute", s);
  CHECK(s.brute_force_max_coordinates == std::numeric_limits<std::size_t>::max());
  s = Settings{};
  iclap::cli::apply_search_choice("auto", s);
  CHECK(s.brute_force_max_coordinates == defaults.brute_force_max_coordinates);
}

TEST_CASE("options: a choice is one of the listed values") {
  const Options o({"--transform", "full"}, {"transform", "search"});
  const std::vector<std::string> transforms{"full", "planar"};
  CHECK(o.choice("transform", transforms, "planar") == "full");
  CHECK(o.choice("search", {"auto", "brute"}, "auto") == "auto");
  CHECK(refusal_of("transform", "affine", [&](const Options& r) { r.choice("transform", transforms, "planar"); }) ==
        "option --transform: 'affine' is not one of full|planar");
}

TEST_CASE("options: integers are whole, in range and within long long") {
  const Options none({}, {"k"});
  CHECK(none.integer("k", 50, 1, 100) == 50);
  auto read = [](long long min, long long max) { return [=](const Options& o) { o.integer("k", 50, min, max); }; };
  // The bounds themselves are in range.
  CHECK(Options({"--k", "1"}, {"k"}).integer("k", 50, 1, 100) == 1);
  CHECK(Options({"--k", "100"}, {"k"}).integer("k", 50, 1, 100) == 100);
  CHECK(refusal_of("k", "0", read(1, 100)) == "--k: 0 is outside [1, 100]");
  CHECK(refusal_of("k", "101", read(1, 100)) == "--k: 101 is outside [1, 100]");
  // With one bound open (the type's own limit), the other is named alone,
  // as for numbers: no "outside [0, 9223372036854775807]".
  const auto lowest = std::numeric_limits<long long>::min(), largest = std::numeric_limits<long long>::max();
  CHECK(refusal_of("k", "-1", read(0, largest)) == "--k: -1 is below 0");
  CHECK(refusal_of("k", "0", read(1, largest)) == "--k: 0 is below 1");
  CHECK(refusal_of("k", "101", read(lowest, 100)) == "--k: 101 is above 100");
  CHECK(refusal_of("k", "-101", read(-100, largest)) == "--k: -101 is below -100");
  CHECK(Options({"--k", "-9223372036854775808"}, {"k"}).integer("k", 50) == lowest);
  CHECK(refusal_of("k", "5x", read(1, 100)) == "--k: '5x' is not an integer");
  CHECK(refusal_of("k", "2.5", read(1, 100)) == "--k: '2.5' is not an integer");
  // Beyond long long: refused, not clamped to its largest value.
  const auto any = std::numeric_limits<long long>::max();
  CHECK(refusal_of("k", "99999999999999999999", read(0, any)) == "--k: '99999999999999999999' is not an integer");
  CHECK(what_of<UsageError>([] { Options::parse_integer("", "--touches", 1, 5); }) == "--touches: '' is not an integer");
}

TEST_CASE("options: numbers are finite, whole strings and in range") {
  auto read = [](double min, double max) { return [=](const Options& o) { o.number("x", 0, min, max); }; };
  const double inf = std::numeric_limits<double>::infinity();
  CHECK(Options({}, {"x"}).number("x", 0.25, 0, 1) == 0.25);
  CHECK(Options({"--x", "0"}, {"x"}).number("x", 0.5, 0, 1) == 0);
  CHECK(Options({"--x", "1"}, {"x"}).number("x", 0.5, 0, 1) == 1);
  CHECK(Options({"--x", "1e-3"}, {"x"}).number("x", 0.5, 0, 1) == 1e-3);
  CHECK(refusal_of("x", "-0.5", read(0, 1)) == "--x: -0.5 is outside [0, 1]");
  CHECK(refusal_of("x", "1.5", read(0, 1)) == "--x: 1.5 is outside [0, 1]");
  CHECK(refusal_of("x", "0.5abc", read(0, 1)) == "--x: '0.5abc' is not a number");
  // Not finite, also without bounds: nan passes any comparison.
  CHECK(refusal_of("x", "nan", read(-inf, inf)) == "--x: 'nan' is not finite");
  CHECK(refusal_of("x", "inf", read(-inf, inf)) == "--x: 'inf' is not finite");
  CHECK(refusal_of("x", "1e999", read(-inf, inf)) == "--x: '1e999' is not finite");
  CHECK(what_of<UsageError>([] { Options::parse_number("", "--x", -1, 1); }) == "--x: '' is not a number");
}

TEST_CASE("options: a value is the whole text; a number too small for a double is refused; the range is named") {
  auto read_k = [](const Options& o) { o.integer("k", 50, 1, 100); };
  auto read_x = [](double min, double max) { return [=](const Options& o) { o.number("x", 0, min, max); }; };
  const double inf = std::numeric_limits<double>::infinity();
  // strtoll and strtod skip leading white space; the options do not.
  CHECK(refusal_of("k", " 3", read_k) == "--k: ' 3' is not an integer");
  CHECK(refusal_of("k", "\t3", read_k) == "--k: '\\x093' is not an integer");
  CHECK(refusal_of("x", " 0.5", read_x(0, 1)) == "--x: ' 0.5' is not a number");
  CHECK(refusal_of("x", "0.5 ", read_x(0, 1)) == "--x: '0.5 ' is not a number");
  // Below the smallest normal double strtod gives 0 or a subnormal: refused,
  // also where 0 would be in range; the smallest normal itself is a value.
  CHECK(refusal_of("x", "1e-400", read_x(0, 1)) == "--x: '1e-400' is too small for a double (it would be 0)");
  CHECK(refusal_of("x", "-1e-400", read_x(-inf, inf)) == "--x: '-1e-400' is too small for a double (it would be -0)");
  CHECK(refusal_of("x", "1e-310", read_x(0, 1)) == "--x: '1e-310' is too small for a double (it would be 1e-310)");
  CHECK(Options({"--x", "2.2250738585072014e-308"}, {"x"}).number("x", 0, 0, 1) ==
        std::numeric_limits<double>::min());
  // The range as the caller gave it: both bounds, or the finite one.
  CHECK(refusal_of("x", "2", read_x(0, 1.5)) == "--x: 2 is outside [0, 1.5]");
  CHECK(refusal_of("x", "-1", read_x(0, inf)) == "--x: -1 is below 0");
  CHECK(refusal_of("x", "7", read_x(-inf, 5)) == "--x: 7 is above 5");
  // A bound is written exactly, so a value just beyond it is seen to be.
  CHECK(refusal_of("x", "0.30000000000000005", read_x(0, 0.3)) ==
        "--x: 0.30000000000000005 is outside [0, 0.3]");
}

TEST_CASE("options: a list of numbers keeps every item; an empty item is refused") {
  CHECK(Options({"--weights", "1,1,1,0.01"}, {"weights"}).numbers("weights") == std::vector<double>{1, 1, 1, 0.01});
  CHECK(Options({"--weights", "2"}, {"weights"}).numbers("weights") == std::vector<double>{2});
  CHECK(Options({}, {"weights"}).numbers("weights").empty());
  auto read = [](const Options& o) { o.numbers("weights", 0); };
  CHECK(refusal_of("weights", "1,,2", read) == "--weights: '' is not a number");
  CHECK(refusal_of("weights", "1,2,", read) == "--weights: '' is not a number");
  CHECK(refusal_of("weights", "1,-2", read) == "--weights: -2 is below 0");
  CHECK(Options::split("a,,b", ',') == std::vector<std::string>{"a", "", "b"});
}

TEST_CASE("--touches: counts and ranges, each count once, in [1, 100000], in increasing order") {
  CHECK(iclap::cli::parse_touches("1..3") == std::vector<int>{1, 2, 3});
  CHECK(iclap::cli::parse_touches("3..3") == std::vector<int>{3});
  CHECK(iclap::cli::parse_touches("1,5,10..12") == std::vector<int>{1, 5, 10, 11, 12});
  CHECK(iclap::cli::parse_touches("100000") == std::vector<int>{100000});
  CHECK(iclap::cli::parse_touches("20,1..3,10") == std::vector<int>{1, 2, 3, 10, 20});
  CHECK(touches_error("5..2") == "--touches: empty range '5..2'");
  CHECK(touches_error("1..3,2") == "--touches: 2 is listed twice");
  CHECK(touches_error("0..3") == "--touches: 0 is outside [1, 100000]");
  CHECK(touches_error("1..100001") == "--touches: 100001 is outside [1, 100000]");
  CHECK(touches_error("100001") == "--touches: 100001 is outside [1, 100000]");
  CHECK(touches_error("0") == "--touches: 0 is outside [1, 100000]");
  CHECK(touches_error("1...3") == "--touches: '.3' is not an integer");
  CHECK(touches_error("1..") == "--touches: '' is not an integer");
  CHECK(touches_error("1,,2") == "--touches: '' is not an integer");
  CHECK(touches_error("1-3") == "--touches: '1-3' is not an integer");
}

TEST_CASE("simulation options: millimetres and degrees become metres and radians; absent ones keep the defaults") {
  const iclap::ExplorationSettings defaults;
  const auto ex = simulated({"--shift-mm", "5", "--yaw-deg", "90", "--frames", "1", "--sweep-min-mm", "20",
                             "--sweep-max-mm", "20", "--turn-probability", "1", "--start-candidates", "64"});
  CHECK(ex.placement_shift == doctest::Approx(0.005));
  CHECK(ex.placement_yaw == doctest::Approx(std::acos(-1.0) / 2));
  CHECK(ex.max_frames_mean == 1);
  // Equal sweep lengths are allowed.
  CHECK(ex.sweep_length_min == doctest::Approx(0.02));
  CHECK(ex.sweep_length_max == doctest::Approx(0.02));
  CHECK(ex.turn_probability == 1);
  CHECK(ex.start_candidates == 64);
  const auto kept = simulated({"--frames", "40"});
  CHECK(kept.max_frames_mean == 40);
  CHECK(kept.placement_shift == defaults.placement_shift);
  CHECK(kept.placement_yaw == defaults.placement_yaw);
  CHECK(kept.start_candidates == defaults.start_candidates);
}

TEST_CASE("simulation options: values out of range are refused, naming the option and the value") {
  CHECK(simulation_error({"--frames", "0"}) == "--frames: 0 is outside [1, 1e+06]");
  CHECK(simulation_error({"--turn-probability", "1.5"}) == "--turn-probability: 1.5 is outside [0, 1]");
  CHECK(simulation_error({"--start-candidates", "0"}) == "--start-candidates: 0 is outside [1, 64]");
  CHECK(simulation_error({"--start-candidates", "65"}) == "--start-candidates: 65 is outside [1, 64]");
  CHECK(simulation_error({"--yaw-deg", "181"}) == "--yaw-deg: 181 is outside [0, 180]");
  // Both sweep lengths as given, or the default of the one not given.
  CHECK(simulation_error({"--sweep-min-mm", "10", "--sweep-max-mm", "5.0"}) ==
        "--sweep-max-mm must be >= --sweep-min-mm, got 5.0 < 10");
  const iclap::ExplorationSettings defaults;
  CHECK(simulation_error({"--sweep-min-mm", "1000"}) ==
        "--sweep-max-mm must be >= --sweep-min-mm, got " + iclap::format_value(defaults.sweep_length_max * 1e3) +
            " < 1000");
}

TEST_CASE("options: range_text names one bound only when the other is open, both when both are open or closed") {
  // integer() and number() never refuse a value where both bounds are open,
  // so range_text's own answer for such a range shows only here: both
  // bounds, not "below" the open lower one or "above" the open upper one.
  const auto lowest = std::numeric_limits<long long>::min(), largest = std::numeric_limits<long long>::max();
  CHECK(Options::range_text(lowest, largest) ==
        "outside [" + std::to_string(lowest) + ", " + std::to_string(largest) + "]");
  CHECK(Options::range_text(0LL, largest) == "below 0");
  CHECK(Options::range_text(lowest, 7LL) == "above 7");
  CHECK(Options::range_text(-3LL, 7LL) == "outside [-3, 7]");
  const double inf = std::numeric_limits<double>::infinity();
  CHECK(Options::range_text(-inf, inf) == "outside [-inf, inf]");
  CHECK(Options::range_text(0.5, inf) == "below 0.5");
  CHECK(Options::range_text(-inf, 0.25) == "above 0.25");
}

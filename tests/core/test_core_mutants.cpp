// SPDX-License-Identifier: MIT
// Behaviour a mutation-testing pass over include/iclap/core found unpinned:
// each case fails for at least one single-site change of the library (the
// strictness of check_positive / check_non_negative and the argument and
// value they name, check_not_empty's two reasons, smallest_spread, the
// location check_coordinate_range names, ParseError's line, the bytes
// quote_text escapes and where it cuts, parallel_for's thread count for
// threads = 1, its worker ids and its stop after a failure, the generator's
// published seeding and output function, derive's use of every id, the
// modulo bias of below(), normal(mean, sigma), uniform(a, b) where b - a
// overflows, ProgressCounter's serialised calls, and append_utf8 at every
// boundary of the encoding).

#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/parallel.hpp"
#include "iclap/core/progress.hpp"
#include "iclap/core/random.hpp"
#include "iclap/core/utf8.hpp"
#include "../support/errors.hpp"

using namespace iclap;
using iclap::test::what_of;

TEST_CASE("check_positive, check_non_negative, scalar check_finite: the boundary, infinities, NaN, argument, value") {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double tiny = std::numeric_limits<double>::denorm_min();
  // 0 is the boundary: refused as positive, taken as non-negative.
  CHECK(what_of([] { check_positive(0.0, "settings.voxel"); }) ==
        "settings.voxel: must be finite and positive, got 0");
  CHECK(what_of([] { check_non_negative(0.0, "settings.margin"); }) == "(no error)");
  CHECK(what_of([&] { check_positive(tiny, "settings.voxel"); }) == "(no error)");
  CHECK(what_of([&] { check_non_negative(tiny, "settings.margin"); }) == "(no error)");
  // Infinities and NaN are refused by both; the value is written by
  // format_value (6 significant digits, never 0.000000 for a tiny one).
  for (const double v : {inf, -inf, nan}) {
    CAPTURE(v);
    CHECK(what_of([&] { check_positive(v, "p"); }) == "p: must be finite and positive, got " + format_value(v));
    CHECK(what_of([&] { check_non_negative(v, "n"); }) == "n: must be finite and >= 0, got " + format_value(v));
    CHECK(what_of([&] { check_finite(v, "z0"); }) == "z0: must be finite, got " + format_value(v));
  }
  // The scalar check_finite takes any finite value, the extremes and the
  // signs included.
  const double big = std::numeric_limits<double>::max();
  for (const double v : {0.0, -0.0, tiny, -2.5, big, -big}) {
    CAPTURE(v);
    CHECK(what_of([&] { check_finite(v, "z0"); }) == "(no error)");
  }
  CHECK(what_of<InvalidArgument>([&] { check_finite(nan, "from"); }) == "from: must be finite, got nan");
  CHECK(what_of([] { check_positive(-2.5, "sigma"); }) == "sigma: must be finite and positive, got -2.5");
  CHECK(what_of([] { check_non_negative(-1e-310, "margin"); }) == "margin: must be finite and >= 0, got -1e-310");
  CHECK(what_of([] { check_non_negative(-0.0, "margin"); }) == "(no error)");  // -0 == 0
}

TEST_CASE("check_not_empty tells no points from dimension 0; check_coordinate_range names row and column") {
  CHECK(what_of<EmptyInput>([] { check_not_empty(Eigen::MatrixXd(3, 0), "model"); }) == "model: has no points");
  CHECK(what_of<EmptyInput>([] { check_not_empty(Eigen::MatrixXd(0, 5), "model"); }) == "model: has dimension 0");
  CHECK(what_of<EmptyInput>([] { check_not_empty(Eigen::MatrixXd(1, 1), "model"); }) == "(no error)");
  // The offending coefficient off the diagonal, so that row and column
  // cannot be confused; the float range is named for a float registration.
  Eigen::MatrixXf m = Eigen::MatrixXf::Zero(3, 4);
  m(1, 2) = 1e20f;
  const std::string w = what_of([&] { check_coordinate_range<float>(m, "test"); });
  CHECK(w.rfind("test: value 1e+20 at row 1, column 2 is beyond the float range of distances (|v| <= 1.84467e+15)",
                0) == 0);
  m(1, 2) = 1e15f;  // inside
  CHECK(what_of([&] { check_coordinate_range<float>(m, "test"); }) == "(no error)");
}

TEST_CASE_TEMPLATE("smallest_spread and largest_coordinate: the documented values; squares at the smallest spread",
                   Scalar, float, double) {
  const bool is_float = std::is_same_v<Scalar, float>;
  // The values the header documents.
  CHECK(smallest_spread<Scalar>() == doctest::Approx(is_float ? 9.1e-13 : 6.7e-139).epsilon(0.01));
  CHECK(format_value(largest_coordinate<Scalar>()) == (is_float ? "1.84467e+15" : "1.34078e+150"));
  // At the smallest spread, a difference of one part in epsilon squares to
  // a normal number (not a subnormal or 0), and it is the smallest that
  // does: at a tenth of it the square is below the normal range.
  const Scalar eps = std::numeric_limits<Scalar>::epsilon();
  const Scalar d = static_cast<Scalar>(smallest_spread<Scalar>()) * eps;
  CHECK(std::isnormal(d * d));
  CHECK_FALSE(std::isnormal((d / 10) * (d / 10)));
}

TEST_CASE("ParseError keeps file, 1-based line and reason apart") {
  const ParseError e("touches.csv", 7, "negative pressure");
  CHECK(e.file() == "touches.csv");
  CHECK(e.line() == 7);
  CHECK(e.reason() == "negative pressure");
  CHECK(std::string(e.what()) == "touches.csv:7: negative pressure");
  CHECK(ParseError("mesh.obj", 0, "no faces").line() == 0);  // the whole file
}

TEST_CASE("quote_text escapes exactly the control bytes and the bytes of no UTF-8 character, and cuts between characters") {
  // Every byte alone: escaped as \xNN (two lowercase hex digits) when below
  // 0x20 or 0x7f, or from 0x80 (alone, no such byte is a UTF-8 character);
  // kept otherwise (space included).
  int escaped = 0;
  for (int b = 0; b < 256; ++b) {
    CAPTURE(b);
    const std::string one(1, static_cast<char>(b));
    char hex[8];
    std::snprintf(hex, sizeof hex, "\\x%02x", b);
    const bool control = b < 0x20 || b == 0x7f;
    CHECK(is_control_byte(static_cast<unsigned char>(b)) == control);
    CHECK(quote_text(one) == (control || b >= 0x80 ? "'" + std::string(hex) + "'" : "'" + one + "'"));
    escaped += control || b >= 0x80;
  }
  CHECK(escaped == 33 + 128);
  CHECK(quote_text("jaw width") == "'jaw width'");
  // A cut that falls on a character boundary keeps every whole character
  // before it, multi-byte ones included.
  CHECK(quote_text("ab\xc3\xbc", 2) == "'ab...'");
  CHECK(quote_text("\xc3\xbc" "ab", 2) == "'\xc3\xbc...'");
  CHECK(quote_text("a\xe2\x82\xac" "b", 4) == "'a\xe2\x82\xac...'");
  CHECK(quote_text("a\xe2\x82\xac" "b", 3) == "'a...'");  // inside the euro sign: before it
  CHECK(quote_text("\xf0\x9f\x98\x80", 4) == "'\xf0\x9f\x98\x80'");  // not longer: not cut
  CHECK(quote_text("\xc3\xbc" "b", 1) == "'...'");  // no whole character fits
}

TEST_CASE("parallel_for: threads = 0 is one per core (at most one per item); 1 is the calling thread alone") {
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  CHECK(detail::worker_count(0, 1000) == std::min(cores, 1000u));
  CHECK(detail::worker_count(0, 1) == 1);
  // 1 is one thread whatever the machine: the calling one.
  CHECK(detail::worker_count(1, 1000) == 1);
  const std::thread::id caller = std::this_thread::get_id();
  int elsewhere = 0;  // only written if items run on another thread
  std::vector<unsigned> workers;
  detail::parallel_for(200, 1, [&](std::size_t, unsigned worker) {
    if (std::this_thread::get_id() != caller) ++elsewhere;
    workers.push_back(worker);
  });
  CHECK(elsewhere == 0);
  CHECK(workers == std::vector<unsigned>(200, 0u));
}

TEST_CASE("parallel_for: each worker id belongs to one thread, each thread has one id") {
  // So per-worker state indexed by it is never shared. As many items as
  // threads, each waiting until all have started: every thread takes one.
  for (unsigned threads : {2u, 4u}) {
    CAPTURE(threads);
    std::mutex m;
    std::condition_variable all_in;
    unsigned started = 0;
    bool waited_in_vain = false;
    std::map<unsigned, std::set<std::thread::id>> threads_of;
    std::map<std::thread::id, std::set<unsigned>> ids_of;
    detail::parallel_for(threads, threads, [&](std::size_t, unsigned worker) {
      std::unique_lock<std::mutex> lock(m);
      threads_of[worker].insert(std::this_thread::get_id());
      ids_of[std::this_thread::get_id()].insert(worker);
      ++started;
      all_in.notify_all();
      if (!all_in.wait_for(lock, std::chrono::seconds(10), [&] { return started == threads; })) waited_in_vain = true;
    });
    CHECK_FALSE(waited_in_vain);
    CHECK(threads_of.size() == threads);
    CHECK(ids_of.size() == threads);
    for (const auto& entry : threads_of) CHECK(entry.second.size() == 1);
    for (const auto& entry : ids_of) CHECK(entry.second.size() == 1);
  }
  // No more threads than worker_count: with one item more than threads,
  // each item waiting (up to 300 ms) for all to have started, a thread
  // beyond them would take the extra item, with an id past the last.
  const unsigned threads = 2;
  std::mutex m;
  std::condition_variable all_in;
  unsigned started = 0;
  std::set<unsigned> ids;
  detail::parallel_for(threads + 1, threads, [&](std::size_t, unsigned worker) {
    std::unique_lock<std::mutex> lock(m);
    ids.insert(worker);
    ++started;
    all_in.notify_all();
    all_in.wait_for(lock, std::chrono::milliseconds(300), [&] { return started == threads + 1; });
  });
  CHECK(ids == std::set<unsigned>{0, 1});
}

TEST_CASE("parallel_for: after the first failure no new item starts") {
  // The other thread runs at most the items it took before the failure was
  // recorded, not the rest.
  // (The items sleep so that the rest would take a second or more: a thread
  // descheduled for a moment does not make the count look like the rest.)
  const std::size_t n = 20000;
  std::atomic<std::size_t> ran{0};
  CHECK_THROWS_WITH_AS(detail::parallel_for(n, 2,
                                            [&](std::size_t i, unsigned) {
                                              ++ran;
                                              if (i == 0) throw std::runtime_error("item 0");
                                              std::this_thread::sleep_for(std::chrono::microseconds(50));
                                            }),
                       "item 0", std::runtime_error);
  CHECK(ran.load() < n / 2);
}

namespace {
/// Rotation left by k bits, as xoshiro256** defines it.
std::uint64_t rotl64(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
}  // namespace

TEST_CASE("Rng: splitmix64 seeding and the xoshiro256** output function, as published") {
  // splitmix64 from 1234567 gives 6457827717110365317, 3203168211198807973,
  // 9817491932198370423, 4593380528125082431 (the published test vector);
  // these are the state s[0..3] of Rng(1234567), whose first output is
  // xoshiro256**'s rotl(s[1] * 5, 7) * 9.
  const std::uint64_t s1 = 3203168211198807973ull;
  Rng rng(1234567);
  CHECK(rng() == rotl64(s1 * 5, 7) * 9);
  // splitmix64 from 0 starts with 0xe220a8397b1dcdaf (s[0]); s[1] is its
  // second output, 0x6e789e6aa1b965f4.
  CHECK(Rng(0)() == rotl64(0x6e789e6aa1b965f4ull * 5, 7) * 9);
}

TEST_CASE("Rng::derive: the seed, the stream and the substream each select the stream") {
  // All 27 streams of seeds, streams and substreams 0..2 start differently.
  std::set<std::uint64_t> firsts;
  for (std::uint64_t seed = 0; seed < 3; ++seed)
    for (std::uint64_t stream = 0; stream < 3; ++stream)
      for (std::uint64_t sub = 0; sub < 3; ++sub) firsts.insert(Rng::derive(seed, stream, sub)());
  CHECK(firsts.size() == 27);
  CHECK(Rng::derive(9, 4)() == Rng::derive(9, 4, 0)());  // substream 0 by default
}

TEST_CASE("Rng::below has no modulo bias, also for n near the top of the range; normal(mean, sigma)") {
  // n = 3 * 2^62: r % n of a plain 64-bit draw would land below 2^62 half
  // the time; unbiased, a third of the time.
  Rng rng(17);
  const std::uint64_t n = 3ull << 62;
  const int draws = 30000;
  int low = 0;
  for (int i = 0; i < draws; ++i) {
    const std::uint64_t r = rng.below(n);
    REQUIRE(r < n);
    low += r < (1ull << 62);
  }
  CHECK(std::abs(low / double(draws) - 1.0 / 3) < 0.02);  // 0.02 is ~7 standard deviations
  // normal(mean, sigma): mean and spread where they are asked for.
  double sum = 0, sum2 = 0;
  const int count = 100000;
  for (int i = 0; i < count; ++i) {
    const double z = rng.normal(10.0, 0.5);
    sum += z;
    sum2 += (z - 10.0) * (z - 10.0);
  }
  CHECK(sum / count == doctest::Approx(10.0).epsilon(0.001));
  CHECK(std::sqrt(sum2 / count) == doctest::Approx(0.5).epsilon(0.02));
}

TEST_CASE("Rng::uniform(a, b) over an interval wider than double's range is spread over it, not piled at b") {
  // b - a overflows: the draws must still cover both halves of [a, b).
  Rng rng(23);
  const double a = -1e308, b = 1e308;
  int below_zero = 0;
  const int draws = 4000;
  for (int i = 0; i < draws; ++i) {
    const double u = rng.uniform(a, b);
    REQUIRE(u >= a);
    REQUIRE(u < b);
    below_zero += u < 0;
  }
  CHECK(std::abs(below_zero / double(draws) - 0.5) < 0.05);  // ~6 standard deviations
}

TEST_CASE("ProgressCounter calls its callback one call at a time, from any number of threads") {
  // The callback notices a second call while it is inside one (it stays a
  // moment, so that unserialised ticks would overlap) and a done that does
  // not grow by one.
  std::atomic<int> inside{0};
  std::atomic<int> overlaps{0};
  std::size_t last = 0;
  int out_of_order = 0;
  const std::size_t n = 400;
  ProgressCounter counter(
      [&](std::size_t done, std::size_t total) {
        if (++inside != 1) ++overlaps;
        std::this_thread::sleep_for(std::chrono::microseconds(100));
        if (done != last + 1 || total != n) ++out_of_order;
        last = done;
        --inside;
      },
      n);
  detail::parallel_for(n, 4, [&](std::size_t, unsigned) { counter.tick(); });
  CHECK(overlaps.load() == 0);
  CHECK(out_of_order == 0);
  CHECK(last == n);
}

TEST_CASE("append_utf8: one to four bytes, with the right bytes at every boundary of the encoding") {
  // (code point, its UTF-8 encoding per RFC 3629)
  const std::vector<std::pair<std::uint32_t, std::string>> cases = {
      {0x00, std::string(1, '\0')},
      {0x41, "A"},
      {0x7F, "\x7f"},
      {0x80, "\xc2\x80"},
      {0xE9, "\xc3\xa9"},
      {0x7FF, "\xdf\xbf"},
      {0x800, "\xe0\xa0\x80"},
      {0x20AC, "\xe2\x82\xac"},
      {0xD7FF, "\xed\x9f\xbf"},  // below the surrogates
      {0xE000, "\xee\x80\x80"},  // above them
      {0xFFFD, "\xef\xbf\xbd"},
      {0xFFFF, "\xef\xbf\xbf"},
      {0x10000, "\xf0\x90\x80\x80"},
      {0x1F600, "\xf0\x9f\x98\x80"},
      {0x10FFFF, "\xf4\x8f\xbf\xbf"},
  };
  std::string all;
  for (const auto& c : cases) {
    CAPTURE(c.first);
    std::string out = "x";  // appended to, not replaced
    append_utf8(out, c.first);
    CHECK(out == "x" + c.second);
    all += c.second;
  }
  std::string together;
  for (const auto& c : cases) append_utf8(together, c.first);
  CHECK(together == all);
  // Every encoding append_utf8 gives is well-formed UTF-8.
  CHECK(utf8_error(all) == std::string_view::npos);
}

TEST_CASE("utf8_error: the offset of the first byte that breaks UTF-8, at every boundary of RFC 3629") {
  const auto npos = std::string_view::npos;
  CHECK(utf8_error("") == npos);
  CHECK(utf8_error("hammer") == npos);
  CHECK(utf8_error("h\xc3\xa4mmer") == npos);                  // U+00E4
  CHECK(utf8_error("\xe6\x89\xb3\xe6\x89\x8b") == npos);        // two CJK characters
  CHECK(utf8_error("\xdf\xbf\xe0\xa0\x80\xed\x9f\xbf\xee\x80\x80\xf0\x90\x80\x80\xf4\x8f\xbf\xbf") == npos);
  // (text, offset of the lead byte of the first ill-formed sequence)
  const std::vector<std::pair<std::string, std::size_t>> bad = {
      {"h\xe4mmer", 1},             // Latin-1: E4 leads a 3-byte sequence, 'm' does not continue it
      {"ab\xe4", 2},                // cut short at the end
      {"a\xc3", 1},
      {"A\xe2\x82\xac\xe2\x82", 4},  // the second euro sign cut after two bytes
      {"\x80", 0},                  // a continuation byte with no lead
      {"a\xbf", 1},
      {"\xc0\x80", 0},              // overlong NUL
      {"\xc1\xbf", 0},              // overlong U+007F
      {"\xe0\x9f\xbf", 0},          // overlong U+07FF
      {"\xed\xa0\x80", 0},          // surrogate U+D800
      {"\xed\xbf\xbf", 0},          // surrogate U+DFFF
      {"\xf0\x8f\xbf\xbf", 0},      // overlong U+FFFF
      {"\xf4\x90\x80\x80", 0},      // U+110000
      {"\xf5\x80\x80\x80", 0},      // no lead byte above F4
      {"\xff", 0},
      {"\xe2\x82x", 0},             // the third byte is no continuation: below 0x80
      {"\xe2\x82\xc0", 0},          // ... or above 0xBF
      {"\xf0\x9f\x98\xff", 0},      // the fourth likewise
      {"\xc3\xc3\xa4", 0},          // a lead byte where a continuation belongs
      {"\xe2\x82\xac\xbf", 3},      // a fourth byte that continues nothing
      {"\xf0\x9f\x98", 0},          // a 4-byte sequence cut after 3
      {"ok \xe2\x82\xac then \xc3", 12},
  };
  for (const auto& b : bad) {
    CAPTURE(b.first);
    CHECK(utf8_error(b.first) == b.second);
  }
}

TEST_CASE("utf8_error: a sequence cut by the end of the view is refused, whatever bytes follow in memory") {
  // A view of the start of a longer text: the lead byte's continuation lies
  // just past the view's end, readable but not part of the text. The check
  // must stop at size(), not read one byte beyond it (as it would if the
  // bound were `> size()`; a std::string's own '\0' would hide that).
  const std::string text = "a\xc3\xa4\xe2\x82\xac\xf0\x9f\x98\x80";  // a, U+00E4, U+20AC, U+1F600
  const std::string_view whole(text);
  CHECK(utf8_error(whole) == std::string_view::npos);
  CHECK(utf8_error(whole.substr(0, 1)) == std::string_view::npos);
  CHECK(utf8_error(whole.substr(0, 2)) == 1);   // C3 without its A4
  CHECK(utf8_error(whole.substr(0, 3)) == std::string_view::npos);
  CHECK(utf8_error(whole.substr(0, 4)) == 3);   // E2 alone
  CHECK(utf8_error(whole.substr(0, 5)) == 3);   // E2 82 without AC
  CHECK(utf8_error(whole.substr(0, 8)) == 6);   // F0 9F without 98 80
  CHECK(utf8_error(whole.substr(0, 9)) == 6);   // F0 9F 98 without 80
  CHECK(utf8_error(whole.substr(0, 6)) == std::string_view::npos);
}

// SPDX-License-Identifier: MIT
#include <doctest/doctest.h>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <sstream>
#include <string>
#include <thread>
#include <typeinfo>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/parallel.hpp"
#include "iclap/core/progress.hpp"
#include "iclap/core/random.hpp"
#include "iclap/core/rotation.hpp"
#include "iclap/core/utf8.hpp"
#include "iclap/io/atomic_file.hpp"
#include "../support/file_size_limit.hpp"
#include "../support/temporaries.hpp"

using namespace iclap;

TEST_CASE("Rng: fixed reference values (the sequence must never change)") {
  // Pinned so that a change to the generator, which would silently change
  // every codebook and simulated dataset, fails here first.
  Rng rng(42);
  const std::uint64_t a = rng();
  const std::uint64_t b = rng();
  Rng again(42);
  CHECK(again() == a);
  CHECK(again() == b);
  CHECK(a != b);
  CHECK(Rng(43)() != a);
}

TEST_CASE("Rng: draws are in range and roughly uniform / normal") {
  Rng rng(1);
  double sum = 0, sum2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double u = rng.uniform();
    REQUIRE(u >= 0.0);
    REQUIRE(u < 1.0);
    sum += u;
  }
  CHECK(sum / n == doctest::Approx(0.5).epsilon(0.01));
  sum = 0;
  for (int i = 0; i < n; ++i) {
    const double z = rng.normal();
    REQUIRE(std::isfinite(z));
    sum += z;
    sum2 += z * z;
  }
  CHECK(std::abs(sum / n) < 0.01);
  CHECK(sum2 / n == doctest::Approx(1.0).epsilon(0.02));
  int counts[7] = {};
  for (int i = 0; i < 70000; ++i) counts[rng.below(7)]++;
  for (int c : counts) CHECK(std::abs(c - 10000) < 500);
}

TEST_CASE("Rng::derive gives distinct, order-independent streams") {
  Rng a = Rng::derive(5, 1, 2);
  Rng b = Rng::derive(5, 2, 1);
  Rng c = Rng::derive(5, 1, 2);
  const auto va = a();
  CHECK(va != b());
  CHECK(va == c());
}

TEST_CASE("checks name the argument and the location") {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(3, 5);
  CHECK_NOTHROW(check_finite(m, "cloud"));
  m(2, 4) = std::numeric_limits<double>::infinity();
  try {
    check_finite(m, "cloud");
    FAIL("expected NonFiniteValue");
  } catch (const NonFiniteValue& e) {
    CHECK(e.argument() == "cloud");
    CHECK(e.reason() == "non-finite value inf at row 2, column 4");
    CHECK(std::string(e.what()) == e.argument() + ": " + e.reason());
    CHECK(e.row() == 2);
    CHECK(e.column() == 4);
  }
  CHECK_THROWS_AS(check_not_empty(Eigen::MatrixXd(3, 0), "model"), EmptyInput);
  CHECK_THROWS_WITH_AS(check_dimension(4, 3, "test"), "test: has dimension 4, expected 3", DimensionMismatch);
  const ParseError pe("data.csv", 12, "negative pressure");
  CHECK(std::string(pe.what()) == "data.csv:12: negative pressure");
}

TEST_CASE("rotation_fault: a rotation within the tolerance passes; a scaled, singular, reflected or non-finite matrix does not") {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  CHECK(orthogonality_deviation(R) < 1e-15);
  CHECK(rotation_fault(R, 1e-3).empty());
  CHECK(rotation_fault(Eigen::Matrix4f::Identity(), 0.0).empty());
  // Rounded to float (about 1e-7 off) it still passes 1e-6.
  CHECK(rotation_fault(R.cast<float>(), 1e-6).empty());
  // Scaled by 1 + e: the deviation is (1 + e)^2 - 1 = 2e + e^2, on either
  // side of the tolerance.
  CHECK(rotation_fault(R * 1.0004, 1e-3).empty());
  CHECK(rotation_fault(R * 1.0006, 1e-3) ==
        "is not orthogonal: the largest entry of |R^T R - I| is 0.00120036 (tolerance 0.001; det 1.0018)");
  CHECK(rotation_fault(Eigen::Matrix3d::Zero(), 1e-3) ==
        "is not orthogonal: the largest entry of |R^T R - I| is 1 (tolerance 0.001; det 0)");
  const Eigen::Matrix3d reflected = R * Eigen::Vector3d(1, -1, 1).asDiagonal();
  CHECK(orthogonality_deviation(reflected) < 1e-15);
  CHECK(rotation_fault(reflected, 1e-3) == "is orthogonal with det -1 (a reflection)");
  Eigen::Matrix3d bad = R;
  bad(1, 2) = std::numeric_limits<double>::quiet_NaN();
  CHECK(rotation_fault(bad, 1e-3) == "holds a NaN or an infinity");
  bad(1, 2) = -std::numeric_limits<double>::infinity();
  CHECK(rotation_fault(bad, 1e-3) == "holds a NaN or an infinity");
  // The scalar form: a NaN deviation is no rotation either.
  CHECK(!rotation_fault(std::numeric_limits<double>::quiet_NaN(), 1.0, 1e-3).empty());
  CHECK(rotation_fault(1e-3, 1e-300, 1e-3).empty());
  CHECK(!rotation_fault(0.0, 0.0, 1e-3).empty());
}

TEST_CASE("find_beyond_range: the first coefficient, column by column, beyond the scalar's range, weights applied") {
  const double fl = largest_coordinate<float>();
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(3, 4);
  m(1, 2) = fl;  // at the limit: in range
  CHECK(find_beyond_range<float>(m) == std::make_pair(Eigen::Index{-1}, Eigen::Index{-1}));
  m(2, 3) = 2 * fl;
  m(0, 3) = -2 * fl;
  CHECK(find_beyond_range<float>(m) == std::make_pair(Eigen::Index{0}, Eigen::Index{3}));
  CHECK(find_beyond_range<double>(m).first == -1);  // far inside double's range
  // A weight moves a coordinate out of range (row 1 of column 2) or into it.
  const double w[3] = {0.25, 2.0, 0.25};
  CHECK(find_beyond_range<float>(m, w) == std::make_pair(Eigen::Index{1}, Eigen::Index{2}));
  const double small[3] = {0.25, 0.25, 0.25};
  CHECK(find_beyond_range<float>(m, small).first == -1);
  m(0, 0) = std::numeric_limits<double>::quiet_NaN();
  CHECK(find_beyond_range<float>(m, small) == std::make_pair(Eigen::Index{0}, Eigen::Index{0}));
  // check_coordinate_range reports the same coefficient.
  CHECK_THROWS_WITH_AS(check_coordinate_range<double>(Eigen::MatrixXd::Constant(2, 2, 1e200), "cloud"),
                       "cloud: value 1e+200 at row 0, column 0 is beyond the double range of distances "
                       "(|v| <= 1.34078e+150): squared distances would overflow; rescale",
                       InvalidArgument);
}

TEST_CASE("quote_text: control bytes escaped, long text cut outside UTF-8 sequences; format_value") {
  using namespace std::string_literals;
  CHECK(quote_text("pliers_1") == "'pliers_1'");
  CHECK(quote_text("") == "''");
  // A NUL would end the message in every printf("%s"); \r would overwrite it.
  CHECK(quote_text("1\0" "2"s) == "'1\\x002'");
  CHECK(quote_text("a\rb\x1b[2J\x7f") == "'a\\x0db\\x1b[2J\\x7f'");
  CHECK(quote_text("zange_m\xc3\xbcller") == "'zange_m\xc3\xbcller'");  // UTF-8 kept
  CHECK(quote_text("abcdefgh", 4) == "'abcd...'");
  CHECK(quote_text("abcd", 4) == "'abcd'");
  // Cut before a two-byte sequence that would straddle the limit.
  CHECK(quote_text("abc\xc3\xbc", 4) == "'abc...'");
  // Bytes that form no UTF-8 character are escaped too, so the message is
  // UTF-8 whatever the input (a Latin-1 name, a cut character, a stray
  // continuation byte, an overlong form, a surrogate), and the characters
  // around them are kept.
  CHECK(quote_text("h\xe4mmer") == "'h\\xe4mmer'");
  CHECK(quote_text("pliers\xc3") == "'pliers\\xc3'");
  CHECK(quote_text("\xbc\xc3\xbc\xff") == "'\\xbc\xc3\xbc\\xff'");
  CHECK(quote_text("\xc0\xaf") == "'\\xc0\\xaf'");
  CHECK(quote_text("\xed\xa0\x80") == "'\\xed\\xa0\\x80'");
  CHECK(quote_text("\xf0\x9f\x98\x80!") == "'\xf0\x9f\x98\x80!'");
  CHECK(utf8_error(quote_text("\xe4\x80\xc3\x00\xff\xf4\x90\x80\x80"s)) == std::string_view::npos);
  const std::string_view mixed = "a\xc3\xa4\xe2\x82\xac\xf0\x9f\x98\x80\xe2\x82";
  CHECK(utf8_sequence_length(mixed, 0) == 1);
  CHECK(utf8_sequence_length(mixed, 1) == 2);
  CHECK(utf8_sequence_length(mixed, 3) == 3);
  CHECK(utf8_sequence_length(mixed, 6) == 4);
  CHECK(utf8_sequence_length(mixed, 2) == 0);   // a continuation byte
  CHECK(utf8_sequence_length(mixed, 10) == 0);  // the euro sign cut short
  // An escaped byte counts as one byte of the limit.
  CHECK(quote_text("ab\xe4\xe4", 3) == "'ab\\xe4...'");
  CHECK(format_value(1e-310) == "1e-310");
  CHECK(format_value(0.5) == "0.5");
}

namespace {
// The names in `dir` that start with `prefix`, sorted.
std::vector<std::string> names_in(const std::filesystem::path& dir, const std::string& prefix = "") {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().filename().string().rfind(prefix, 0) == 0) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}
using iclap::test::slurp;
}  // namespace

TEST_CASE("utf8_bom_length / without_utf8_bom: one leading byte-order mark, nothing else") {
  using namespace std::string_literals;
  static_assert(utf8_bom_length("\xEF\xBB\xBFx") == 3 && without_utf8_bom("\xEF\xBB\xBFx") == "x");
  CHECK(kUtf8Bom.size() == 3);
  CHECK(utf8_bom_length("") == 0);
  CHECK(utf8_bom_length("\xEF\xBB\xBF") == 3);
  CHECK(without_utf8_bom("\xEF\xBB\xBF").empty());
  // A mark cut short, a byte off, a mark not at the start: not a mark.
  CHECK(utf8_bom_length("\xEF") == 0);
  CHECK(utf8_bom_length("\xEF\xBB") == 0);
  CHECK(utf8_bom_length("\xEF\xBB\xBE") == 0);
  CHECK(utf8_bom_length("\xBB\xBF") == 0);
  CHECK(utf8_bom_length(" \xEF\xBB\xBF") == 0);
  CHECK(without_utf8_bom("a\xEF\xBB\xBF") == "a\xEF\xBB\xBF");
  // Only the first of two marks is skipped: the second is text (U+FEFF).
  CHECK(without_utf8_bom("\xEF\xBB\xBF\xEF\xBB\xBFv 1 2 3") == "\xEF\xBB\xBFv 1 2 3");
  // A NUL after the mark is text too.
  CHECK(without_utf8_bom("\xEF\xBB\xBF\0x"s) == "\0x"s);
}

TEST_CASE("AtomicFileWriter: all or nothing") {
  const std::string path = "iclap_test_atomic.txt";
  std::remove(path.c_str());
  // A file that happens to be named like the old fixed temporary survives.
  std::ofstream(path + ".partial") << "precious\n";
  {
    AtomicFileWriter w(path);
    w.stream() << "half";
    CHECK(w.temporary_path().rfind(path + ".partial-", 0) == 0);
    CHECK(std::ifstream(w.temporary_path()).good());
    // destroyed without commit: nothing appears
  }
  CHECK(!std::ifstream(path).good());
  CHECK(names_in(".", path) == std::vector<std::string>{path + ".partial"});
  {
    AtomicFileWriter w(path);
    AtomicFileWriter second(path);  // two writers, two temporaries
    CHECK(w.temporary_path() != second.temporary_path());
    w.stream() << "complete\n";
    w.commit();
  }
  CHECK(slurp(path) == "complete\n");
  {
    AtomicFileWriter w(path);
    w.stream() << "replacement that fails";
  }
  CHECK(slurp(path) == "complete\n");  // the old file is untouched
  {
    // A write that fails part-way (file size limit, as on a full disk):
    // WriteError, the old file untouched, no temporary left.
    AtomicFileWriter w(path);
    test::FileSizeLimit limit(4096);
    REQUIRE(limit.ok());
    w.stream() << std::string(1 << 16, 'x');
    CHECK_THROWS_AS(w.commit(), WriteError);
  }
  REQUIRE(slurp(path).size() < 100);  // not the 64 KiB of x (which doctest would print)
  CHECK(slurp(path) == "complete\n");
  CHECK(names_in(".", path).size() == 2);
  CHECK(slurp(path + ".partial") == "precious\n");
  {
    // Without the directory sync (a file of a staging directory), the file
    // is in place all the same and no temporary is left.
    AtomicFileWriter w(path);
    w.stream() << "staged\n";
    w.commit(AtomicFileWriter::DirectorySync::no);
  }
  CHECK(slurp(path) == "staged\n");
  CHECK(names_in(".", path).size() == 2);
  std::remove(path.c_str());
  std::remove((path + ".partial").c_str());
  CHECK_THROWS_AS(AtomicFileWriter("/nonexistent-dir/x.txt"), IoError);
}

TEST_CASE("directory_of: the parent, or . for a bare name; sync_directory skips what it cannot open") {
  CHECK(directory_of("results.csv") == std::filesystem::path("."));
  CHECK(directory_of("out/results.csv") == std::filesystem::path("out"));
  CHECK(directory_of("/results.csv") == std::filesystem::path("/"));
  CHECK(directory_of("a/b/") == std::filesystem::path("a/b"));
  CHECK(sync_directory(".") == 0);
  CHECK(sync_directory("/nonexistent-dir") == 0);
}

TEST_CASE("AtomicFileWriter: through a symbolic link, keeping permissions, with the longest file names") {
  namespace fs = std::filesystem;
  const iclap::test::TempDir scratch("atomic");
  const fs::path& dir = scratch.path;
  fs::create_directories(dir / "real");
  auto write = [](const fs::path& p, const std::string& text) {
    AtomicFileWriter w(p.string());
    w.stream() << text;
    w.commit();
  };
  // A link is followed: the file it leads to gets the content (it kept the
  // old one, and the link became a regular file).
  const fs::path target = dir / "real" / "data.csv", link = dir / "link.csv";
  write(target, "old\n");
  fs::create_symlink(fs::path("real") / "data.csv", link);
  write(link, "new\n");
  CHECK(fs::is_symlink(fs::symlink_status(link)));
  CHECK(slurp(target.string()) == "new\n");
  // Permission bits stay (a 0600 file became 0644), even read-only ones.
  fs::permissions(target, fs::perms::owner_read | fs::perms::owner_write);
  write(target, "private\n");
  CHECK((fs::status(target).permissions() & fs::perms::all) == (fs::perms::owner_read | fs::perms::owner_write));
  fs::permissions(target, fs::perms::owner_read);
  write(target, "read-only\n");
  CHECK((fs::status(target).permissions() & fs::perms::all) == fs::perms::owner_read);
  CHECK(slurp(target.string()) == "read-only\n");
  // A 250-byte name, with no room for the ".partial-PID-N" suffix.
  const fs::path long_name = dir / std::string(250, 'n');
  write(long_name, "long\n");
  CHECK(slurp(long_name.string()) == "long\n");
  // A loop of links is an error naming the path.
  fs::create_symlink("b", dir / "a");
  fs::create_symlink("a", dir / "b");
  CHECK_THROWS_WITH_AS(AtomicFileWriter((dir / "a").string()), doctest::Contains("symbolic links"), IoError);
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 5);  // real, link, long, a, b
}

namespace {
// What `f` threw: "WriteError" or "IoError" (a WriteError is an IoError too),
// the path the error names and what().
struct ThrownIo {
  std::string type = "none", path, what;
};
template <typename F>
ThrownIo io_error_of(F&& f) {
  try {
    f();
  } catch (const WriteError& e) {
    return {"WriteError", e.path(), e.what()};
  } catch (const IoError& e) {
    return {"IoError", e.path(), e.what()};
  }
  return {};
}
}  // namespace

TEST_CASE("AtomicFileWriter: a failed open, rename or sync names the path and leaves the old file and no temporary") {
  namespace fs = std::filesystem;
  const iclap::test::TempDir scratch("atomic_errors");
  const fs::path& dir = scratch.path;
  // A directory that does not exist: nothing is created.
  const std::string missing = (dir / "no_such_dir" / "out.txt").string();
  ThrownIo t = io_error_of([&] { AtomicFileWriter w(missing); });
  CHECK(t.type == "IoError");
  CHECK(t.path == missing);
  CHECK(t.what == missing + ": cannot open for writing: " + std::strerror(ENOENT));
  CHECK(names_in(dir).empty());

  const std::string target = (dir / "out.txt").string();
  std::ofstream(target, std::ios::binary) << "old\ncontent\n";
  // An open mode the stream refuses (append, with the writer's truncation):
  // the temporary file just created is removed again, and the reason is not
  // an unrelated earlier errno (it read "No such file or directory").
  t = io_error_of([&] { AtomicFileWriter w(target, std::ios::app); });
  CHECK(t.type == "IoError");
  CHECK(t.path == target);
  CHECK(t.what == target + ": cannot open for writing: the stream refused the open mode");
  CHECK(names_in(dir) == std::vector<std::string>{"out.txt"});
  CHECK(slurp(target) == "old\ncontent\n");

  // The target is a directory that is not empty: the rename fails. IoError
  // (not WriteError), the directory and its file as they were, no temporary.
  const fs::path taken = dir / "taken";
  fs::create_directories(taken);
  std::ofstream(taken / "inside.txt", std::ios::binary) << "inside\n";
  t = io_error_of([&] {
    AtomicFileWriter w(taken.string());
    w.stream() << "new\n";
    w.commit();
  });
  CHECK(t.type == "IoError");
  CHECK(t.path == taken.string());
  CHECK(t.what.rfind(taken.string() + ": cannot move into place: ", 0) == 0);
  CHECK(fs::is_directory(taken));
  CHECK(names_in(taken) == std::vector<std::string>{"inside.txt"});
  CHECK(slurp((taken / "inside.txt").string()) == "inside\n");
  CHECK(names_in(dir) == std::vector<std::string>{"out.txt", "taken"});

  // The temporary file vanishes before the commit (removed by someone else):
  // it cannot be opened to be synced, WriteError, the old content stays.
  t = io_error_of([&] {
    AtomicFileWriter w(target);
    w.stream() << "new\n";
    REQUIRE(std::remove(w.temporary_path().c_str()) == 0);
    w.commit();
  });
  CHECK(t.type == "WriteError");
  CHECK(t.path == target);
  CHECK(t.what == target + ": fsync failed: " + std::strerror(ENOENT));
  CHECK(slurp(target) == "old\ncontent\n");
  CHECK(names_in(dir) == std::vector<std::string>{"out.txt", "taken"});
}

TEST_CASE("AtomicFileWriter: when all 1000 temporary names it tries are taken, IoError and nothing replaced") {
  namespace fs = std::filesystem;
  const iclap::test::TempDir scratch("atomic_names");
  const fs::path& dir = scratch.path;
  const std::string target = (dir / "data.csv").string();
  std::ofstream(target, std::ios::binary) << "kept\n";
  // The writer tries PATH.partial-PID-N for N from a process-wide counter
  // on: a probe shows where the counter stands.
  const std::string stem = target + ".partial-" + std::to_string(::getpid()) + "-";
  std::string probe;
  {
    AtomicFileWriter w(target);
    probe = w.temporary_path();
  }
  REQUIRE(probe.rfind(stem, 0) == 0);
  const unsigned next = static_cast<unsigned>(std::stoul(probe.substr(stem.size()))) + 1;
  auto decoy_text = [](unsigned n) { return "decoy " + std::to_string(n) + "\n"; };
  for (unsigned n = next; n < next + 1000; ++n)
    std::ofstream(stem + std::to_string(n), std::ios::binary) << decoy_text(n);
  const ThrownIo t = io_error_of([&] { AtomicFileWriter w(target); });
  CHECK(t.type == "IoError");
  CHECK(t.path == target);
  CHECK(t.what == target + ": cannot create a temporary file beside it (1000 names taken)");
  // No file of another name appeared, none of the 1000 was replaced or
  // truncated, the target is as it was.
  CHECK(names_in(dir).size() == 1001);
  unsigned intact = 0;
  for (unsigned n = next; n < next + 1000; ++n)
    intact += slurp(stem + std::to_string(n)) == decoy_text(n) ? 1u : 0u;
  CHECK(intact == 1000);
  CHECK(slurp(target) == "kept\n");
  // The name after them is free: the next writer takes it.
  {
    AtomicFileWriter w(target);
    CHECK(w.temporary_path() == stem + std::to_string(next + 1000));
    w.stream() << "new\n";
    w.commit();
  }
  CHECK(slurp(target) == "new\n");
  CHECK(names_in(dir).size() == 1001);
}

TEST_CASE("parallel_for visits every item once; ProgressCounter reports them one at a time, in order") {
  for (unsigned threads : {1u, 2u, 4u}) {
    CAPTURE(threads);
    const std::size_t n = 1000;
    std::vector<int> visits(n, 0);
    std::vector<unsigned> worker_of(n, 0);
    std::vector<std::pair<std::size_t, std::size_t>> calls;  // written only under the counter's lock
    ProgressCounter counter([&](std::size_t done, std::size_t total) { calls.emplace_back(done, total); }, n);
    detail::parallel_for(n, threads, [&](std::size_t i, unsigned worker) {
      ++visits[i];
      worker_of[i] = worker;
      counter.tick();
    });
    CHECK(std::count(visits.begin(), visits.end(), 1) == static_cast<std::ptrdiff_t>(n));
    CHECK(*std::max_element(worker_of.begin(), worker_of.end()) < detail::worker_count(threads, n));
    REQUIRE(calls.size() == n);
    for (std::size_t k = 0; k < n; ++k) CHECK(calls[k] == std::make_pair(k + 1, n));
  }
  ProgressCounter silent(ProgressCallback{}, 3);
  silent.tick();  // no callback: nothing to report, no error
  CHECK(detail::worker_count(4, 2) == 2);
  CHECK(detail::worker_count(3, 0) == 1);
  CHECK_THROWS_AS(detail::parallel_for(100, 2,
                                       [](std::size_t i, unsigned) {
                                         if (i == 7) throw std::runtime_error("item 7");
                                       }),
                  std::runtime_error);
  // Several items fail: the smallest index's error, for any thread count
  // and timing (item 13 fails last here; with 2 or 4 threads, a later item
  // that failed first was reported, so the message changed with threads).
  for (unsigned threads : {1u, 2u, 4u})
    for (int run = 0; run < 3; ++run) {
      CAPTURE(threads);
      std::string message;
      try {
        detail::parallel_for(40, threads, [](std::size_t i, unsigned) {
          if (i == 13) {
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            throw std::runtime_error("item 13");
          }
          if (i > 13) throw std::runtime_error("item " + std::to_string(i));
        });
      } catch (const std::runtime_error& e) {
        message = e.what();
      }
      CHECK(message == "item 13");
    }
}

TEST_CASE("Rng::uniform(a, b) stays in [a, b), for an interval of one ulp and one wider than double's range") {
  Rng rng(3);
  const double a = 1, b = std::nextafter(1.0, 2.0);
  int at_b = 0;  // a + (b - a) u rounded to b for about half of the draws
  for (int i = 0; i < 10000; ++i) {
    const double u = rng.uniform(a, b);
    at_b += !(u >= a && u < b);
  }
  CHECK(at_b == 0);
  int outside = 0;  // b - a overflowed: inf
  for (int i = 0; i < 1000; ++i) {
    const double u = rng.uniform(-1e308, 1e308);
    outside += !(u >= -1e308 && u < 1e308);
  }
  CHECK(outside == 0);
  CHECK(rng.uniform(2.0, 2.0) == 2.0);
  // An ordinary interval draws as before: a + (b - a) u.
  Rng x(11), y(11);
  for (int i = 0; i < 100; ++i) CHECK(x.uniform(-0.3, 0.7) == -0.3 + (0.7 - -0.3) * y.uniform());
}

TEST_CASE("format_exact: the shortest text that reads back to the value in its type") {
  CHECK(format_exact(std::nextafter(1.0f, 2.0f)) == "1.0000001");
  CHECK(format_exact(-0.0) == "-0");
  CHECK(format_exact(0.1) == "0.1");
}

TEST_CASE("rename_argument_prefix: a plain InvalidArgument whose name starts with the prefix gets the new prefix") {
  CHECK(rename_argument_prefix("settings.", "settings.search.", [] { return 7; }) == 7);
  auto what = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const InvalidArgument& e) {
      return (typeid(e) == typeid(InvalidArgument) ? "plain " : "derived ") + std::string(e.what());
    }
    return "none";
  };
  CHECK(what([] {
          rename_argument_prefix("settings.", "settings.search.",
                                 [] { throw InvalidArgument("settings.leaf_max_size", "must be at least 1"); });
        }) == "plain settings.search.leaf_max_size: must be at least 1");
  // The whole name as the prefix, and an empty prefix (prepends).
  CHECK(what([] { rename_argument_prefix("k", "settings.k", [] { throw InvalidArgument("k", "is 0"); }); }) ==
        "plain settings.k: is 0");
  CHECK(what([] { rename_argument_prefix("", "options.", [] { throw InvalidArgument("k", "is 0"); }); }) ==
        "plain options.k: is 0");
  // Another name (also a shorter one, and one that only contains the
  // prefix) and another exception pass unchanged; a derived error is renamed
  // and keeps its type.
  CHECK(what([] { rename_argument_prefix("settings.", "s.", [] { throw InvalidArgument("settings", "bad"); }); }) ==
        "plain settings: bad");
  CHECK(what([] { rename_argument_prefix("settings.", "s.", [] { throw InvalidArgument("my.settings.k", "bad"); }); }) ==
        "plain my.settings.k: bad");
  CHECK(what([] { rename_argument_prefix("settings.", "s.", [] { throw EmptyInput("settings.points"); }); }) ==
        "derived s.points: is empty");
  CHECK_THROWS_AS(rename_argument_prefix("settings.", "s.", [] { throw std::out_of_range("settings.x"); }),
                  std::out_of_range);
}

TEST_CASE("rename_argument: an InvalidArgument naming `from` is renamed, of its own type; the rest passes as it is") {
  // The value of f is returned, also by reference and for void.
  int calls = 0;
  CHECK(rename_argument("x", "y", [] { return 7; }) == 7);
  int target = 1;
  int& ref = rename_argument("x", "y", [&]() -> int& { return target; });
  CHECK(&ref == &target);
  rename_argument("x", "y", [&] { ++calls; });
  CHECK(calls == 1);

  auto caught = [](auto&& f) -> std::pair<std::string, std::string> {
    try {
      f();
    } catch (const InvalidArgument& e) {
      return {typeid(e) == typeid(InvalidArgument) ? "InvalidArgument" : "derived", e.what()};
    }
    return {"none", ""};
  };
  // Renamed, same reason; a callable name is called only then.
  CHECK(caught([] { rename_argument("image", "images[3]", [] { throw InvalidArgument("image", "is odd"); }); }) ==
        std::pair<std::string, std::string>("InvalidArgument", "images[3]: is odd"));
  int named = 0;
  auto name = [&] {
    ++named;
    return std::string("images[4]");
  };
  CHECK(caught([&] { rename_argument("image", name, [] { throw InvalidArgument("image", "is odd"); }); }).second ==
        "images[4]: is odd");
  CHECK(named == 1);
  CHECK(rename_argument("image", name, [] { return 1; }) == 1);
  CHECK(named == 1);
  // Another argument passes unchanged; a derived error naming `from` is
  // renamed and keeps its type (test_core_audit3.cpp).
  CHECK(caught([] { rename_argument("image", "images[3]", [] { throw InvalidArgument("settings.k", "is 0"); }); }) ==
        std::pair<std::string, std::string>("InvalidArgument", "settings.k: is 0"));
  CHECK(caught([] { rename_argument("image", "images[3]", [] { throw EmptyInput("image"); }); }) ==
        std::pair<std::string, std::string>("derived", "images[3]: is empty"));
  CHECK(caught([] { rename_argument("image", "images[3]", [] { throw DimensionMismatch("image", 84, 83); }); }) ==
        std::pair<std::string, std::string>("derived", "images[3]: has dimension 83, expected 84"));
  // Nested renames map two names.
  auto both = [](const char* which) {
    rename_argument("settings.voxel", "voxel", [&] {
      rename_argument("settings.truncation", "free_radius", [&] { throw InvalidArgument(which, "bad"); });
    });
  };
  CHECK(caught([&] { both("settings.voxel"); }).second == "voxel: bad");
  CHECK(caught([&] { both("settings.truncation"); }).second == "free_radius: bad");
  // Other exceptions are not touched.
  CHECK_THROWS_AS(rename_argument("x", "y", [] { throw std::runtime_error("x"); }), std::runtime_error);
}

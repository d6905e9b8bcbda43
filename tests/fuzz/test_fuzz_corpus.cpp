// SPDX-License-Identifier: MIT
// Runs the fuzz targets' entry functions on their seed corpus in the normal
// test suite, so every compiler and sanitizer build exercises them (the
// libFuzzer runs themselves are tests/fuzz/run.sh). In a build with
// AddressSanitizer's allocator hooks (the suite's clang++ ASan+UBSan half)
// the file readers' entries are also held to the libFuzzer targets' heap
// bound (fuzz_heap.hpp), on every seed and every prefix replayed.

#include <doctest/doctest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_dataset_csv.hpp"
#include "fuzz_heap.hpp"
#include "fuzz_mesh.hpp"
#include "fuzz_point_file.hpp"
#include "fuzz_stream_parser.hpp"

namespace fs = std::filesystem;

namespace {
std::vector<std::pair<std::string, std::vector<std::uint8_t>>> corpus(const std::string& kind) {
  std::vector<std::pair<std::string, std::vector<std::uint8_t>>> files;
  for (const auto& entry : fs::directory_iterator(fs::path(ICLAP_FUZZ_CORPUS) / kind)) {
    std::ifstream in(entry.path(), std::ios::binary);
    files.emplace_back(entry.path().filename().string(),
                       std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()));
  }
  return files;
}

using Entry = void (*)(const std::uint8_t*, std::size_t);

/// Whether the file readers' heap bound is checked in this build.
constexpr bool kHeapBound =
#ifdef ICLAP_FUZZ_HEAP_HOOKS
    true;
#else
    false;
#endif

/// Keeps an allocation the compiler could otherwise elide (a new paired with
/// a delete may be left out) by letting its address escape.
void* volatile escaped = nullptr;
void escape(void* p) { escaped = p; }

/// `entry` on the first `size` bytes; with `bounded`, also the heap bound of
/// the libFuzzer targets of the file readers (a no-op without the hooks).
void run_entry(Entry entry, const std::uint8_t* data, std::size_t size, bool bounded) {
  if (!bounded) return entry(data, size);
  const iclap::fuzz::FuzzHeapWatch heap;
  entry(data, size);
  heap.check(size);
}

/// Runs `entry` on every seed file of `kind` (at least 8 of them) and on
/// every `stride`-th prefix of each: truncation anywhere keeps the invariants.
void check_corpus(const std::string& kind, Entry entry, std::size_t stride, bool bounded = false) {
  const auto files = corpus(kind);
  CHECK(files.size() >= 8);
  for (const auto& file : files) {
    // Not a structured binding: C++17 lets no lambda (CAPTURE's) capture one.
    const std::string& name = file.first;
    const std::vector<std::uint8_t>& bytes = file.second;
    CAPTURE(name);
    CHECK_NOTHROW(run_entry(entry, bytes.data(), bytes.size(), bounded));
    for (std::size_t n = 0; n < bytes.size(); n += stride) CHECK_NOTHROW(run_entry(entry, bytes.data(), n, bounded));
  }
}
}  // namespace

TEST_CASE("Fuzz entry: stream parser on the seed corpus") {
  check_corpus("stream_parser", iclap::fuzz::fuzz_stream_parser, 7);
}

TEST_CASE("Fuzz entry: dataset CSV reader on the seed corpus") {
  check_corpus("dataset_csv", iclap::fuzz::fuzz_dataset_csv, 5);
}

TEST_CASE("Fuzz entry: OBJ loader on the seed corpus") { check_corpus("mesh_obj", iclap::fuzz::fuzz_mesh_obj, 5, true); }

TEST_CASE("Fuzz entry: STL loader on the seed corpus") { check_corpus("mesh_stl", iclap::fuzz::fuzz_mesh_stl, 7, true); }

TEST_CASE("Fuzz entry: PLY loader on the seed corpus") { check_corpus("mesh_ply", iclap::fuzz::fuzz_mesh_ply, 5, true); }

TEST_CASE("Fuzz entry: point-file reader on the seed corpus") {
  check_corpus("point_file", iclap::fuzz::fuzz_point_file, 3, true);
}

TEST_CASE("Fuzz entry: the heap bound can fail") {
  if (!kHeapBound) {
    MESSAGE("no AddressSanitizer allocator hooks in this build: the heap bound is checked by the ASan builds");
    return;
  }
  const std::size_t size = 100;
  {
    const iclap::fuzz::FuzzHeapWatch heap;
    std::vector<char> within(iclap::fuzz::fuzz_heap_bound(size) / 2);
    escape(within.data());
    CHECK_NOTHROW(heap.check(size));
  }
  {
    const iclap::fuzz::FuzzHeapWatch heap;
    // Freed again before the check: the bound is on the peak, not on what is
    // still allocated.
    {
      std::vector<char> beyond(iclap::fuzz::fuzz_heap_bound(size) + 1);
      escape(beyond.data());
    }
    CHECK_THROWS_AS(heap.check(size), std::logic_error);
  }
  // An entry that allocates beyond the bound fails the replay.
  const Entry greedy = [](const std::uint8_t*, std::size_t n) {
    std::vector<char> v(iclap::fuzz::fuzz_heap_bound(n) + 1);
    escape(v.data());
  };
  CHECK_THROWS_AS(run_entry(greedy, nullptr, 0, true), std::logic_error);
  CHECK_NOTHROW(run_entry(greedy, nullptr, 0, false));
}

TEST_CASE("Fuzz entry: the invariant checks can fail") {
  CHECK_THROWS_AS(iclap::fuzz::fuzz_require(false, "test"), std::logic_error);
  CHECK_THROWS_AS(iclap::fuzz::fuzz_csv_require(false, "test"), std::logic_error);
  CHECK_THROWS_AS(iclap::fuzz::fuzz_mesh_require(false, "test"), std::logic_error);
  CHECK_THROWS_AS(iclap::fuzz::fuzz_points_require(false, "test"), std::logic_error);
  // An error message naming another file, a line past the end or a byte
  // offset past the end is a finding.
  using iclap::ParseError;
  using iclap::fuzz::fuzz_check_parse_error;
  CHECK_THROWS_AS(fuzz_check_parse_error(ParseError("other.obj", 1, "x"), "fuzz.obj", "a\n"), std::logic_error);
  CHECK_THROWS_AS(fuzz_check_parse_error(ParseError("fuzz.obj", 3, "x"), "fuzz.obj", "a\n"), std::logic_error);
  CHECK_THROWS_AS(fuzz_check_parse_error(ParseError("fuzz.stl", 0, "byte offset 3: x"), "fuzz.stl", "a\n"),
                  std::logic_error);
  CHECK_NOTHROW(fuzz_check_parse_error(ParseError("fuzz.stl", 2, "byte offset 2: x"), "fuzz.stl", "a\n"));
}

// SPDX-License-Identifier: MIT
// Runs the fuzz targets' entry functions on their seed corpus in the normal
// test suite, so every compiler and sanitizer build exercises them (the
// libFuzzer runs themselves are tests/fuzz/run.sh).

#include <doctest/doctest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_dataset_csv.hpp"
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

/// Runs `entry` on every seed file of `kind` (at least 8 of them) and on
/// every `stride`-th prefix of each: truncation anywhere keeps the invariants.
void check_corpus(const std::string& kind, void (*entry)(const std::uint8_t*, std::size_t), std::size_t stride) {
  const auto files = corpus(kind);
  CHECK(files.size() >= 8);
  for (const auto& file : files) {
    // Not a structured binding: C++17 lets no lambda (CAPTURE's) capture one.
    const std::string& name = file.first;
    const std::vector<std::uint8_t>& bytes = file.second;
    CAPTURE(name);
    CHECK_NOTHROW(entry(bytes.data(), bytes.size()));
    for (std::size_t n = 0; n < bytes.size(); n += stride) CHECK_NOTHROW(entry(bytes.data(), n));
  }
}
}  // namespace

TEST_CASE("Fuzz entry: stream parser on the seed corpus") {
  check_corpus("stream_parser", iclap::fuzz::fuzz_stream_parser, 7);
}

TEST_CASE("Fuzz entry: dataset CSV reader on the seed corpus") {
  check_corpus("dataset_csv", iclap::fuzz::fuzz_dataset_csv, 5);
}

TEST_CASE("Fuzz entry: OBJ loader on the seed corpus") { check_corpus("mesh_obj", iclap::fuzz::fuzz_mesh_obj, 5); }

TEST_CASE("Fuzz entry: STL loader on the seed corpus") { check_corpus("mesh_stl", iclap::fuzz::fuzz_mesh_stl, 7); }

TEST_CASE("Fuzz entry: PLY loader on the seed corpus") { check_corpus("mesh_ply", iclap::fuzz::fuzz_mesh_ply, 5); }

TEST_CASE("Fuzz entry: point-file reader on the seed corpus") {
  check_corpus("point_file", iclap::fuzz::fuzz_point_file, 3);
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

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

TEST_CASE("Fuzz entry: the invariant checks can fail") {
  CHECK_THROWS_AS(iclap::fuzz::fuzz_require(false, "test"), std::logic_error);
  CHECK_THROWS_AS(iclap::fuzz::fuzz_csv_require(false, "test"), std::logic_error);
}

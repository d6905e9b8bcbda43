// SPDX-License-Identifier: MIT
// Runs the fuzz targets' entry functions on their seed corpus in the normal
// test suite, so every compiler and sanitizer build exercises them (the
// libFuzzer runs themselves are tests/fuzz/run.sh).

#include <doctest/doctest.h>

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
}  // namespace

TEST_CASE("Fuzz entry: stream parser on the seed corpus") {
  const auto files = corpus("stream_parser");
  CHECK(files.size() >= 8);
  for (const auto& file : files) {
    // Named members, not a structured binding: CAPTURE's lambda may not
    // capture a binding in C++17 (clang++ rejects it).
    const std::string& name = file.first;
    const auto& bytes = file.second;
    CAPTURE(name);
    CHECK_NOTHROW(iclap::fuzz::fuzz_stream_parser(bytes.data(), bytes.size()));
    // Every prefix too: truncation anywhere keeps the invariants.
    for (std::size_t n = 0; n < bytes.size(); n += 7) CHECK_NOTHROW(iclap::fuzz::fuzz_stream_parser(bytes.data(), n));
  }
}

TEST_CASE("Fuzz entry: dataset CSV reader on the seed corpus") {
  const auto files = corpus("dataset_csv");
  CHECK(files.size() >= 8);
  for (const auto& file : files) {
    // Named members, not a structured binding: CAPTURE's lambda may not
    // capture a binding in C++17 (clang++ rejects it).
    const std::string& name = file.first;
    const auto& bytes = file.second;
    CAPTURE(name);
    CHECK_NOTHROW(iclap::fuzz::fuzz_dataset_csv(bytes.data(), bytes.size()));
    for (std::size_t n = 0; n < bytes.size(); n += 5) CHECK_NOTHROW(iclap::fuzz::fuzz_dataset_csv(bytes.data(), n));
  }
}

TEST_CASE("Fuzz entry: the invariant checks can fail") {
  CHECK_THROWS_AS(iclap::fuzz::fuzz_require(false, "test"), std::logic_error);
  CHECK_THROWS_AS(iclap::fuzz::fuzz_csv_require(false, "test"), std::logic_error);
}

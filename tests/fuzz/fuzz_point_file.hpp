// SPDX-License-Identifier: MIT
#pragma once
// Fuzz entry for the point-file reader of `iclap register`
// (read_point_file), shared by the libFuzzer target (fuzz_point_file.cpp)
// and the doctest suite (test_fuzz_corpus.cpp).
//
// Any input either parses or throws iclap::ParseError whose message starts
// with the file name and whose line exists; any other exception escapes and
// is a finding. A parsed file gives at least one point of at least one
// finite value, one line number per point (increasing), and each point is
// what its line holds: as many values as the dimension, each the number
// strtod reads from the line's field.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/io/point_file.hpp"

namespace iclap::fuzz {

inline void fuzz_points_require(bool ok, const char* what) {
  if (!ok) throw std::logic_error(std::string("point file invariant violated: ") + what);
}

inline void fuzz_point_file(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string name = "fuzz.txt";
  // The input's lines as std::getline splits them (after the read: the
  // libFuzzer target bounds the heap the read takes, fuzz_heap.hpp).
  std::vector<std::string_view> input_lines;
  const auto split_lines = [&] {
    for (std::size_t at = 0; at < text.size();) {
      const std::size_t end = text.find('\n', at);
      input_lines.push_back(std::string_view(text).substr(at, (end == std::string::npos ? text.size() : end) - at));
      at = end == std::string::npos ? text.size() : end + 1;
    }
  };
  Eigen::MatrixXd p;
  std::vector<std::size_t> lines;
  try {
    std::istringstream in(text);
    p = read_point_file(in, name, &lines);
  } catch (const ParseError& e) {
    split_lines();
    fuzz_points_require(std::string(e.what()).rfind(name + ":", 0) == 0, "error message names the file");
    fuzz_points_require(e.file() == name && !e.reason().empty(), "error file and reason");
    fuzz_points_require(e.line() <= input_lines.size(), "error line beyond the input");
    return;
  }
  split_lines();
  fuzz_points_require(p.rows() >= 1 && p.cols() >= 1, "at least one point of at least one value");
  fuzz_points_require(p.allFinite(), "values finite");
  fuzz_points_require(lines.size() == static_cast<std::size_t>(p.cols()), "one line number per point");
  for (std::size_t j = 0; j < lines.size(); ++j) {
    fuzz_points_require(lines[j] >= 1 && lines[j] <= input_lines.size(), "point line in the input");
    fuzz_points_require(j == 0 || lines[j] > lines[j - 1], "point lines increase");
    // Re-read the point's line: fields split at commas and blanks.
    std::string line(input_lines[lines[j] - 1]);
    if (lines[j] == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::vector<std::string> fields;
    std::string cur;
    for (char ch : line + " ") {
      if (ch == ',' || std::isspace(static_cast<unsigned char>(ch))) {
        if (!cur.empty()) fields.push_back(cur);
        cur.clear();
      } else {
        cur += ch;
      }
    }
    fuzz_points_require(fields.size() == static_cast<std::size_t>(p.rows()), "every point has the dimension's values");
    for (std::size_t i = 0; i < fields.size(); ++i) {
      char* end = nullptr;
      const double v = std::strtod(fields[i].c_str(), &end);
      fuzz_points_require(end == fields[i].c_str() + fields[i].size(), "a value is a whole field");
      fuzz_points_require(v == p(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)),
                          "a value is its field's number");
    }
  }
}

}  // namespace iclap::fuzz

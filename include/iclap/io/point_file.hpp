// SPDX-License-Identifier: MIT
#pragma once

#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <istream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/error.hpp"
#include "iclap/core/utf8.hpp"

namespace iclap {

/// Reads a plain point file: one point per line, numbers separated by
/// whitespace and/or commas; an optional header line (the first line that
/// is not empty nor a comment, when none of its fields is a number: a first
/// line mixing numbers and words, e.g. the typo "0 0 O", is a ParseError, not
/// a header); empty lines and lines starting with '#' are skipped;
/// CRLF line endings and a UTF-8 byte-order mark are accepted. The dimension
/// is the number of columns, the same on every line.
///
/// Returns the points one per column (dim x n, double). Throws ParseError
/// ("FILE:LINE: reason") for a malformed number, NaN or infinity, a wrong
/// column count or a file without points; nothing partial is returned.
/// With `lines`, it receives the 1-based line number of each point (for
/// messages about a point found later, e.g. a value out of range).
/// Throws IoError naming `name` when `in` is already failed on entry (an
/// std::ifstream that could not open its file: it read as a file without
/// points) or a read fails; an open stream without points is a ParseError.
inline Eigen::MatrixXd read_point_file(std::istream& in, const std::string& name,
                                       std::vector<std::size_t>* lines = nullptr) {
  if (!in) throw IoError(name, "cannot open (the stream failed before the first read)");
  std::vector<double> values;
  std::vector<std::size_t> point_lines;
  std::size_t dim = 0, count = 0, line_no = 0;
  bool seen_content = false;
  std::string line;
  std::vector<std::string> tokens;
  while (std::getline(in, line)) {
    ++line_no;
    if (line_no == 1) line.erase(0, utf8_bom_length(line));
    if (!line.empty() && line.back() == '\r') line.pop_back();
    // A carriage return left inside the line is a line break of another
    // system (old Mac files): read as a space, it made the whole file one
    // point of many coordinates.
    if (line.find('\r') != std::string::npos)
      throw ParseError(name, line_no, "carriage return inside the line (line breaks must be \\n or \\r\\n)");
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    tokens.clear();
    std::string cur;
    bool after_comma = false;  // a comma seen since the last value
    for (char ch : line) {
      const bool comma = ch == ',';
      if (comma || std::isspace(static_cast<unsigned char>(ch))) {
        if (!cur.empty()) {
          tokens.push_back(cur);
          cur.clear();
          after_comma = false;
        }
        if (comma) {
          if (after_comma || tokens.empty()) throw ParseError(name, line_no, "empty value before a comma");
          after_comma = true;
        }
      } else {
        cur += ch;
      }
    }
    if (!cur.empty()) {
      tokens.push_back(cur);
      after_comma = false;
    }
    if (after_comma) throw ParseError(name, line_no, "empty value after the last comma");
    if (tokens.empty()) continue;

    const bool first_content = !seen_content;
    seen_content = true;
    std::vector<double> row;
    row.reserve(tokens.size());
    std::string bad_token;
    std::size_t bad_column = 0;
    for (std::size_t k = 0; k < tokens.size(); ++k) {
      const std::string& tok = tokens[k];
      const char* begin = tok.c_str();
      const char* end = begin + tok.size();
      if (*begin == '+' && begin + 1 != end && begin[1] != '-') ++begin;
      double v = 0;
      const auto res = std::from_chars(begin, end, v);
      // A number too large or too small for a double is no header word.
      if (res.ec == std::errc::result_out_of_range && res.ptr == end)
        throw ParseError(name, line_no, quote_text(tok, 40) + " in column " + std::to_string(k + 1) + " is out of the range of a double");
      if (res.ec != std::errc() || res.ptr != end) {
        if (bad_token.empty()) {
          bad_token = tok;
          bad_column = k + 1;
        }
        continue;  // look at every field: a header has no number at all
      }
      row.push_back(v);
    }
    if (!bad_token.empty()) {
      // The optional header: the first line with content, none of whose
      // fields is a number. A first line that mixes numbers and words (a typo
      // such as "0 0 O") is a malformed point, not a header to drop.
      if (first_content && row.empty()) continue;
      throw ParseError(name, line_no,
                       quote_text(bad_token, 40) + " in column " + std::to_string(bad_column) + " is not a number" +
                           (first_content ? " (a first line with a number in it is a point, not a header)" : ""));
    }
    for (std::size_t k = 0; k < row.size(); ++k)
      if (!std::isfinite(row[k]))
        throw ParseError(name, line_no, "non-finite value " + quote_text(tokens[k], 40) + " in column " + std::to_string(k + 1));
    if (dim == 0) {
      dim = row.size();
    } else if (row.size() != dim) {
      throw ParseError(name, line_no,
                       std::to_string(row.size()) + " values, expected " + std::to_string(dim) +
                           " (the dimension set by the first point)");
    }
    values.insert(values.end(), row.begin(), row.end());
    point_lines.push_back(line_no);
    ++count;
  }
  if (in.bad()) throw IoError(name, "read error");
  if (count == 0) throw ParseError(name, line_no, "no points in the file");
  Eigen::MatrixXd points(static_cast<Eigen::Index>(dim), static_cast<Eigen::Index>(count));
  for (std::size_t j = 0; j < count; ++j)
    for (std::size_t i = 0; i < dim; ++i)
      points(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = values[j * dim + i];
  if (lines) *lines = std::move(point_lines);
  return points;
}

/// Same, from a file path (errors name the path; a directory is named as
/// such, as read_dataset_csv does: the stream would say only "read error").
inline Eigen::MatrixXd read_point_file(const std::string& path, std::vector<std::size_t>* lines = nullptr) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw IoError(path, "is a directory, not a point file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path, std::string("cannot open: ") + std::strerror(errno));
  return read_point_file(in, path, lines);
}

}  // namespace iclap

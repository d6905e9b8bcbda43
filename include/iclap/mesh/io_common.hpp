// SPDX-License-Identifier: MIT
#pragma once

// Plumbing shared by the mesh loaders: whole-file reads, a line cursor that
// counts lines and strips CR, whitespace tokens and exact number parsing.

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <istream>
#include <iterator>
#include <string>
#include <string_view>
#include <system_error>

#include "iclap/core/error.hpp"

namespace iclap::detail {

/// The whole content of `in` (binary); IoError naming `name` on a read error.
inline std::string read_all(std::istream& in, const std::string& name) {
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError(name, "read failed");
  return data;
}

/// The whole content of the file `path`; IoError if it cannot be opened.
inline std::string read_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw IoError(path, "is a directory, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path, std::string("cannot open for reading: ") + std::strerror(errno));
  return read_all(in, path);
}

/// Iterates over the lines of a text buffer: '\n' ends a line, a trailing
/// '\r' is dropped, `line_number()` is 1-based.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text, std::size_t pos = 0) : text_(text), pos_(pos) {}
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string_view::npos) end = text_.size();
    line = text_.substr(pos_, end - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = end + 1;
    ++line_;
    return true;
  }
  std::size_t line_number() const noexcept { return line_; }
  /// Byte offset just past the last line returned.
  std::size_t position() const noexcept { return pos_ < text_.size() ? pos_ : text_.size(); }

 private:
  std::string_view text_;
  std::size_t pos_;
  std::size_t line_ = 0;
};

inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/// Splits off the next blank-separated token of `s` (empty at the end).
inline std::string_view next_token(std::string_view& s) {
  std::size_t i = 0;
  while (i < s.size() && is_space(s[i])) ++i;
  std::size_t j = i;
  while (j < s.size() && !is_space(s[j])) ++j;
  const std::string_view tok = s.substr(i, j - i);
  s.remove_prefix(j);
  return tok;
}

/// `t` without one leading '+'; false for a sign after it ("++1", "+-1",
/// which from_chars would read as -1) or nothing left.
inline bool strip_plus(std::string_view& t) {
  if (!t.empty() && t.front() == '+') {
    t.remove_prefix(1);
    if (!t.empty() && (t.front() == '+' || t.front() == '-')) return false;
  }
  return !t.empty();
}

/// A whole token as a finite double (a leading '+' allowed).
inline bool token_to_double(std::string_view t, double& v) {
  if (!strip_plus(t)) return false;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size() && std::isfinite(v);
}

/// A whole token as an integer (a leading '+' allowed).
inline bool token_to_int64(std::string_view t, std::int64_t& v) {
  if (!strip_plus(t)) return false;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

/// A token for a message: quote_text(t, 40).
inline std::string show_token(std::string_view t) { return quote_text(t, 40); }

/// Throws ParseError at line `line` of `name` when `rest` (what is left of
/// a line after its tokens were read) holds another token: "unexpected
/// 'junk' after `after`". A line with more than its syntax allows is
/// malformed, not silently cut.
inline void expect_line_end(std::string_view rest, const std::string& name, std::size_t line, const std::string& after) {
  const std::string_view extra = next_token(rest);
  if (!extra.empty()) throw ParseError(name, line, "unexpected " + show_token(extra) + " after " + after);
}

inline bool starts_with(std::string_view s, std::string_view prefix) {
  return s.size() >= prefix.size() && s.compare(0, prefix.size(), prefix) == 0;
}

}  // namespace iclap::detail

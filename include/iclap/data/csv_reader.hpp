// SPDX-License-Identifier: MIT
#pragma once

// Reader of the haptic dataset CSV (README, "Dataset format").

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/core/utf8.hpp"
#include "iclap/data/csv_common.hpp"
#include "iclap/data/dataset.hpp"

namespace iclap {

/// Receives the warnings of a successful read, in file order.
using DatasetWarningHandler = std::function<void(const DatasetWarning&)>;

namespace detail {

inline std::string_view trim_ascii(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

/// Splits on every comma (no quoting: the format has none), trimming blanks.
inline void split_fields(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      out.push_back(trim_ascii(line.substr(start)));
      return;
    }
    out.push_back(trim_ascii(line.substr(start, comma - start)));
    start = comma + 1;
  }
}

/// Parses a whole field as a double; false if it is not a number.
inline bool parse_double(std::string_view s, double& v) {
  if (!s.empty() && s.front() == '+') {
    s.remove_prefix(1);
    if (!s.empty() && s.front() == '-') return false;
  }
  const auto res = std::from_chars(s.data(), s.data() + s.size(), v);
  return !s.empty() && res.ec == std::errc() && res.ptr == s.data() + s.size();
}

inline bool parse_int64(std::string_view s, std::int64_t& v) {
  if (!s.empty() && s.front() == '+') {
    s.remove_prefix(1);
    if (!s.empty() && s.front() == '-') return false;
  }
  const auto res = std::from_chars(s.data(), s.data() + s.size(), v);
  return !s.empty() && res.ec == std::errc() && res.ptr == s.data() + s.size();
}

/// `p<r>_<c>` with canonical decimal r and c (no sign, no leading zeros).
inline bool parse_taxel_name(std::string_view name, Index& r, Index& c) {
  if (name.size() < 4 || name[0] != 'p') return false;
  const std::size_t us = name.find('_');
  if (us == std::string_view::npos) return false;
  auto canonical = [](std::string_view d, Index& out) {
    if (d.empty() || d.size() > 9) return false;
    if (d.size() > 1 && d[0] == '0') return false;
    Index v = 0;
    for (char ch : d) {
      if (ch < '0' || ch > '9') return false;
      v = v * 10 + (ch - '0');
    }
    out = v;
    return true;
  };
  return canonical(name.substr(1, us - 1), r) && canonical(name.substr(us + 1), c);
}

/// A column name or field for a message (control bytes escaped, cut at 60 bytes).
inline std::string quote_name(std::string_view s) { return quote_text(s, 60); }

/// The whole reader: `text` is the file content, `name` its display name.
inline Dataset parse_dataset_csv(std::string_view text, const std::string& name,
                                 std::vector<DatasetWarning>& warnings) {
  text = without_utf8_bom(text);

  Dataset ds;
  std::size_t pos = 0;
  std::size_t line_no = 0;
  auto next_line = [&](std::string_view& line) {
    if (pos >= text.size()) return false;
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    line = text.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = end + 1;
    ++line_no;
    // Lines end with \n or \r\n; another carriage return (a file with \r
    // line breaks, or \r\r\n) would otherwise end up inside a field.
    if (line.find('\r') != std::string_view::npos)
      throw ParseError(name, line_no, "carriage return inside the line (line breaks must be \\n or \\r\\n)");
    return true;
  };

  // Comments, then the header.
  std::string_view line;
  bool have_header = false;
  while (next_line(line)) {
    if (trim_ascii(line).empty()) continue;
    if (line.front() == '#') {
      line.remove_prefix(1);
      if (!line.empty() && line.front() == ' ') line.remove_prefix(1);
      ds.comments.emplace_back(line);
      continue;
    }
    have_header = true;
    break;
  }
  if (!have_header) throw ParseError(name, line_no, "no header row (the file has no columns)");
  const std::size_t header_line = line_no;

  std::vector<std::string_view> fields;
  split_fields(line, fields);
  const std::size_t ncols = fields.size();

  // Column roles.
  constexpr std::size_t kAbsent = static_cast<std::size_t>(-1);
  std::map<std::string, std::size_t> named;  // required and optional columns -> index
  std::vector<std::pair<std::pair<Index, Index>, std::size_t>> taxels;
  std::map<std::pair<Index, Index>, std::size_t> taxel_index;
  static const char* const kKnown[] = {"object", "exploration", "frame", "x",  "y", "z",
                                       "t",      "qw",          "qx",    "qy", "qz"};
  for (std::size_t i = 0; i < ncols; ++i) {
    const std::string col(fields[i]);
    Index r = 0, c = 0;
    const bool known = std::any_of(std::begin(kKnown), std::end(kKnown),
                                   [&](const char* k) { return col == k; });
    if (known) {
      if (!named.emplace(col, i).second)
        throw ParseError(name, header_line, "duplicate column " + quote_name(col));
    } else if (parse_taxel_name(col, r, c)) {
      if (!taxel_index.emplace(std::make_pair(r, c), i).second)
        throw ParseError(name, header_line, "duplicate column " + quote_name(col));
      taxels.push_back({{r, c}, i});
    } else if (col.empty()) {
      warnings.push_back({name, header_line,
                          "ignoring unnamed column " + std::to_string(i + 1)});
    } else {
      warnings.push_back({name, header_line, "ignoring unknown column " + quote_name(col)});
    }
  }
  for (const char* req : {"object", "exploration", "frame", "x", "y", "z"})
    if (!named.count(req))
      throw ParseError(name, header_line, std::string("missing required column '") + req + "'");
  if (taxels.empty())
    throw ParseError(name, header_line, "missing required taxel columns p<row>_<col> (none found)");
  Index rows = 0, cols = 0;
  for (const auto& t : taxels) {
    rows = std::max(rows, t.first.first + 1);
    cols = std::max(cols, t.first.second + 1);
  }
  for (Index r = 0; r < rows; ++r)
    for (Index c = 0; c < cols; ++c)
      if (!taxel_index.count({r, c}))
        throw ParseError(name, header_line,
                         "taxel grid " + std::to_string(rows) + "x" + std::to_string(cols) +
                             " has a hole: missing column " +
                             quote_name(DatasetColumns::taxel_name(r, c)));
  int quaternion_parts = 0;
  std::string present, missing;
  for (const char* q : {"qw", "qx", "qy", "qz"}) {
    std::string& list = named.count(q) ? present : missing;
    list += (list.empty() ? "" : ", ") + std::string(q);
    quaternion_parts += named.count(q) ? 1 : 0;
  }
  if (quaternion_parts != 0 && quaternion_parts != 4)
    throw ParseError(name, header_line,
                     "quaternion has only some of its components: " + present + " present, " +
                         missing + " missing (give all four of qw,qx,qy,qz or none)");
  ds.rows = rows;
  ds.cols = cols;
  const std::size_t i_object = named["object"], i_expl = named["exploration"],
                    i_frame = named["frame"], i_x = named["x"], i_y = named["y"], i_z = named["z"];
  const std::size_t i_t = named.count("t") ? named["t"] : kAbsent;
  const bool has_q = quaternion_parts == 4;
  const std::size_t i_qw = has_q ? named["qw"] : kAbsent, i_qx = has_q ? named["qx"] : kAbsent,
                    i_qy = has_q ? named["qy"] : kAbsent, i_qz = has_q ? named["qz"] : kAbsent;
  // Column index -> flat taxel offset (row-major), for the row loop.
  std::vector<std::pair<std::size_t, Index>> taxel_cols;
  taxel_cols.reserve(taxels.size());
  for (const auto& t : taxels) taxel_cols.push_back({t.second, t.first.first * cols + t.first.second});

  // Keep the header names (the header line's view stays valid in `text`).
  std::vector<std::string> header(ncols);
  for (std::size_t i = 0; i < ncols; ++i) header[i] = std::string(fields[i]);

  auto finite = [&](std::size_t i) {
    double v = 0;
    if (!parse_double(fields[i], v) || !std::isfinite(v))
      throw ParseError(name, line_no,
                       "column " + quote_name(header[i]) + ": " + quote_name(fields[i]) +
                           " is not a finite number");
    return v;
  };
  auto integer = [&](std::size_t i) {
    std::int64_t v = 0;
    if (!parse_int64(fields[i], v))
      throw ParseError(name, line_no,
                       "column " + quote_name(header[i]) + ": " + quote_name(fields[i]) +
                           " is not an integer");
    return v;
  };

  // One row per frame: the line of each (object, exploration, frame) seen.
  FrameIndex frame_lines;
  while (next_line(line)) {
    if (trim_ascii(line).empty()) continue;
    if (line.front() == '#')
      throw ParseError(name, line_no, "comment line after the header (comments go before it)");
    split_fields(line, fields);
    if (fields.size() != ncols)
      throw ParseError(name, line_no,
                       "expected " + std::to_string(ncols) + " fields (as in the header), got " +
                           std::to_string(fields.size()));
    Frame f;
    const std::string_view obj = fields[i_object];
    const std::string problem = object_name_problem(obj);
    if (!problem.empty())
      throw ParseError(name, line_no, "column 'object': name " + quote_name(obj) + " " + problem);
    f.object = std::string(obj);
    f.exploration = integer(i_expl);
    f.frame = integer(i_frame);
    f.position = Eigen::Vector3d(finite(i_x), finite(i_y), finite(i_z));
    if (i_t != kAbsent) f.time = finite(i_t);
    if (has_q) {
      const double w = finite(i_qw), x = finite(i_qx), y = finite(i_qy), z = finite(i_qz);
      f.orientation = Eigen::Quaterniond(w, x, y, z);
      const std::string q = quaternion_problem(*f.orientation);
      if (!q.empty()) throw ParseError(name, line_no, "columns qw,qx,qy,qz: the quaternion " + q);
    }
    f.pressures.resize(rows, cols);
    for (const auto& tc : taxel_cols) {
      const double p = finite(tc.first);
      if (p < 0)
        throw ParseError(name, line_no,
                         "column " + quote_name(header[tc.first]) + ": negative pressure " +
                             std::string(fields[tc.first]));
      f.pressures(tc.second / cols, tc.second % cols) = p;
    }
    // Two rows of one frame, checked once the row is otherwise valid (a
    // file concatenated twice, or a recorder restarted).
    if (const auto first = frame_lines.insert(f.object, f.exploration, f.frame, line_no))
      throw ParseError(name, line_no,
                       frame_text(f.object, f.exploration, f.frame) + " is already on line " +
                           std::to_string(*first) + " (one row per frame)");
    ds.frames.push_back(std::move(f));
  }
  return ds;
}

}  // namespace detail

/// Reads a dataset from `in`; `name` is used in errors and warnings (e.g. the
/// file name or "<stdin>"). Throws ParseError("name", line, reason) on any
/// malformed input and returns nothing partial; `on_warning` (optional) is
/// called with each warning, in file order, only if the read succeeds.
/// CRLF line endings and a UTF-8 byte-order mark are accepted. Throws
/// IoError naming `name` when `in` is already failed on entry (an
/// std::ifstream that could not open its file: it read as an empty text, a
/// ParseError "no header row") or a read fails; an open, empty stream is a
/// ParseError. O(file size).
inline Dataset read_dataset_csv(std::istream& in, const std::string& name,
                                const DatasetWarningHandler& on_warning = {}) {
  if (!in) throw IoError(name, "cannot open for reading (the stream failed before the first read)");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError(name, "read failed");
  std::vector<DatasetWarning> warnings;
  Dataset ds = detail::parse_dataset_csv(text, name, warnings);
  if (on_warning)
    for (const auto& w : warnings) on_warning(w);
  return ds;
}

/// Reads the dataset file at `path` (see the stream overload). Throws IoError
/// if the file cannot be opened.
inline Dataset read_dataset_csv(const std::string& path, const DatasetWarningHandler& on_warning = {}) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw IoError(path, "is a directory, not a dataset file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path, std::string("cannot open for reading: ") + std::strerror(errno));
  return read_dataset_csv(in, path, on_warning);
}

}  // namespace iclap

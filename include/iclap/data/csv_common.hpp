// SPDX-License-Identifier: MIT
#pragma once

// Shared pieces of the dataset CSV reader, writer and appender: column names,
// exact number formatting, the validation of a frame before it is written and
// the index that keeps one row per frame.
// The format itself is described in the README, "Dataset format".

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <tuple>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"
#include "iclap/core/utf8.hpp"
#include "iclap/data/dataset.hpp"

namespace iclap {

/// A non-fatal remark of a reader, e.g. an ignored unknown column. The
/// library never prints: readers hand warnings to the caller, who decides.
struct DatasetWarning {
  std::string file;       ///< display name of the input
  std::size_t line = 0;   ///< 1-based line, 0 for the whole file
  std::string message;    ///< e.g. "ignoring unknown column 'note'"

  /// "FILE:LINE: warning: message", the form compilers use.
  std::string to_string() const {
    return file + ":" + std::to_string(line) + ": warning: " + message;
  }
};

/// The columns a dataset file has, in the order the writer puts them:
/// object, exploration, frame, [t], x, y, z, [qw, qx, qy, qz], then the
/// taxels row-major p0_0, p0_1, ..., p<rows-1>_<cols-1>.
struct DatasetColumns {
  Index rows = 0;
  Index cols = 0;
  bool time = false;         ///< column `t`
  bool orientation = false;  ///< columns qw, qx, qy, qz

  /// Column names in writer order.
  std::vector<std::string> names() const {
    std::vector<std::string> n = {"object", "exploration", "frame"};
    if (time) n.push_back("t");
    for (const char* c : {"x", "y", "z"}) n.emplace_back(c);
    if (orientation)
      for (const char* c : {"qw", "qx", "qy", "qz"}) n.emplace_back(c);
    for (Index r = 0; r < rows; ++r)
      for (Index c = 0; c < cols; ++c) n.push_back(taxel_name(r, c));
    return n;
  }

  /// `p<r>_<c>`.
  static std::string taxel_name(Index r, Index c) {
    return "p" + std::to_string(r) + "_" + std::to_string(c);
  }
};

namespace detail {

/// Appends the shortest decimal text that reads back to exactly `v`
/// (std::to_chars), so write-then-read is the identity.
inline void append_number(std::string& out, double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, res.ptr);
}

inline void append_number(std::string& out, std::int64_t v) {
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, res.ptr);
}

/// Why `name` cannot be an object name in the CSV, or empty if it can.
inline std::string object_name_problem(std::string_view name) {
  if (name.empty()) return "is empty";
  for (char ch : name) {
    if (ch == ',') return "contains a comma";
    if (ch == '"') return "contains a quote";
    if (ch == '\n' || ch == '\r') return "contains a line break";
    // Other control bytes (a NUL, an escape sequence) are corruption, not a
    // label: printed in results and messages they cut or garble them.
    if (ch != '\t' && is_control_byte(static_cast<unsigned char>(ch))) return "contains a control character";
  }
  if (name.front() == ' ' || name.front() == '\t' || name.back() == ' ' || name.back() == '\t')
    return "has leading or trailing white space";
  if (name.front() == '#') return "starts with '#'";
  // The format is UTF-8 text; other bytes would go on into results files,
  // SVG figures and file names (a Latin-1 "h\xe4mmer", a cut character).
  const std::size_t bad = utf8_error(name);
  if (bad != std::string_view::npos) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(static_cast<unsigned char>(name[bad])));
    return "is not UTF-8: byte " + std::string(hex) + " at offset " + std::to_string(bad) +
           " starts no well-formed character";
  }
  return {};
}

/// Checks that `f` can be written as a row of a file with `columns`; throws
/// InvalidArgument naming `where` (e.g. "dataset.frames[12]") otherwise.
inline void validate_frame(const Frame& f, const DatasetColumns& columns, const std::string& where) {
  const std::string problem = object_name_problem(f.object);
  if (!problem.empty()) throw InvalidArgument(where + ".object", quote_text(f.object, 60) + " " + problem);
  if (f.pressures.rows() != columns.rows || f.pressures.cols() != columns.cols)
    throw InvalidArgument(where + ".pressures",
                          "is " + std::to_string(f.pressures.rows()) + "x" +
                              std::to_string(f.pressures.cols()) + ", the file's taxel grid is " +
                              std::to_string(columns.rows) + "x" + std::to_string(columns.cols));
  for (Index r = 0; r < f.pressures.rows(); ++r)
    for (Index c = 0; c < f.pressures.cols(); ++c) {
      const double p = f.pressures(r, c);
      if (!std::isfinite(p) || p < 0)
        throw InvalidArgument(where + ".pressures",
                              "taxel " + DatasetColumns::taxel_name(r, c) + " is " +
                                  format_exact(p) + ", pressures must be finite and >= 0");
    }
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(f.position[i]))
      throw InvalidArgument(where + ".position", "is not finite");
  if (f.time.has_value() != columns.time)
    throw InvalidArgument(where + ".time", columns.time ? "is missing, the file has a t column"
                                                        : "is set, the file has no t column");
  if (f.time && !std::isfinite(*f.time)) throw InvalidArgument(where + ".time", "is not finite");
  if (f.orientation.has_value() != columns.orientation)
    throw InvalidArgument(where + ".orientation",
                          columns.orientation ? "is missing, the file has qw,qx,qy,qz columns"
                                              : "is set, the file has no quaternion columns");
  if (f.orientation && !f.orientation->coeffs().allFinite())
    throw InvalidArgument(where + ".orientation", "is not finite");
  if (f.orientation) {
    const std::string q = quaternion_problem(*f.orientation);
    if (!q.empty()) throw InvalidArgument(where + ".orientation", q);
  }
}

/// Appends one CSV row (with its '\n') for `f` in the column order given by
/// `order`, a permutation of column ids (see `column_id`).
enum class ColumnId : int { object, exploration, frame, t, x, y, z, qw, qx, qy, qz, taxel };

struct ColumnSlot {
  ColumnId id = ColumnId::object;
  Index row = 0;  ///< taxel row (id == taxel)
  Index col = 0;  ///< taxel column (id == taxel)
};

/// The slots of `columns` in writer order.
inline std::vector<ColumnSlot> writer_slots(const DatasetColumns& columns) {
  std::vector<ColumnSlot> s = {{ColumnId::object}, {ColumnId::exploration}, {ColumnId::frame}};
  if (columns.time) s.push_back({ColumnId::t});
  s.push_back({ColumnId::x});
  s.push_back({ColumnId::y});
  s.push_back({ColumnId::z});
  if (columns.orientation)
    for (ColumnId id : {ColumnId::qw, ColumnId::qx, ColumnId::qy, ColumnId::qz}) s.push_back({id});
  for (Index r = 0; r < columns.rows; ++r)
    for (Index c = 0; c < columns.cols; ++c) s.push_back({ColumnId::taxel, r, c});
  return s;
}

inline void append_row(std::string& out, const Frame& f, const std::vector<ColumnSlot>& slots) {
  bool first = true;
  for (const ColumnSlot& s : slots) {
    if (!first) out += ',';
    first = false;
    switch (s.id) {
      case ColumnId::object: out += f.object; break;
      case ColumnId::exploration: append_number(out, f.exploration); break;
      case ColumnId::frame: append_number(out, f.frame); break;
      case ColumnId::t: append_number(out, *f.time); break;
      case ColumnId::x: append_number(out, f.position.x()); break;
      case ColumnId::y: append_number(out, f.position.y()); break;
      case ColumnId::z: append_number(out, f.position.z()); break;
      case ColumnId::qw: append_number(out, f.orientation->w()); break;
      case ColumnId::qx: append_number(out, f.orientation->x()); break;
      case ColumnId::qy: append_number(out, f.orientation->y()); break;
      case ColumnId::qz: append_number(out, f.orientation->z()); break;
      case ColumnId::taxel: append_number(out, f.pressures(s.row, s.col)); break;
    }
  }
  out += '\n';
}

/// "frame F of exploration E of object 'O'", for messages.
inline std::string frame_text(std::string_view object, std::int64_t exploration, std::int64_t frame) {
  return "frame " + std::to_string(frame) + " of exploration " + std::to_string(exploration) + " of object " +
         quote_text(object, 60);
}

/// Where each frame (object, exploration, frame index) of a dataset was
/// first seen: a line of a file, an index into Dataset::frames. The format
/// has one row per frame (which of two is the frame, and in what order,
/// would be undefined), so the reader, the writer and the appender refuse a
/// second one, naming the first. O(log frames) per frame.
class FrameIndex {
 public:
  /// Records the frame at `place`, or, if it was recorded before, records
  /// nothing and returns the place it was first recorded at.
  std::optional<std::size_t> insert(std::string_view object, std::int64_t exploration, std::int64_t frame,
                                    std::size_t place) {
    const auto placed = places_.emplace(std::make_tuple(std::string(object), exploration, frame), place);
    if (placed.second) return std::nullopt;
    return placed.first->second;
  }

 private:
  std::map<std::tuple<std::string, std::int64_t, std::int64_t>, std::size_t> places_;
};

}  // namespace detail
}  // namespace iclap

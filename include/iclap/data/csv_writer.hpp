// SPDX-License-Identifier: MIT
#pragma once

// Writer of the haptic dataset CSV (README, "Dataset format").

#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>

#include "iclap/core/error.hpp"
#include "iclap/data/csv_common.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/io/atomic_file.hpp"

namespace iclap {

/// The columns `write_dataset_csv` uses for `ds`: its grid, `t` if the frames
/// have times, qw..qz if they have orientations.
inline DatasetColumns dataset_columns(const Dataset& ds) {
  DatasetColumns c;
  c.rows = ds.rows;
  c.cols = ds.cols;
  c.time = !ds.frames.empty() && ds.frames.front().time.has_value();
  c.orientation = !ds.frames.empty() && ds.frames.front().orientation.has_value();
  return c;
}

namespace detail {

inline void validate_grid(Index rows, Index cols, const std::string& where) {
  if (rows < 1 || cols < 1)
    throw InvalidArgument(where, "taxel grid " + std::to_string(rows) + "x" + std::to_string(cols) +
                                     " must have at least one row and one column");
}

inline void validate_comments(const std::vector<std::string>& comments, const std::string& where) {
  for (std::size_t i = 0; i < comments.size(); ++i)
    if (comments[i].find_first_of("\r\n") != std::string::npos)
      throw InvalidArgument(where + "[" + std::to_string(i) + "]", "contains a line break");
}

/// "# comment" lines then the header line.
inline std::string header_text(const std::vector<std::string>& comments, const DatasetColumns& columns) {
  std::string out;
  for (const auto& c : comments) out += "# " + c + "\n";
  bool first = true;
  for (const auto& n : columns.names()) {
    if (!first) out += ',';
    first = false;
    out += n;
  }
  out += '\n';
  return out;
}

}  // namespace detail

/// Writes `ds` as dataset CSV to `out`: its comments ("# " + text), the header
/// in writer order (see DatasetColumns) and one row per frame in order.
/// Numbers use the shortest text that reads back exactly (std::to_chars), so
/// `read_dataset_csv` of the output gives identical values, and the bytes are
/// a pure function of `ds` ('\n' line endings, no locale). The whole dataset
/// is validated before the first byte is written: InvalidArgument names the
/// frame and field (object name with a comma or quote or not UTF-8,
/// pressures of the wrong size, negative or non-finite values, `t` or
/// orientation on only some frames, a comment with a line break, two frames
/// with the same object, exploration and frame index). O(frames x taxels +
/// frames log frames).
inline void write_dataset_csv(std::ostream& out, const Dataset& ds) {
  detail::validate_grid(ds.rows, ds.cols, "dataset.rows/cols");
  detail::validate_comments(ds.comments, "dataset.comments");
  const DatasetColumns columns = dataset_columns(ds);
  // One row per frame, as the reader requires.
  detail::FrameIndex seen;
  for (std::size_t i = 0; i < ds.frames.size(); ++i) {
    const Frame& f = ds.frames[i];
    const std::string where = "dataset.frames[" + std::to_string(i) + "]";
    detail::validate_frame(f, columns, where);
    if (const auto first = seen.insert(f.object, f.exploration, f.frame, i))
      throw InvalidArgument(where, detail::frame_text(f.object, f.exploration, f.frame) + " is also dataset.frames[" +
                                       std::to_string(*first) + "] (one row per frame)");
  }
  const auto slots = detail::writer_slots(columns);
  std::string buf = detail::header_text(ds.comments, columns);
  for (const Frame& f : ds.frames) {
    detail::append_row(buf, f, slots);
    if (buf.size() > (1u << 20)) {
      out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
      buf.clear();
    }
  }
  out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
}

/// Writes `ds` to the file `path` all-or-nothing (through AtomicFileWriter):
/// on any error the previous content of `path`, if any, is left untouched.
/// Throws InvalidArgument (invalid dataset) or IoError (write failed).
inline void write_dataset_csv(const std::string& path, const Dataset& ds) {
  AtomicFileWriter file(path, std::ios::out | std::ios::binary);
  write_dataset_csv(file.stream(), ds);
  file.commit();
}

}  // namespace iclap

// SPDX-License-Identifier: MIT
#pragma once

// Streaming, crash-tolerant appender of dataset CSV rows, for recorders that
// log frames as they arrive (the rig recorder).

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/core/utf8.hpp"
#include "iclap/data/csv_common.hpp"
#include "iclap/data/csv_reader.hpp"
#include "iclap/data/csv_writer.hpp"

namespace iclap {

/// Appends frames to a dataset CSV file one complete row at a time.
///
/// Opening: if `path` does not exist or is empty (or holds only a UTF-8
/// byte-order mark, which is kept), it is created with the
/// comment lines and the header of `columns` (writer order). If it exists, its
/// header must have exactly the columns of `columns` (in any order; rows are
/// then written in the file's column order) or the constructor throws
/// ParseError naming the file and the header line; `comments` are not written
/// again. The header is checked before anything is changed. A trailing
/// partial row (the file does not end with a line break and its last line
/// has fewer fields than the header, or all of them with the last one empty,
/// e.g. after a power loss mid-write) is cut off and its size reported by
/// `recovered_bytes()`, so the file is always a sequence of complete rows. A
/// last line without a line break that has all the header's fields, the
/// last one not empty (or more fields), may be a whole row written by
/// another program or one cut inside its last number: the constructor
/// refuses it (ParseError naming the line) rather than guess, and changes
/// nothing. A header cut short (a run killed while creating the file: the
/// file ends inside its comments or header, with no line break and no row)
/// is completed, nothing cut, when it is the beginning of the header line
/// this appender writes, or of its comments and header
/// (`header_completed()`); any other last header or comment line without a
/// line break and before any row is refused as possibly cut short.
///
/// Writing: `append` validates the frame first (InvalidArgument, nothing
/// written; this includes a frame whose object, exploration and frame index
/// are those of a row already in the file, found when opening or appended
/// since, as the reader allows one row per frame), formats the whole row,
/// writes it with one buffered write and flushes it to the operating
/// system, so a crash of the process loses at most the row in flight.
/// `sync()` additionally asks the OS to put it on disk. A write that fails
/// (WriteError: disk full, file size limit) closes the appender and cuts the
/// file back to its last complete row; further rows are refused.
///
/// Not thread-safe; one appender per file. Move-only.
class DatasetCsvAppender {
 public:
  DatasetCsvAppender(std::string path, const DatasetColumns& columns,
                     const std::vector<std::string>& comments = {})
      : path_(std::move(path)), columns_(columns) {
    detail::validate_grid(columns.rows, columns.cols, "columns");
    detail::validate_comments(comments, "comments");
    std::error_code ec;
    if (std::filesystem::is_directory(path_, ec)) throw IoError(path_, "is a directory, not a dataset file");
    const bool exists = std::filesystem::exists(path_, ec);
    const bool empty = exists && std::filesystem::file_size(path_, ec) == 0 && !ec;
    std::string start;  // written first: a new file's comments and header, or the end of the file's header
    if (exists && !empty) {
      start = open_existing(comments);
    } else {
      slots_ = detail::writer_slots(columns_);
      start = detail::header_text(comments, columns_);
      lines_ = comments.size() + 1;
    }
    file_ = std::fopen(path_.c_str(), "ab");
    if (!file_) throw IoError(path_, std::string("cannot open for appending: ") + std::strerror(errno));
    if (exists && !empty) {
      size_ = static_cast<std::uintmax_t>(std::filesystem::file_size(path_, ec));
      if (ec) throw IoError(path_, "cannot read its size: " + ec.message());
    }
    // One buffer larger than any row: each row leaves in a single write().
    std::setvbuf(file_, nullptr, _IOFBF, 1 << 16);
    if (!start.empty()) write_and_flush(start);
  }

  /// Same as above with the columns spelled out: a `rows` x `cols` grid,
  /// with a `t` column if `time`, qw..qz columns if `orientation`.
  DatasetCsvAppender(std::string path, Index rows, Index cols, bool time, bool orientation,
                     const std::vector<std::string>& comments = {})
      : DatasetCsvAppender(std::move(path), DatasetColumns{rows, cols, time, orientation}, comments) {}

  DatasetCsvAppender(DatasetCsvAppender&& o) noexcept
      : path_(std::move(o.path_)),
        columns_(o.columns_),
        slots_(std::move(o.slots_)),
        file_(std::exchange(o.file_, nullptr)),
        rows_in_file_(o.rows_in_file_),
        recovered_bytes_(o.recovered_bytes_),
        header_completed_(o.header_completed_),
        size_(o.size_),
        failed_(o.failed_),
        frames_(std::move(o.frames_)),
        lines_(o.lines_) {}
  DatasetCsvAppender& operator=(DatasetCsvAppender&&) = delete;
  DatasetCsvAppender(const DatasetCsvAppender&) = delete;
  DatasetCsvAppender& operator=(const DatasetCsvAppender&) = delete;

  ~DatasetCsvAppender() {
    if (file_) std::fclose(file_);
  }

  /// Writes `f` as one complete row and flushes it. The frame must match the
  /// file's columns (grid size, `t` and orientation present exactly when the
  /// file has those columns) and be valid (finite, pressures >= 0, an object
  /// name without commas or quotes), and no row of the file may have its
  /// object, exploration and frame index: InvalidArgument otherwise, naming
  /// that row's line, and nothing is written. IoError if the write fails.
  void append(const Frame& f) {
    if (failed_) throw WriteError(path_, "an earlier write failed; the appender is closed");
    if (!file_)  // moved from (its path went with it)
      throw WriteError("DatasetCsvAppender", "this appender was moved from; append through the one it was moved to");
    detail::validate_frame(f, columns_, "frame");
    const std::size_t line = lines_ + 1;
    if (const auto first = frames_.insert(f.object, f.exploration, f.frame, line))
      throw InvalidArgument("frame", detail::frame_text(f.object, f.exploration, f.frame) + " is already in " +
                                         path_ + ", line " + std::to_string(*first) + " (one row per frame)");
    row_.clear();
    detail::append_row(row_, f, slots_);
    write_and_flush(row_);  // on failure the appender is closed: the index no longer matters
    lines_ = line;
    ++rows_in_file_;
  }

  /// Asks the operating system to write the file to its storage (fsync), for
  /// durability against power loss, not only process crashes. Slow: call it
  /// at the end of an exploration, not per row.
  void sync() {
    if (!file_ || fsync_file()) return;
    failed_ = true;
    throw WriteError(path_, std::string("fsync failed: ") + std::strerror(errno));
  }

  const std::string& path() const noexcept { return path_; }
  const DatasetColumns& columns() const noexcept { return columns_; }
  /// Data rows in the file: those found when opening plus those appended.
  std::size_t rows_in_file() const noexcept { return rows_in_file_; }
  /// Bytes of a trailing partial row cut off when opening (0 normally).
  std::size_t recovered_bytes() const noexcept { return recovered_bytes_; }
  /// True if the file held a header cut short when opening (the beginning of
  /// this appender's header line, or of its comments and header) and the
  /// appender wrote the rest.
  bool header_completed() const noexcept { return header_completed_; }

 private:
  // Reads the existing file's header, checks it, counts its rows and indexes
  // their frames; then (and only then) cuts off a trailing partial row.
  // Returns what to write before the first row: "\n" if the file's last line
  // is the (complete) header, which lacks its line break; the rest of the
  // comments and header of a file that holds only a BOM or a beginning of
  // them (`comments`: this appender's); "" otherwise.
  std::string open_existing(const std::vector<std::string>& comments) {
    std::string text;
    {
      std::ifstream in(path_, std::ios::binary);
      if (!in) throw IoError(path_, std::string("cannot open for reading: ") + std::strerror(errno));
      text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
      if (in.bad()) throw IoError(path_, "read failed");
    }
    std::string_view view(text);
    const std::size_t offset = utf8_bom_length(view);
    std::size_t pos = offset, line_no = 0, header_line = 0;
    std::size_t header_start = 0, header_end = 0;  // offsets of the header line and just past it
    std::string_view header, unterminated;
    std::size_t unterminated_start = 0;
    std::vector<std::pair<std::string_view, std::size_t>> rows;  // complete data rows and their lines
    while (pos < view.size()) {
      std::size_t end = view.find('\n', pos);
      const bool terminated = end != std::string_view::npos;
      if (!terminated) end = view.size();
      std::string_view line = view.substr(pos, end - pos);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      ++line_no;
      const std::size_t line_start = pos;
      pos = terminated ? end + 1 : end;
      if (header_line == 0) {
        if (detail::trim_ascii(line).empty() || line.front() == '#') continue;
        header = line;
        header_line = line_no;
        header_start = line_start;
        header_end = pos;
        continue;
      }
      if (!terminated) {
        unterminated = line;
        unterminated_start = line_start;
      } else if (!detail::trim_ascii(line).empty()) {
        rows.emplace_back(line, line_no);
      }
    }
    // A creation cut short leaves a beginning of the comments and header,
    // without a line break or row (a BOM-only file: an empty beginning).
    const bool ends_unterminated = view.size() > offset && view.back() != '\n';
    const std::string ours = detail::header_text(comments, columns_);
    const std::string_view content = view.substr(offset);
    if (header_line == 0 && content.size() < ours.size() && ours.compare(0, content.size(), content) == 0) {
      header_completed_ = !content.empty();
      slots_ = detail::writer_slots(columns_);
      lines_ = comments.size() + 1;
      return ours.substr(content.size());
    }
    if (header_line == 0) {
      const std::size_t last = view.rfind('\n');
      const bool comment_cut = ends_unterminated && view[last == std::string_view::npos ? offset : last + 1] == '#';
      throw ParseError(path_, line_no,
                       comment_cut ? "existing file has no header row, and its last line, a comment, has no line "
                                     "break: the comments may have been cut short while the file was created; "
                                     "cannot append to it"
                                   : "existing file has no header row; cannot append to it");
    }
    const bool header_last = header_end == view.size() && ends_unterminated;
    // Or, after comments of its own, a beginning of the header line.
    const std::string line_ours = detail::header_text({}, columns_);  // with its line break
    const std::string_view torn = view.substr(header_start);         // as written (a '\r' stays)
    if (header_last && torn.size() + 1 < line_ours.size() && line_ours.compare(0, torn.size(), torn) == 0) {
      header_completed_ = true;
      slots_ = detail::writer_slots(columns_);
      lines_ = header_line;
      return line_ours.substr(torn.size());
    }
    std::vector<std::string_view> header_fields;
    detail::split_fields(header, header_fields);
    check_header(header_fields, header_line,
                 header_last ? "; the header line has no line break and no row follows: it may have been cut "
                               "short while the file was created, but it does not begin the recorder's header"
                             : "");
    index_rows(header_fields, rows);
    lines_ = line_no;
    if (unterminated_start > 0) {
      std::vector<std::string_view> fields;
      detail::split_fields(unterminated, fields);
      // A row cut right after its last comma has all its fields, the last
      // one empty, which no whole row has (the reader refuses empty
      // values): it is partial too.
      const bool whole = fields.size() > header_fields.size() ||
                         (fields.size() == header_fields.size() && !detail::trim_ascii(fields.back()).empty());
      if (!detail::trim_ascii(unterminated).empty() && whole)
        throw ParseError(path_, line_no,
                         "the last row has " + std::to_string(fields.size()) + " fields (the header has " +
                             std::to_string(header_fields.size()) +
                             ") but no line break: a whole row or one cut inside its last value; end it with a "
                             "line break or remove it before appending");
      // Fewer fields than the header, or an empty last one: a row cut off
      // mid-write.
      recovered_bytes_ = view.size() - unterminated_start;
      --lines_;
      std::error_code ec;
      std::filesystem::resize_file(path_, unterminated_start, ec);
      if (ec) throw IoError(path_, "cannot cut off a partial last row: " + ec.message());
    }
    return header_last ? "\n" : "";
  }

  // Counts the file's complete data rows and records the frame of each in
  // frames_, so that append refuses a second row of a frame. A row whose
  // object, exploration or frame the reader would refuse is counted and not
  // indexed: the file is unreadable already, and stays as it was.
  // `header`: the header's fields, checked by check_header.
  void index_rows(const std::vector<std::string_view>& header,
                  const std::vector<std::pair<std::string_view, std::size_t>>& rows) {
    std::size_t i_object = 0, i_expl = 0, i_frame = 0;
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == "object") i_object = i;
      if (header[i] == "exploration") i_expl = i;
      if (header[i] == "frame") i_frame = i;
    }
    const std::size_t needed = std::max({i_object, i_expl, i_frame}) + 1;
    std::vector<std::string_view> fields;
    for (const auto& row : rows) {
      ++rows_in_file_;
      detail::split_fields(row.first, fields);
      std::int64_t exploration = 0, frame = 0;
      if (fields.size() < needed || !detail::object_name_problem(fields[i_object]).empty() ||
          !detail::parse_int64(fields[i_expl], exploration) || !detail::parse_int64(fields[i_frame], frame))
        continue;
      frames_.insert(fields[i_object], exploration, frame, row.second);
    }
  }

  // `fields`: the header's, found on line `line`; `note` ends the message of
  // a mismatch.
  void check_header(const std::vector<std::string_view>& fields, std::size_t line, const char* note) {
    const auto expected = columns_.names();
    const auto ours = detail::writer_slots(columns_);
    std::set<std::string> want(expected.begin(), expected.end()), seen;
    std::string unexpected, duplicate;
    for (auto f : fields) {
      const std::string s(f);
      if (!want.count(s)) unexpected += (unexpected.empty() ? "" : ", ") + quote_text(s, 60);
      else if (!seen.insert(s).second) duplicate += (duplicate.empty() ? "" : ", ") + quote_text(s, 60);
    }
    std::string missing;
    std::size_t n_missing = 0;
    for (const auto& e : expected)
      if (!seen.count(e)) {
        if (++n_missing <= 5) missing += (missing.empty() ? "" : ", ") + quote_text(e);
      }
    if (n_missing > 5) missing += " and " + std::to_string(n_missing - 5) + " more";
    if (!unexpected.empty() || !missing.empty() || !duplicate.empty()) {
      std::string reason = "header does not match the recorder's columns (" +
                           std::to_string(columns_.rows) + "x" + std::to_string(columns_.cols) +
                           " taxels, t " + (columns_.time ? "yes" : "no") + ", quaternion " +
                           (columns_.orientation ? "yes" : "no") + "):";
      if (!missing.empty()) reason += " missing " + missing + ";";
      if (!unexpected.empty()) reason += " unexpected " + unexpected + ";";
      if (!duplicate.empty()) reason += " duplicate " + duplicate + ";";
      reason.pop_back();
      throw ParseError(path_, line, reason + note);
    }
    // Same set of columns: write in the file's order.
    for (auto f : fields) {
      const std::string s(f);
      for (std::size_t i = 0; i < expected.size(); ++i)
        if (expected[i] == s) slots_.push_back(ours[i]);
    }
  }

  // Writes and flushes `text`. On failure closes the file (dropping what is
  // still buffered) and cuts it back to `size_`, the end of the last
  // complete write, so no partial row stays behind.
  void write_and_flush(const std::string& text) {
    const std::size_t n = std::fwrite(text.data(), 1, text.size(), file_);
    if (n == text.size() && std::fflush(file_) == 0) {
      size_ += text.size();
      return;
    }
    const int err = errno;
    failed_ = true;
    std::fclose(file_);
    file_ = nullptr;
    std::error_code ec;
    std::filesystem::resize_file(path_, size_, ec);
    throw WriteError(path_, std::string("write failed: ") + std::strerror(err) +
                                (ec ? "; cutting the partial row off failed too: " + ec.message()
                                    : "; the file was cut back to its last complete row"));
  }

  bool fsync_file();

  std::string path_;
  DatasetColumns columns_;
  std::vector<detail::ColumnSlot> slots_;
  std::FILE* file_ = nullptr;
  std::string row_;
  std::size_t rows_in_file_ = 0;
  std::size_t recovered_bytes_ = 0;
  bool header_completed_ = false;
  std::uintmax_t size_ = 0;  // bytes in the file after the last complete write
  bool failed_ = false;
  detail::FrameIndex frames_;  // the frame of every row in the file, by line
  std::size_t lines_ = 0;      // lines in the file (comments, header, rows)
};

}  // namespace iclap

#if defined(__unix__) || defined(__APPLE__)
#include <unistd.h>
inline bool iclap::DatasetCsvAppender::fsync_file() { return ::fsync(::fileno(file_)) == 0; }
#else
inline bool iclap::DatasetCsvAppender::fsync_file() { return std::fflush(file_) == 0; }
#endif

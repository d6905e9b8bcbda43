// SPDX-License-Identifier: MIT
#pragma once

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "iclap/core/error.hpp"

namespace iclap {

/// Writes a file all-or-nothing: the content goes to `PATH.partial` beside the
/// target and is renamed over `PATH` only by `commit()`. If the writer is
/// destroyed without a commit (an exception, a failed write), the partial file
/// is removed and `PATH` is left as it was, so a failed run never leaves a
/// truncated output behind. Rename is atomic on POSIX file systems.
///
/// Not thread-safe; one writer per target path.
class AtomicFileWriter {
 public:
  /// Opens the temporary file; throws IoError naming `path` if it cannot.
  explicit AtomicFileWriter(std::string path, std::ios::openmode mode = std::ios::out)
      : path_(std::move(path)), temp_(path_ + ".partial") {
    out_.open(temp_, mode | std::ios::out | std::ios::trunc);
    if (!out_) throw IoError(path_, std::string("cannot open for writing: ") + std::strerror(errno));
  }
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

  ~AtomicFileWriter() {
    if (!committed_) {
      out_.close();
      std::remove(temp_.c_str());
    }
  }

  /// The stream to write the content to.
  std::ostream& stream() noexcept { return out_; }

  /// The final path.
  const std::string& path() const noexcept { return path_; }

  /// Flushes, checks that every write succeeded and moves the file into
  /// place. Throws IoError (and leaves the target untouched) otherwise.
  void commit() {
    out_.flush();
    const bool ok = static_cast<bool>(out_);
    out_.close();
    if (!ok || out_.fail()) throw IoError(path_, "write failed");
    if (std::rename(temp_.c_str(), path_.c_str()) != 0)
      throw IoError(path_, std::string("cannot move into place: ") + std::strerror(errno));
    committed_ = true;
  }

 private:
  std::string path_;
  std::string temp_;
  std::ofstream out_;
  bool committed_ = false;
};

}  // namespace iclap

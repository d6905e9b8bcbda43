// SPDX-License-Identifier: MIT
#pragma once

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "iclap/core/error.hpp"

#if defined(__unix__) || defined(__APPLE__)
#include <fcntl.h>
#include <unistd.h>
#endif

namespace iclap {

/// Writes a file all-or-nothing: the content goes to a temporary file beside
/// the target (`PATH.partial-PID-N`, created exclusively, so it never
/// replaces a file of that name) and is renamed over `PATH` only by
/// `commit()`. If the writer is destroyed without a commit (an exception, a
/// failed write), the temporary file is removed and `PATH` is left as it
/// was, so a failed run never leaves a truncated output behind. Rename is
/// atomic on POSIX file systems.
///
/// Not thread-safe; one writer per target path.
class AtomicFileWriter {
 public:
  /// Creates and opens the temporary file; throws IoError naming `path` if
  /// it cannot.
  explicit AtomicFileWriter(std::string path, std::ios::openmode mode = std::ios::out)
      : path_(std::move(path)), temp_(create_temporary(path_)) {
    out_.open(temp_, mode | std::ios::out | std::ios::trunc);
    if (!out_) {
      const int err = errno;
      std::remove(temp_.c_str());
      throw IoError(path_, std::string("cannot open for writing: ") + std::strerror(err));
    }
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

  /// The temporary file the content goes to until commit().
  const std::string& temporary_path() const noexcept { return temp_; }

  /// Flushes, checks that every write succeeded and moves the file into
  /// place. Throws WriteError if a write failed, IoError if the rename
  /// failed, and leaves the target untouched either way.
  void commit() {
    out_.flush();
    const bool ok = static_cast<bool>(out_);
    out_.close();
    if (!ok || out_.fail()) throw WriteError(path_, "write failed");
    if (std::rename(temp_.c_str(), path_.c_str()) != 0)
      throw IoError(path_, std::string("cannot move into place: ") + std::strerror(errno));
    committed_ = true;
  }

 private:
  // A new, empty file `path.partial-PID-N` (the first N not taken).
  static std::string create_temporary(const std::string& path) {
#if defined(__unix__) || defined(__APPLE__)
    static std::atomic<unsigned> counter{0};
    for (int attempt = 0; attempt < 1000; ++attempt) {
      const std::string temp = path + ".partial-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
      const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0666);
      if (fd >= 0) {
        ::close(fd);
        return temp;
      }
      if (errno != EEXIST) throw IoError(path, std::string("cannot open for writing: ") + std::strerror(errno));
    }
    throw IoError(path, "cannot create a temporary file beside it (1000 names taken)");
#else
    return path + ".partial";
#endif
  }

  std::string path_;
  std::string temp_;
  std::ofstream out_;
  bool committed_ = false;
};

}  // namespace iclap

// SPDX-License-Identifier: MIT
#pragma once

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "iclap/core/error.hpp"

#if defined(__unix__) || defined(__APPLE__)
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#endif

namespace iclap {

/// The directory that holds `path`: its parent, or "." for a bare name.
inline std::filesystem::path directory_of(const std::filesystem::path& path) {
  std::filesystem::path parent = path.parent_path();
  return parent.empty() ? std::filesystem::path(".") : parent;
}

#if defined(__unix__) || defined(__APPLE__)
namespace detail {
/// Opens `path` with `flags`, asks the operating system to put it on
/// storage (fsync) and closes it. Returns 0, or the errno of the failed
/// open (`opened` false) or fsync.
inline int open_and_sync(const char* path, int flags, bool& opened) noexcept {
  const int fd = ::open(path, flags);
  opened = fd >= 0;
  if (!opened) return errno;
  const int err = ::fsync(fd) == 0 ? 0 : errno;
  ::close(fd);
  return err;
}
}  // namespace detail

/// Asks the operating system to put directory `dir`'s entries on storage
/// (fsync), so that files just renamed into it stay there after a power
/// loss. Returns 0, or the errno of a failed fsync. A directory that cannot
/// be opened for reading (mode 0300) or a file system that cannot sync
/// directories (EINVAL) is skipped and returns 0: there is nothing more to do.
inline int sync_directory(const std::string& dir) noexcept {
  bool opened = false;
  const int err = detail::open_and_sync(dir.c_str(), O_RDONLY | O_DIRECTORY, opened);
  return !opened || err == EINVAL ? 0 : err;
}
#endif

/// Writes a file all-or-nothing: the content goes to a temporary file beside
/// the target (`PATH.partial-PID-N`, created exclusively, so it never
/// replaces a file of that name; `DIR/.partial-PID-N` where that name would
/// be longer than a file name may be) and is renamed over `PATH` only by
/// `commit()`. If the writer is destroyed without a commit (an exception, a
/// failed write), the temporary file is removed and `PATH` is left as it
/// was, so a failed run never leaves a truncated output behind. Rename is
/// atomic on POSIX file systems.
///
/// Where `PATH` is a symbolic link, the file it leads to is replaced and the
/// link stays. Where `PATH` exists, the new file gets its permission bits
/// (a 0600 file stays 0600), and until then the temporary file is readable
/// by its owner only.
///
/// Not thread-safe; one writer per target path.
class AtomicFileWriter {
 public:
  /// Creates and opens the temporary file; throws IoError naming `path` if
  /// it cannot.
  explicit AtomicFileWriter(std::string path, std::ios::openmode mode = std::ios::out)
      : path_(std::move(path)), target_(resolve_links(path_)), temp_(create_temporary(path_, target_)) {
    errno = 0;  // a refused open mode (std::ios::app) fails without setting it
    out_.open(temp_, mode | std::ios::out | std::ios::trunc);
    if (!out_) {
      const int err = errno;
      std::remove(temp_.c_str());
      throw IoError(path_, std::string("cannot open for writing: ") +
                               (err != 0 ? std::strerror(err) : "the stream refused the open mode"));
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

  /// Whether commit() puts the directory holding the file on storage.
  enum class DirectorySync {
    yes,  ///< the default: the rename itself survives a power loss
    no    ///< for a file in a staging directory whose caller moves it on and syncs where it lands
  };

  /// Flushes, checks that every write succeeded, asks the operating system
  /// to put the content on storage (fsync) and moves the file into place,
  /// then (unless `directory` is DirectorySync::no) puts the directory that
  /// holds it on storage too, so that the rename itself survives a power
  /// loss. Throws WriteError if a write or the file's fsync failed, IoError
  /// if the rename failed, and leaves the target untouched either way. Once
  /// the file is in place, a failed fsync of the directory throws WriteError
  /// saying so (the new content stays); a file system that cannot sync
  /// directories (EINVAL), or a directory that may be written but not read,
  /// is not an error.
  void commit(DirectorySync directory = DirectorySync::yes) {
    out_.flush();
    const bool ok = static_cast<bool>(out_);
    out_.close();
    if (!ok || out_.fail()) throw WriteError(path_, "write failed");
#if defined(__unix__) || defined(__APPLE__)
    // The content reaches storage before the rename makes it the file, so
    // that after a power loss the path holds the old content or the new,
    // not an empty or partial new file (file systems need not order the
    // data writes before the rename).
    bool opened = false;
    if (const int err = detail::open_and_sync(temp_.c_str(), O_RDONLY, opened))
      throw WriteError(path_, std::string("fsync failed: ") + std::strerror(err));
    // The replaced file's permission bits (given after writing, so that a
    // read-only target is still replaced, as before).
    struct stat existing {};
    if (::stat(target_.c_str(), &existing) == 0 && ::chmod(temp_.c_str(), existing.st_mode & 07777) != 0)
      throw IoError(path_, std::string("cannot give the new file the old one's permissions: ") + std::strerror(errno));
#endif
    if (std::rename(temp_.c_str(), target_.c_str()) != 0)
      throw IoError(path_, std::string("cannot move into place: ") + std::strerror(errno));
    committed_ = true;
#if defined(__unix__) || defined(__APPLE__)
    if (directory == DirectorySync::yes) sync_target_directory();
#else
    (void)directory;
#endif
  }

 private:
#if defined(__unix__) || defined(__APPLE__)
  /// fsync of the directory holding the target (after the rename).
  void sync_target_directory() const {
    const std::string dir = directory_of(target_).string();
    if (const int err = iclap::sync_directory(dir))
      throw WriteError(path_, "written and moved into place, but the fsync of its directory " + dir +
                                  " failed, so a power loss may undo the move: " + std::strerror(err));
  }
#endif

  /// `path`, or where it is a symbolic link (of a chain), the path it
  /// finally leads to, so that the rename replaces that file, not the link.
  /// IoError naming `path` for a loop of links.
  static std::string resolve_links(const std::string& path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::path p = path;
    for (int hops = 0; fs::is_symlink(fs::symlink_status(p, ec)); ++hops) {
      if (hops == 40) throw IoError(path, "cannot open for writing: too many levels of symbolic links");
      const fs::path link = fs::read_symlink(p, ec);
      if (ec) throw IoError(path, "cannot read the symbolic link: " + ec.message());
      p = link.is_absolute() ? link : p.parent_path() / link;
    }
    return p.string();
  }

  // A new, empty file `target.partial-PID-N` (the first N not taken);
  // `DIR/.partial-PID-N` when the name would be too long. IoError names
  // `path`, the name given.
  static std::string create_temporary(const std::string& path, const std::string& target) {
#if defined(__unix__) || defined(__APPLE__)
    static std::atomic<unsigned> counter{0};
    // Private (0600) while it replaces a file, whose permission bits may
    // keep its content from other users (commit() gives them); a new file
    // gets 0666 less the umask, as any.
    struct stat existing {};
    const mode_t mode = ::stat(target.c_str(), &existing) == 0 ? 0600 : 0666;
    const std::filesystem::path t = target;
    const bool short_name = t.filename().string().size() + 32 > 255;  // NAME_MAX on Linux and macOS
    for (int attempt = 0; attempt < 1000; ++attempt) {
      const std::string suffix = ".partial-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
      const std::string temp = short_name ? (t.parent_path() / suffix).string() : target + suffix;
      const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL, mode);
      if (fd >= 0) {
        ::close(fd);
        return temp;
      }
      if (errno != EEXIST) throw IoError(path, std::string("cannot open for writing: ") + std::strerror(errno));
    }
    throw IoError(path, "cannot create a temporary file beside it (1000 names taken)");
#else
    (void)path;
    return target + ".partial";
#endif
  }

  std::string path_;    // as given, for messages
  std::string target_;  // the file replaced: path_ with symbolic links followed
  std::string temp_;
  std::ofstream out_;
  bool committed_ = false;
};

}  // namespace iclap

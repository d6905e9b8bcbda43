// SPDX-License-Identifier: MIT
#pragma once

// Makes writes fail part-way, as on a full disk: a file size limit
// (RLIMIT_FSIZE) for this process, with SIGXFSZ ignored so an over-limit
// write fails with EFBIG instead of killing the test. Both are restored on
// destruction. Tests that use it write nothing else meanwhile.

#include <sys/resource.h>

#include <csignal>

namespace iclap::test {

class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    getrlimit(RLIMIT_FSIZE, &old_);
    rlimit lim = old_;
    lim.rlim_cur = bytes;
    ok_ = setrlimit(RLIMIT_FSIZE, &lim) == 0;
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }
  /// False if the limit could not be set (the test should then fail).
  bool ok() const noexcept { return ok_; }

 private:
  rlimit old_{};
  void (*old_handler_)(int) = nullptr;
  bool ok_ = false;
};

}  // namespace iclap::test

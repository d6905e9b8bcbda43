// SPDX-License-Identifier: MIT
#pragma once
// The device side of a pseudo-terminal for the fake sensors of the rig
// tests: the code under test opens `path()` like a /dev/ttyACM* port, the
// fake reads its commands and writes its replies and frames on the master.
// Used from one thread (the fake's), apart from construction and destruction.

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace iclap::rig::test {

class PtyPort {
 public:
  /// Opens a raw pseudo-terminal; throws std::runtime_error if it cannot.
  PtyPort() {
    termios raw{};
    ::cfmakeraw(&raw);
    raw.c_cflag |= CLOCAL | CREAD;
    char name[256] = {};
    if (::openpty(&master_, &slave_, name, &raw, nullptr) != 0)
      throw std::runtime_error(std::string("openpty failed: ") + std::strerror(errno));
    path_ = name;
    // Children (the iclap process under test) must not inherit the master,
    // or closing it here would not hang up their port.
    ::fcntl(master_, F_SETFD, FD_CLOEXEC);
    ::fcntl(slave_, F_SETFD, FD_CLOEXEC);
    ::fcntl(master_, F_SETFL, ::fcntl(master_, F_GETFL) | O_NONBLOCK);
  }
  ~PtyPort() {
    close();
    if (slave_ >= 0) ::close(slave_);
  }
  PtyPort(const PtyPort&) = delete;
  PtyPort& operator=(const PtyPort&) = delete;

  /// The slave device path (/dev/pts/N).
  const std::string& path() const { return path_; }
  /// False once closed (unplugged).
  bool is_open() const { return master_ >= 0; }
  /// True when everything queued has been written.
  bool drained() const { return out_.empty(); }

  /// Bytes written to the host that it has not read yet (what the slave's
  /// line discipline holds); -1 if that cannot be asked.
  int unread_by_host() const {
    int pending = 0;
    return ::ioctl(slave_, FIONREAD, &pending) == 0 ? pending : -1;
  }

  /// Waits up to `patience` until the host has at least `bytes` unread.
  bool wait_unread_by_host(int bytes, std::chrono::milliseconds patience) const {
    const auto deadline = std::chrono::steady_clock::now() + patience;
    for (;;) {
      const int pending = unread_by_host();
      if (pending < 0) return false;
      if (pending >= bytes) return true;
      if (std::chrono::steady_clock::now() >= deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }

  /// Up to `size` bytes the host wrote, waiting at most `wait`; 0 if none.
  std::size_t read(std::uint8_t* buffer, std::size_t size, std::chrono::milliseconds wait) {
    if (master_ < 0) return 0;
    pollfd p{master_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(wait.count())) <= 0 || !(p.revents & POLLIN)) return 0;
    const ssize_t n = ::read(master_, buffer, size);
    return n > 0 ? static_cast<std::size_t>(n) : 0;
  }

  /// Queues bytes for the host; `flush` writes them.
  void queue(const std::vector<std::uint8_t>& bytes) { out_.insert(out_.end(), bytes.begin(), bytes.end()); }
  void queue(std::uint8_t byte) { out_.push_back(byte); }

  /// Writes queued output, waiting up to `patience` for room.
  void flush(std::chrono::milliseconds patience = std::chrono::milliseconds(0)) {
    const auto deadline = std::chrono::steady_clock::now() + patience;
    while (!out_.empty() && master_ >= 0) {
      const ssize_t n = ::write(master_, out_.data(), out_.size());
      if (n > 0) {
        out_.erase(out_.begin(), out_.begin() + n);
        continue;
      }
      if (std::chrono::steady_clock::now() >= deadline) return;
      pollfd p{master_, POLLOUT, 0};
      ::poll(&p, 1, 5);
    }
  }

  /// Closes the master once the host has read what was sent (the kernel
  /// discards unread input on hang-up). `before_close` runs just before the
  /// close: the host may look as soon as it sees the hang-up.
  template <typename F>
  void unplug(F&& before_close) {
    flush(std::chrono::milliseconds(2000));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (std::chrono::steady_clock::now() < deadline) {
      if (unread_by_host() <= 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    before_close();
    close();
  }

  void close() {
    if (master_ >= 0) ::close(master_);
    master_ = -1;
  }

 private:
  int master_ = -1;
  int slave_ = -1;
  std::string path_;
  std::vector<std::uint8_t> out_;
};

}  // namespace iclap::rig::test

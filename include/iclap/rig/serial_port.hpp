// SPDX-License-Identifier: MIT
#pragma once

// POSIX serial port transport (termios). Including this header is the
// opt-in: it needs <termios.h> and friends, which iclap's other headers never
// include. Tested end to end on pseudo-terminals (tests/rig).

#include <fcntl.h>
#include <poll.h>
#include <sys/file.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>

#include "iclap/core/error.hpp"
#include "iclap/rig/byte_stream.hpp"

namespace iclap::rig {

/// A serial port in raw mode, 8 data bits, no parity, 1 stop bit, no flow
/// control: what the WTS sensor's USB CDC-ACM port (/dev/ttyACM*) expects.
/// CDC-ACM ignores the baud rate; 115200 is customary.
///
/// Opening takes an advisory exclusive lock (flock) so two recorders cannot
/// share one sensor, and discards input that was waiting from before.
/// read() reports a hang-up (unplug, or a pseudo-terminal whose master
/// closed) as DeviceLost. Move-only; one reader and one writer thread.
class SerialPort final : public ByteStream {
 public:
  struct Settings {
    int baud = 115200;      ///< one of the standard rates 1200..921600
    bool exclusive = true;  ///< fail if another process holds the port
  };

  /// Opens and configures `path`. Throws TransportError naming the path
  /// (no such device, permission denied, in use, not a terminal), or
  /// InvalidArgument for an unsupported baud rate.
  explicit SerialPort(std::string path) : SerialPort(std::move(path), Settings{}) {}
  SerialPort(std::string path, Settings settings) : path_(std::move(path)) {
    const speed_t speed = baud_constant(settings.baud);
    fd_ = ::open(path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) {
      const int err = errno;
      std::string reason = std::string("cannot open: ") + std::strerror(err);
      if (err == ENOENT) reason += " (is the device plugged in? `iclap devices` lists ports)";
      if (err == EACCES) reason += " (add your user to the group owning the port, usually 'dialout')";
      throw TransportError(path_, reason);
    }
    try {
      if (!::isatty(fd_)) fail("is not a serial port (not a terminal device)");
      if (settings.exclusive && ::flock(fd_, LOCK_EX | LOCK_NB) != 0)
        fail(errno == EWOULDBLOCK ? std::string("is in use by another program")
                                  : std::string("cannot lock: ") + std::strerror(errno));
      termios tio{};
      if (::tcgetattr(fd_, &tio) != 0) fail(std::string("cannot read terminal settings: ") + std::strerror(errno));
      ::cfmakeraw(&tio);
      tio.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | CSTOPB | CRTSCTS);
      tio.c_cflag |= static_cast<tcflag_t>(CS8 | CLOCAL | CREAD);
      tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
      tio.c_cc[VMIN] = 1;  // with O_NONBLOCK: no data -> EAGAIN, 0 bytes -> hang-up
      tio.c_cc[VTIME] = 0;
      if (::cfsetispeed(&tio, speed) != 0 || ::cfsetospeed(&tio, speed) != 0)
        fail("cannot set baud rate " + std::to_string(settings.baud));
      if (::tcsetattr(fd_, TCSANOW, &tio) != 0)
        fail(std::string("cannot set raw mode 8N1: ") + std::strerror(errno));
      ::tcflush(fd_, TCIFLUSH);
    } catch (...) {
      ::close(fd_);
      fd_ = -1;
      throw;
    }
  }

  ~SerialPort() override { close(); }
  SerialPort(SerialPort&& other) noexcept : path_(std::move(other.path_)), fd_(other.fd_) { other.fd_ = -1; }
  SerialPort& operator=(SerialPort&& other) noexcept {
    if (this != &other) {
      close();
      path_ = std::move(other.path_);
      fd_ = other.fd_;
      other.fd_ = -1;
    }
    return *this;
  }

  std::size_t read(std::uint8_t* buffer, std::size_t capacity, std::chrono::milliseconds timeout) override {
    require_open();
    if (capacity == 0) return 0;
    pollfd p{fd_, POLLIN, 0};
    const int rc = ::poll(&p, 1, poll_timeout(timeout));
    if (rc < 0) {
      if (errno == EINTR) return 0;
      throw TransportError(path_, std::string("poll failed: ") + std::strerror(errno));
    }
    if (rc == 0) return 0;
    if (p.revents & POLLNVAL) throw TransportError(path_, "descriptor is not open");
    const bool hangup = (p.revents & (POLLHUP | POLLERR)) != 0;
    if (p.revents & POLLIN) {
      const ssize_t n = ::read(fd_, buffer, capacity);
      if (n > 0) return static_cast<std::size_t>(n);
      if (n == 0) throw DeviceLost(path_, "device lost (end of stream: port hung up)");
      const int err = errno;
      if (err != EAGAIN && err != EWOULDBLOCK && err != EINTR) {
        if (is_lost_errno(err)) throw DeviceLost(path_, std::string("device lost (") + std::strerror(err) + ")");
        throw TransportError(path_, std::string("read failed: ") + std::strerror(err));
      }
    }
    if (hangup) throw DeviceLost(path_, "device lost (port hung up)");
    return 0;
  }

  void write(const std::uint8_t* data, std::size_t size, std::chrono::milliseconds timeout) override {
    require_open();
    const auto deadline = deadline_after(timeout);
    std::size_t done = 0;
    while (done < size) {
      const ssize_t n = ::write(fd_, data + done, size - done);
      if (n > 0) {
        done += static_cast<std::size_t>(n);
        continue;
      }
      const int err = n < 0 ? errno : EAGAIN;
      if (err == EINTR) continue;
      if (err != EAGAIN && err != EWOULDBLOCK) {
        if (is_lost_errno(err)) throw DeviceLost(path_, std::string("device lost (") + std::strerror(err) + ")");
        throw TransportError(path_, std::string("write failed: ") + std::strerror(err));
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0)
        throw TransportError(path_, "write timed out after " + std::to_string(timeout.count()) + " ms");
      pollfd p{fd_, POLLOUT, 0};
      if (::poll(&p, 1, poll_timeout(left)) < 0 && errno != EINTR)
        throw TransportError(path_, std::string("poll failed: ") + std::strerror(errno));
      if (p.revents & (POLLHUP | POLLERR)) throw DeviceLost(path_, "device lost (port hung up)");
    }
  }
  using ByteStream::write;

  void close() noexcept override {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  bool is_open() const noexcept override { return fd_ >= 0; }
  const std::string& name() const noexcept override { return path_; }
  /// The file descriptor (-1 when closed), e.g. for a caller's own poll().
  int native_handle() const noexcept { return fd_; }

 private:
  [[noreturn]] void fail(const std::string& reason) const { throw TransportError(path_, reason); }
  void require_open() const {
    if (fd_ < 0) throw TransportError(path_, "port is closed");
  }
  static bool is_lost_errno(int err) noexcept { return err == EIO || err == ENXIO || err == ENODEV || err == EPIPE; }
  static int poll_timeout(std::chrono::milliseconds t) noexcept {
    return static_cast<int>(std::clamp<std::chrono::milliseconds::rep>(t.count(), 0, 24 * 3600 * 1000));
  }
  static speed_t baud_constant(int baud) {
    switch (baud) {
      case 1200: return B1200;
      case 2400: return B2400;
      case 4800: return B4800;
      case 9600: return B9600;
      case 19200: return B19200;
      case 38400: return B38400;
      case 57600: return B57600;
      case 115200: return B115200;
      case 230400: return B230400;
#ifdef B460800
      case 460800: return B460800;
#endif
#ifdef B921600
      case 921600: return B921600;
#endif
      default: throw InvalidArgument("baud", std::to_string(baud) + " is not a standard serial rate");
    }
  }

  std::string path_;
  int fd_ = -1;
};

}  // namespace iclap::rig

// SPDX-License-Identifier: MIT
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>

#include "iclap/core/error.hpp"

namespace iclap::rig {

/// A transport operation failed (cannot open, bad settings, write refused).
/// `path()` names the device; `what()` reads "PATH: reason".
class TransportError : public IoError {
 public:
  using IoError::IoError;
};

/// The device went away (unplugged, port hung up, HID device removed). Tools
/// tell it apart from other failures: the recording so far is intact, and
/// `iclap record` exits with status 3.
class DeviceLost : public TransportError {
 public:
  using TransportError::TransportError;
};

/// steady_clock::now() + `timeout`, saturated: a timeout of
/// milliseconds::max() (the usual "as long as it takes") overflowed the sum,
/// undefined behaviour that gave a deadline in the past, so nothing waited.
/// A negative timeout is now. For deadlines of waits.
inline std::chrono::steady_clock::time_point deadline_after(std::chrono::milliseconds timeout) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point now = Clock::now();
  if (timeout <= std::chrono::milliseconds::zero()) return now;
  if (timeout >= std::chrono::duration_cast<std::chrono::milliseconds>(Clock::time_point::max() - now))
    return Clock::time_point::max();
  return now + std::chrono::duration_cast<Clock::duration>(timeout);
}

/// A bidirectional byte stream to a device: the one interface the protocol
/// code talks to, implemented by SerialPort (serial_port.hpp), HidByteStream
/// (hid_device.hpp) and test doubles.
///
/// Contract: read() waits at most `timeout` and returns the bytes available
/// (0 on timeout or when a signal interrupted the wait, so callers can check
/// a stop flag); write() sends everything or throws. Both throw DeviceLost
/// when the device is gone and TransportError on other failures, including
/// use after close(). close() is idempotent and never throws. One reader
/// and one writer thread at most; not otherwise thread-safe.
class ByteStream {
 public:
  virtual ~ByteStream() = default;
  ByteStream() = default;
  ByteStream(const ByteStream&) = delete;
  ByteStream& operator=(const ByteStream&) = delete;

  /// Reads up to `capacity` bytes into `buffer`, waiting at most `timeout`.
  virtual std::size_t read(std::uint8_t* buffer, std::size_t capacity, std::chrono::milliseconds timeout) = 0;
  /// Writes all `size` bytes, waiting at most `timeout` for the device to
  /// accept them (TransportError "write timed out" otherwise).
  virtual void write(const std::uint8_t* data, std::size_t size,
                     std::chrono::milliseconds timeout = std::chrono::milliseconds(1000)) = 0;
  virtual void close() noexcept = 0;
  virtual bool is_open() const noexcept = 0;
  /// The device's name for messages (e.g. its path).
  virtual const std::string& name() const noexcept = 0;
};

}  // namespace iclap::rig

// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/rig/crc16.hpp"
#include "iclap/rig/wts_protocol.hpp"

namespace iclap::rig {

/// One CRC-checked packet: its id and payload (without preamble, size, CRC).
struct RawPacket {
  std::uint8_t id = 0;
  Bytes payload;
};

/// Counters of a PacketFramer. Every byte fed is, once the stream is
/// finished, either part of a returned packet or counted in `junk_bytes`:
/// `bytes_in == packet_bytes + junk_bytes + buffered()`.
struct FramerStats {
  std::uint64_t bytes_in = 0;      ///< bytes fed
  std::uint64_t packets = 0;       ///< packets returned
  std::uint64_t packet_bytes = 0;  ///< bytes of returned packets, preamble to CRC
  std::uint64_t junk_bytes = 0;    ///< bytes dropped outside any valid packet
  std::uint64_t crc_errors = 0;    ///< complete candidates whose CRC did not match
  std::uint64_t oversize = 0;      ///< headers announcing more than max_payload bytes
  std::uint64_t truncated = 0;     ///< candidates cut short by a packet inside them, or by the end of the stream
};

/// Splits a byte stream into WTS packets (see README, "Rig tools").
///
/// Bytes may arrive in any chunking. The framer looks for the preamble
/// AA AA AA, reads id and size, and returns the packet once its CRC checks.
/// It resynchronises on its own, dropping a bad candidate one byte at a
/// time so that a real packet starting inside it is still found:
/// - a header announcing more than `max_payload` bytes is dropped at once
///   (`oversize`), so junk cannot make the framer wait for 64 kB;
/// - a candidate inside whose announced extent a complete, CRC-valid packet
///   starts is dropped (`truncated`): it was cut short, e.g. by an unplug
///   or a lost byte, or its size field is corrupted. This is decided as soon
///   as that inner packet is complete, so a corrupted size field delays the
///   stream by one packet at most;
/// - a complete candidate with a bad CRC is dropped (`crc_errors`);
/// - finish() drops an incomplete candidate at the end of a stream.
/// Every decision depends only on the bytes, never on how they were
/// chunked: feeding a stream at once or byte by byte yields the same packets
/// and the same counters (tests and the fuzzer check this). The price: a
/// valid packet that carries a complete valid packet in its payload (a loop
/// echo of a packet) yields the inner packet only. WTS frames cannot do
/// this by accident: 12-bit taxels never contain AA AA.
///
/// Memory: the buffer holds at most one incomplete candidate plus the bytes
/// fed since (O(max_payload + chunk)). Time: O(bytes) per returned packet
/// plus a CRC per preamble seen inside a candidate. Not thread-safe.
class PacketFramer {
 public:
  /// Default bound on the payload size: 1024 bytes holds a frame of up to
  /// 509 taxels (a 14x6 frame is 173 bytes) and every reply.
  static constexpr std::size_t kDefaultMaxPayload = 1024;

  /// `max_payload` in [0, 65535]; throws InvalidArgument otherwise.
  explicit PacketFramer(std::size_t max_payload = kDefaultMaxPayload) : max_payload_(max_payload) {
    if (max_payload > kWtsMaxPayload)
      throw InvalidArgument("max_payload", std::to_string(max_payload) + " exceeds 65535");
  }

  /// Appends bytes. A feed after finish() starts a new stream.
  void feed(const std::uint8_t* data, std::size_t size) {
    if (finished_) finished_ = false;
    if (size == 0) return;
    compact();
    buffer_.insert(buffer_.end(), data, data + size);
    stats_.bytes_in += size;
  }

  /// Marks the end of the stream: incomplete candidates are abandoned and
  /// trailing bytes become junk, so next() drains every complete packet.
  void finish() noexcept { finished_ = true; }

  /// The next valid packet, or nothing until more bytes arrive. O(buffered
  /// bytes) per call.
  std::optional<RawPacket> next() {
    for (;;) {
      const std::size_t end = buffer_.size();
      const std::size_t start = find_preamble(begin_, end);
      drop(start - begin_);
      if (end - begin_ < kWtsHeaderSize) {
        if (finished_) drop(end - begin_);
        return std::nullopt;
      }
      const std::size_t size = get_u16(&buffer_[begin_ + 4]);
      if (size > max_payload_) {
        ++stats_.oversize;
        drop(1);
        continue;
      }
      const std::size_t total = kWtsHeaderSize + size + kWtsCrcSize;
      const std::size_t limit = std::min(end, begin_ + total);
      if (valid_packet_inside(begin_, limit)) {
        ++stats_.truncated;
        drop(1);
        continue;
      }
      if (limit - begin_ < total) {  // incomplete
        if (!finished_) return std::nullopt;
        ++stats_.truncated;
        drop(1);
        continue;
      }
      if (!crc_ok(begin_, total)) {
        ++stats_.crc_errors;
        drop(1);
        continue;
      }
      return take(total);
    }
  }

  /// Bytes received but not yet returned or dropped.
  std::size_t buffered() const noexcept { return buffer_.size() - begin_; }
  std::size_t max_payload() const noexcept { return max_payload_; }
  const FramerStats& stats() const noexcept { return stats_; }

  /// Forgets buffered bytes (counted as junk) and the finished mark; the
  /// counters stay.
  void reset() noexcept {
    drop(buffered());
    finished_ = false;
  }

 private:
  // First position in [from, end) where a preamble starts, or, when there
  // is none, the first position of a trailing partial preamble (or end).
  std::size_t find_preamble(std::size_t from, std::size_t end) const noexcept {
    std::size_t run = 0;
    for (std::size_t i = from; i < end; ++i) {
      run = buffer_[i] == kWtsPreambleByte ? run + 1 : 0;
      if (run == kWtsPreambleSize) return i + 1 - kWtsPreambleSize;
    }
    return end - run;
  }

  bool crc_ok(std::size_t pos, std::size_t total) const noexcept {
    return wts_crc16(&buffer_[pos], total - kWtsCrcSize) == get_u16(&buffer_[pos + total - kWtsCrcSize]);
  }

  // Whether a complete packet within the bound and with a valid CRC starts
  // in (pos, limit) and ends at or before `limit`.
  bool valid_packet_inside(std::size_t pos, std::size_t limit) const noexcept {
    for (std::size_t p = pos + 1; p + kWtsHeaderSize + kWtsCrcSize <= limit; ++p) {
      p = find_preamble(p, limit);
      if (p + kWtsHeaderSize + kWtsCrcSize > limit) return false;
      const std::size_t size = get_u16(&buffer_[p + 4]);
      const std::size_t total = kWtsHeaderSize + size + kWtsCrcSize;
      if (size <= max_payload_ && total <= limit - p && crc_ok(p, total)) return true;
    }
    return false;
  }

  RawPacket take(std::size_t total) {
    const std::size_t size = total - kWtsHeaderSize - kWtsCrcSize;
    RawPacket packet;
    packet.id = buffer_[begin_ + 3];
    const auto first = buffer_.begin() + static_cast<std::ptrdiff_t>(begin_ + kWtsHeaderSize);
    packet.payload.assign(first, first + static_cast<std::ptrdiff_t>(size));
    begin_ += total;
    ++stats_.packets;
    stats_.packet_bytes += total;
    return packet;
  }

  void drop(std::size_t n) noexcept {
    begin_ += n;
    stats_.junk_bytes += n;
  }

  void compact() {
    if (begin_ == 0) return;
    if (begin_ == buffer_.size()) {
      buffer_.clear();
    } else if (begin_ >= 4096 || begin_ * 2 >= buffer_.size()) {
      buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(begin_));
    } else {
      return;
    }
    begin_ = 0;
  }

  std::size_t max_payload_;
  std::vector<std::uint8_t> buffer_;
  std::size_t begin_ = 0;  // first unconsumed byte of buffer_
  bool finished_ = false;
  FramerStats stats_;
};

}  // namespace iclap::rig

// SPDX-License-Identifier: MIT
#pragma once

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
  std::uint64_t truncated = 0;     ///< candidates abandoned before they were complete
};

/// Splits a byte stream into WTS packets (see README, "Rig tools").
///
/// Bytes may arrive in any chunking. The framer looks for the preamble
/// AA AA AA, reads id and size, and returns the packet once its CRC checks.
/// It resynchronises on its own: a candidate with a bad CRC, or a header
/// announcing more than `max_payload` bytes, is dropped one byte at a time,
/// so a real packet that starts inside it is still found. A candidate that
/// is still incomplete is abandoned (counted in `truncated`) as soon as a
/// complete, CRC-valid packet starts after its preamble, so a corrupted size
/// field delays the stream by at most one packet instead of swallowing up to
/// 64 kB; `finish()` abandons whatever is incomplete at the end of a stream
/// (e.g. an unplug) and returns the complete packets buffered behind it.
///
/// Memory: the buffer holds at most one incomplete candidate plus the bytes
/// fed since (O(max_payload + chunk)). Not thread-safe.
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
      switch (check(begin_, end)) {
        case Candidate::kValid: return take();
        case Candidate::kBad:
          drop(1);
          continue;
        case Candidate::kIncomplete:
          if (finished_ || later_valid_packet()) {
            ++stats_.truncated;
            drop(1);
            continue;
          }
          return std::nullopt;
      }
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
  enum class Candidate { kValid, kBad, kIncomplete };

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

  // Classifies the candidate whose preamble starts at `pos`, counting
  // oversize headers and CRC errors when `count`.
  Candidate check(std::size_t pos, std::size_t end, bool count = true) {
    if (end - pos < kWtsHeaderSize) return Candidate::kIncomplete;
    const std::size_t size = get_u16(&buffer_[pos + 4]);
    if (size > max_payload_) {
      if (count) ++stats_.oversize;
      return Candidate::kBad;
    }
    const std::size_t total = kWtsHeaderSize + size + kWtsCrcSize;
    if (end - pos < total) return Candidate::kIncomplete;
    const std::uint16_t crc = wts_crc16(&buffer_[pos], total - kWtsCrcSize);
    if (crc != get_u16(&buffer_[pos + total - kWtsCrcSize])) {
      if (count) ++stats_.crc_errors;
      return Candidate::kBad;
    }
    return Candidate::kValid;
  }

  // Whether a complete, valid packet starts after the current candidate's
  // first byte (then the candidate cannot be a real packet in progress).
  bool later_valid_packet() {
    const std::size_t end = buffer_.size();
    for (std::size_t pos = begin_ + 1; pos + kWtsHeaderSize <= end; ++pos) {
      pos = find_preamble(pos, end);
      if (pos + kWtsHeaderSize > end) return false;
      if (check(pos, end, false) == Candidate::kValid) return true;
    }
    return false;
  }

  RawPacket take() {
    const std::size_t size = get_u16(&buffer_[begin_ + 4]);
    const std::size_t total = kWtsHeaderSize + size + kWtsCrcSize;
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

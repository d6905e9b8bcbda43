// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <queue>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "iclap/core/error.hpp"
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
/// echo of a packet) yields the inner packet only. In a WTS frame only the
/// 32-bit timestamp can hold AA AA AA (12-bit taxels never hold AA AA), so
/// a frame is lost this way only when its timestamp is 0x??AAAAAA or
/// 0xAAAAAA?? and the bytes after it also form a packet whose 16-bit CRC
/// checks, about once in 2^40 frames or fewer.
///
/// A feed() after finish() first settles the finished stream exactly as
/// next() would (complete packets are kept for next(), an incomplete tail is
/// dropped as `truncated`/junk), so the result does not depend on whether
/// next() was called in between.
///
/// Memory: the buffer holds at most one incomplete candidate plus the bytes
/// fed since (O(max_payload + chunk)), plus bookkeeping per preamble in it.
/// Time: O(bytes) per returned packet plus one CRC per preamble position,
/// computed once whatever the chunking and however many candidates enclose
/// it (junk of nested headers costs O(L^2) bytes hashed, not O(L^3)). Not
/// thread-safe.
class PacketFramer {
 public:
  /// Default bound on the payload size: 1024 bytes holds a frame of up to
  /// 509 taxels (a 14x6 frame is 173 bytes) and every reply.
  static constexpr std::size_t kDefaultMaxPayload = 1024;

  /// `max_payload` in [0, 65535]; throws InvalidArgument otherwise.
  explicit PacketFramer(std::size_t max_payload = kDefaultMaxPayload) : max_payload_(max_payload) {
    check_max_payload(max_payload);
  }

  /// Appends bytes. A feed after finish() starts a new stream: the finished
  /// one is settled first (its complete packets still come out of next(),
  /// its incomplete tail is dropped), whether or not next() ran in between.
  void feed(const std::uint8_t* data, std::size_t size) {
    if (finished_) {
      while (auto packet = next_in_buffer()) ready_.push_back(std::move(*packet));
      finished_ = false;
    }
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
    if (!ready_.empty()) {
      RawPacket packet = std::move(ready_.front());
      ready_.pop_front();
      return packet;
    }
    return next_in_buffer();
  }

  /// Bytes received but not yet returned or dropped.
  std::size_t buffered() const noexcept { return buffer_.size() - begin_; }
  std::size_t max_payload() const noexcept { return max_payload_; }
  const FramerStats& stats() const noexcept { return stats_; }
  /// CRCs computed so far (candidates and packets inside them): a work
  /// counter for tests, not part of the stream's accounting.
  std::uint64_t crc_computations() const noexcept { return crc_computations_; }

  /// Changes the payload bound from now on (same range as the constructor).
  /// Buffered bytes are judged again under the new bound.
  void set_max_payload(std::size_t max_payload) {
    check_max_payload(max_payload);
    if (max_payload == max_payload_) return;
    max_payload_ = max_payload;
    forget_inner();
  }

  /// Forgets buffered bytes (counted as junk) and the finished mark; the
  /// counters stay. Packets a feed() after finish() set aside for next()
  /// are kept (they are counted as packets already).
  void reset() noexcept {
    drop(buffered());
    finished_ = false;
    forget_inner();
  }

 private:
  static void check_max_payload(std::size_t max_payload) {
    if (max_payload > kWtsMaxPayload)
      throw InvalidArgument("max_payload", std::to_string(max_payload) + " exceeds 65535");
  }

  std::optional<RawPacket> next_in_buffer() {
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
      if (!candidate_crc_ok(total)) {
        ++stats_.crc_errors;
        drop(1);
        continue;
      }
      return take(total);
    }
  }

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

  bool crc_ok(std::size_t pos, std::size_t total) noexcept {
    ++crc_computations_;
    return wts_crc_matches(&buffer_[pos], total);
  }

  // The CRC check of the candidate at begin_ (complete, `total` bytes),
  // reusing the verdict if it was checked as a packet inside an earlier
  // candidate.
  bool candidate_crc_ok(std::size_t total) {
    const std::uint64_t at = base_ + begin_;
    const auto bad = inner_bad_crc_.find(at);
    if (bad != inner_bad_crc_.end()) {
      inner_bad_crc_.erase(inner_bad_crc_.begin(), std::next(bad));
      return false;
    }
    return crc_ok(begin_, total);
  }

  // Whether a complete packet within the bound and with a valid CRC starts
  // in (pos, limit) and ends at or before `limit` (pos is begin_).
  //
  // Each position is examined once: positions are scanned in order up to
  // the last one that can hold a packet ending by `limit` (scan_), a
  // preamble with a size within the bound waits in inner_waiting_ until its
  // announced end is within `limit`, then its CRC is computed once and a
  // valid one is kept in inner_valid_ (by end). Positions are absolute
  // stream offsets (base_ + index), so compaction does not move them, and
  // entries at or before begin_ are dropped lazily. A verdict depends only
  // on the bytes from the position to its announced end, which never change,
  // so this answers exactly as scanning every preamble in (pos, limit).
  bool valid_packet_inside(std::size_t pos, std::size_t limit) {
    const std::uint64_t first = base_ + pos + 1;
    const std::uint64_t abs_limit = base_ + limit;
    if (scan_ < first) scan_ = first;
    // (the verdict at pos itself is kept for candidate_crc_ok())
    inner_bad_crc_.erase(inner_bad_crc_.begin(), inner_bad_crc_.lower_bound(base_ + pos));
    for (; scan_ + kWtsHeaderSize + kWtsCrcSize <= abs_limit; ++scan_) {
      const std::size_t i = static_cast<std::size_t>(scan_ - base_);
      if (!is_wts_preamble(&buffer_[i])) continue;
      const std::size_t size = get_u16(&buffer_[i + 4]);
      if (size > max_payload_) continue;
      inner_waiting_.emplace(scan_ + kWtsHeaderSize + size + kWtsCrcSize, scan_);
    }
    while (!inner_waiting_.empty() && inner_waiting_.top().first <= abs_limit) {
      const auto [end, at] = inner_waiting_.top();
      inner_waiting_.pop();
      if (at < first) continue;  // dropped already
      if (crc_ok(static_cast<std::size_t>(at - base_), static_cast<std::size_t>(end - at)))
        inner_valid_.emplace(end, at);
      else
        inner_bad_crc_.insert(at);
    }
    while (!inner_valid_.empty()) {
      const auto& [end, at] = *inner_valid_.begin();
      if (at < first) {
        inner_valid_.erase(inner_valid_.begin());
        continue;
      }
      return end <= abs_limit;
    }
    return false;
  }

  // Forgets what valid_packet_inside() learnt (the bound changed, or the
  // buffer was emptied).
  void forget_inner() noexcept {
    inner_waiting_ = {};
    inner_valid_.clear();
    inner_bad_crc_.clear();
    scan_ = 0;
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
      forget_inner();  // every remembered position is behind begin_
    } else if (begin_ >= 4096 || begin_ * 2 >= buffer_.size()) {
      buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(begin_));
    } else {
      return;
    }
    base_ += begin_;
    begin_ = 0;
  }

  std::size_t max_payload_;
  std::vector<std::uint8_t> buffer_;
  std::size_t begin_ = 0;  // first unconsumed byte of buffer_
  std::uint64_t base_ = 0;  // stream offset of buffer_[0]
  bool finished_ = false;
  FramerStats stats_;
  std::deque<RawPacket> ready_;  // settled by a feed() after finish()
  // valid_packet_inside() memory, in stream offsets (see there).
  std::uint64_t scan_ = 0;
  using EndAt = std::pair<std::uint64_t, std::uint64_t>;  // (announced end, position)
  std::priority_queue<EndAt, std::vector<EndAt>, std::greater<EndAt>> inner_waiting_;
  std::set<EndAt> inner_valid_;
  std::set<std::uint64_t> inner_bad_crc_;
  std::uint64_t crc_computations_ = 0;
};

}  // namespace iclap::rig

// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <variant>

#include "iclap/core/error.hpp"
#include "iclap/rig/packet_framer.hpp"
#include "iclap/rig/wts_message.hpp"
#include "iclap/rig/wts_protocol.hpp"

namespace iclap::rig {

/// Counters of a WtsStreamParser: the framer's (junk, CRC errors, ...) plus
/// what happened to the valid packets.
struct ParserStats : FramerStats {
  std::uint64_t frames = 0;               ///< frames yielded
  std::uint64_t replies = 0;              ///< replies yielded
  std::uint64_t frames_wrong_shape = 0;   ///< valid frames whose taxel count is not the grid's (dropped)
  std::uint64_t frames_without_grid = 0;  ///< valid frames before any grid was known (dropped)
  std::uint64_t frames_out_of_range = 0;  ///< valid frames with a taxel above max_texel (dropped)
  std::uint64_t malformed = 0;            ///< valid packets too short for their kind (dropped)
  /// Taxel count of the last frame dropped for its shape (0 if none), so a
  /// tool can say "the sensor sends 100 taxels, the grid 14x6 has 84".
  std::uint64_t last_wrong_shape_taxels = 0;
};

/// Turns the sensor's byte stream into frames and replies.
///
/// Framing, resynchronisation and the payload bound are PacketFramer's.
/// Whenever a grid is set (override or matrix info), the bound is raised, if
/// needed, to that grid's frame payload (frame_payload_size(): 5 + 2 bytes a
/// taxel), so the frames of any grid the parser accepts fit; it is never
/// lowered. A grid whose frame cannot fit a WTS packet at all (more than
/// kMaxGridTaxels taxels) is refused.
/// Valid packets are decoded: id 0x00 is a frame (timestamp_ms:u32,
/// flags:u8, u16 taxels row-major), any other id a reply (status:u16,
/// payload). The grid comes from the latest successful, complete "get
/// matrix info" reply (rows = res_y, columns = res_x) whose grid is usable,
/// so a sensor queried again after a change is followed; a reply with an
/// unusable grid (a side of 0, too many taxels) updates `matrix_info()` and
/// leaves the grid as it was (`WtsSensor::query_matrix_info` refuses it).
/// `Settings::grid` overrides all of this: an override is never replaced by
/// the sensor's answer.
///
/// A frame whose taxel count differs from the grid's rows x cols is dropped
/// and counted (`frames_wrong_shape`, `last_wrong_shape_taxels`), never
/// reshaped or padded: a dataset row must hold exactly the grid's taxels,
/// and guessing a shape would put pressures in the wrong cells. A frame that
/// arrives before any grid is known is dropped and counted likewise
/// (`frames_without_grid`); query the matrix info (or set a grid) first.
/// Same-count transposes (res_x/res_y read the other way) cannot be told
/// apart on the wire; that is what the override is for.
///
/// A frame with a taxel above `max_texel` (default 4095: the WTS sends
/// 12-bit pressures) is dropped and counted (`frames_out_of_range`). This is
/// defence in depth: the protocol's CRC misses some two-bit errors (its
/// update step maps two states to one, e.g. the same bit flipped in two
/// bytes 13 apart cancels out), and a flipped high nibble is caught here.
///
/// Not thread-safe.
class WtsStreamParser {
 public:
  /// Most taxels a frame can carry: 5 + 2 x 32765 = 65535 payload bytes.
  static constexpr std::size_t kMaxGridTaxels = (kWtsMaxPayload - 5) / 2;

  /// Payload bytes of an uncompressed frame of `g`: timestamp, flags, taxels.
  /// Only for a grid of 1 to kMaxGridTaxels taxels.
  static std::size_t frame_payload_size(const Grid& g) noexcept {
    return 5 + 2 * static_cast<std::size_t>(g.rows) * static_cast<std::size_t>(g.cols);
  }

  struct Settings {
    /// Largest payload accepted; see PacketFramer. Raised to the grid's
    /// frame payload when a grid is set (see the class comment).
    std::size_t max_payload = PacketFramer::kDefaultMaxPayload;
    /// Grid override; when empty the matrix info reply decides.
    std::optional<Grid> grid;
    /// Largest plausible taxel value; 0xFFFF accepts everything.
    std::uint16_t max_texel = 4095;
  };

  WtsStreamParser() : WtsStreamParser(Settings{}) {}
  explicit WtsStreamParser(Settings settings)
      : framer_(settings.max_payload), grid_(settings.grid), grid_overridden_(settings.grid.has_value()),
        max_texel_(settings.max_texel) {
    if (grid_) {
      check_grid(*grid_);
      fit_bound(*grid_);
    }
  }

  /// Appends received bytes (any chunking). A feed after finish() starts a
  /// new stream; the finished one is decoded first (its messages still come
  /// out of next()), so the result does not depend on whether next() ran
  /// in between.
  void feed(const std::uint8_t* data, std::size_t size) {
    if (finished_) {
      while (auto m = decode_next()) {
        Decoded& d = ready_.emplace_back();
        if (auto* f = std::get_if<TactileFrame>(&*m)) {
          d.is_frame = true;
          d.frame = std::move(*f);
        } else {
          d.reply = std::move(std::get<Reply>(*m));
        }
      }
      finished_ = false;
    }
    framer_.feed(data, size);
  }
  void feed(const Bytes& bytes) { feed(bytes.data(), bytes.size()); }

  /// Marks the end of the stream (see PacketFramer::finish()).
  void finish() noexcept {
    finished_ = true;
    framer_.finish();
  }

  /// The next frame or reply, or nothing until more bytes arrive.
  std::optional<WtsMessage> next() {
    if (!ready_.empty()) {
      std::optional<WtsMessage> m;
      Decoded& d = ready_.front();
      if (d.is_frame)
        m.emplace(std::in_place_type<TactileFrame>, std::move(d.frame));
      else
        m.emplace(std::in_place_type<Reply>, std::move(d.reply));
      ready_.pop_front();
      return m;
    }
    return decode_next();
  }

  /// The grid frames are decoded with, if known.
  const std::optional<Grid>& grid() const noexcept { return grid_; }
  /// Whether the grid was set by the caller (then replies do not change it).
  bool grid_overridden() const noexcept { return grid_overridden_; }
  /// Overrides the grid from now on. Throws InvalidArgument for an empty
  /// grid or one of more than kMaxGridTaxels taxels.
  void set_grid(const Grid& grid) {
    check_grid(grid);
    fit_bound(grid);
    grid_ = grid;
    grid_overridden_ = true;
  }
  /// The last successful matrix info reply seen, if any.
  const std::optional<MatrixInfo>& matrix_info() const noexcept { return matrix_info_; }

  ParserStats stats() const noexcept {
    ParserStats s = counts_;
    static_cast<FramerStats&>(s) = framer_.stats();
    return s;
  }
  std::size_t buffered() const noexcept { return framer_.buffered(); }
  /// The payload bound in force (Settings::max_payload, raised for the grid).
  std::size_t max_payload() const noexcept { return framer_.max_payload(); }

 private:
  static bool usable_grid(const Grid& g) noexcept {
    // Bounded side by side: rows * cols of a grid set in code could overflow.
    return g.rows >= 1 && g.cols >= 1 && static_cast<std::size_t>(g.cols) <= kMaxGridTaxels / static_cast<std::size_t>(g.rows);
  }
  static void check_grid(const Grid& g) {
    if (!usable_grid(g))
      throw InvalidArgument("grid", to_string(g) + " is not a grid of 1 to " + std::to_string(kMaxGridTaxels) +
                                        " taxels (a frame of more does not fit a WTS packet)");
  }
  // Raises the framer's payload bound so that frames of `g` fit.
  void fit_bound(const Grid& g) {
    const std::size_t needed = frame_payload_size(g);
    if (needed > framer_.max_payload()) framer_.set_max_payload(needed);
  }

  std::optional<WtsMessage> decode_next() {
    while (auto packet = framer_.next()) {
      std::optional<WtsMessage> message;
      if (packet->id == wts_id::kFrameData) {
        auto& frame = std::get<TactileFrame>(message.emplace(std::in_place_type<TactileFrame>));
        if (decode_frame(packet->payload, frame)) return message;
      } else {
        auto& reply = std::get<Reply>(message.emplace(std::in_place_type<Reply>));
        if (decode_reply(*packet, reply)) return message;
      }
    }
    return std::nullopt;
  }

  // Fills `frame` and returns true, or counts the drop and returns false.
  bool decode_frame(const Bytes& payload, TactileFrame& frame) {
    constexpr std::size_t kHead = 5;  // timestamp u32, flags u8
    if (payload.size() < kHead || (payload.size() - kHead) % 2 != 0) {
      ++counts_.malformed;
      return false;
    }
    const std::size_t taxels = (payload.size() - kHead) / 2;
    if (!grid_) {
      ++counts_.frames_without_grid;
      return false;
    }
    if (taxels != static_cast<std::size_t>(grid_->size())) {
      ++counts_.frames_wrong_shape;
      counts_.last_wrong_shape_taxels = taxels;
      return false;
    }
    frame.timestamp_ms = get_u32(payload.data());
    frame.flags = payload[4];
    frame.texels.resize(grid_->rows, grid_->cols);
    const std::uint8_t* p = payload.data() + kHead;
    std::uint16_t* out = frame.texels.data();  // row-major, like the wire
    std::uint16_t largest = 0;
    for (std::size_t i = 0; i < taxels; ++i) {
      out[i] = get_u16(p + 2 * i);
      largest = std::max(largest, out[i]);
    }
    if (largest > max_texel_) {
      ++counts_.frames_out_of_range;
      return false;
    }
    ++counts_.frames;
    return true;
  }

  bool decode_reply(RawPacket& packet, Reply& reply) {
    if (packet.payload.size() < 2) {
      ++counts_.malformed;
      return false;
    }
    reply.id = packet.id;
    reply.status = get_u16(packet.payload.data());
    reply.payload.assign(packet.payload.begin() + 2, packet.payload.end());
    if (reply.id == wts_id::kGetMatrixInfo && reply.ok() && reply.payload.size() >= 10) {
      const MatrixInfo info = decode_matrix_info(reply);
      matrix_info_ = info;
      const Grid g = info.grid();
      if (!grid_overridden_ && usable_grid(g)) {
        fit_bound(g);
        grid_ = g;
      }
    }
    ++counts_.replies;
    return true;
  }

  PacketFramer framer_;
  std::optional<Grid> grid_;
  bool grid_overridden_ = false;
  std::optional<MatrixInfo> matrix_info_;
  std::uint16_t max_texel_;
  ParserStats counts_;
  // A message decoded by a feed() after finish(), kept for next() (not a
  // WtsMessage: moving that variant trips GCC's maybe-uninitialized).
  struct Decoded {
    bool is_frame = false;
    TactileFrame frame;
    Reply reply;
  };
  bool finished_ = false;
  std::deque<Decoded> ready_;
};

}  // namespace iclap::rig

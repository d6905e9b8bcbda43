// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <variant>

#include "iclap/core/error.hpp"
#include "iclap/rig/byte_stream.hpp"
#include "iclap/rig/stream_parser.hpp"
#include "iclap/rig/wts_message.hpp"
#include "iclap/rig/wts_protocol.hpp"

namespace iclap::rig {

/// The sensor answered a command with a non-zero status.
class WtsCommandError : public Error {
 public:
  WtsCommandError(std::uint8_t id, std::uint16_t status)
      : Error("sensor refused '" + wts_command_name(id) + "' with status " + std::to_string(status)),
        id_(id),
        status_(status) {}
  std::uint8_t id() const noexcept { return id_; }
  std::uint16_t status() const noexcept { return status_; }

 private:
  std::uint8_t id_;
  std::uint16_t status_;
};

/// The sensor did not answer a command in time (after every attempt).
class WtsTimeout : public Error {
 public:
  using Error::Error;
};

/// A conversation with a WTS sensor over any ByteStream: commands with
/// their replies, and the stream of frames.
///
/// Replies are matched to commands by id; frames that arrive while a reply
/// is awaited are queued (up to `Settings::max_queued_frames`, oldest
/// dropped first and counted) and returned by next_frame() in order.
/// Replies nobody waits for are ignored. The protocol numbers no request,
/// so a reply that comes after its attempt timed out (and the command was
/// sent again) is taken as the answer to the next request with that id:
/// keep `reply_timeout` above the sensor's slowest answer (a WTS answers in
/// milliseconds; the default waits a second).
///
/// Device loss: when the stream reports DeviceLost, the parser is finished
/// and every frame received intact before the loss is still returned by
/// next_frame(); only then is DeviceLost rethrown. So a consumer that reads
/// until DeviceLost records every intact frame that reached the host.
///
/// The destructor sends "stop periodic frames" if this object started
/// them and the stream is still open (no wait, errors ignored), so a sensor
/// is not left streaming after an exception. Not thread-safe. The stream
/// must outlive the sensor.
class WtsSensor {
 public:
  struct Settings {
    std::chrono::milliseconds reply_timeout{1000};  ///< per attempt
    int attempts = 3;                               ///< sends of a command before WtsTimeout
    std::size_t max_queued_frames = 10000;          ///< frames kept while nobody reads (at least 1)
    WtsStreamParser::Settings parser;               ///< payload bound, grid override, max taxel
  };

  explicit WtsSensor(ByteStream& stream) : WtsSensor(stream, Settings{}) {}
  WtsSensor(ByteStream& stream, Settings settings)
      : stream_(stream), settings_(settings), parser_(settings.parser) {
    if (settings_.attempts < 1) throw InvalidArgument("settings.attempts", "must be at least 1");
    if (settings_.reply_timeout.count() < 1) throw InvalidArgument("settings.reply_timeout", "must be positive");
    if (settings_.max_queued_frames < 1)
      throw InvalidArgument("settings.max_queued_frames", "must be at least 1, got 0");
  }
  WtsSensor(const WtsSensor&) = delete;
  WtsSensor& operator=(const WtsSensor&) = delete;

  ~WtsSensor() {
    if (!streaming_ || lost_ || !stream_.is_open()) return;
    try {
      const Bytes stop = encode_stop_periodic_frames();
      stream_.write(stop.data(), stop.size(), std::chrono::milliseconds(200));
    } catch (...) {
      // Best effort: the device may be gone.
    }
  }

  /// Sends `command` (one packet from wts_protocol.hpp) and returns the
  /// reply with the same id, whatever its status. Retries on silence, then
  /// throws WtsTimeout naming the command. DeviceLost passes through.
  /// Throws InvalidArgument, sending nothing, if `command` is not exactly one
  /// packet (preamble, size field matching its length, CRC).
  Reply request(const Bytes& command) {
    if (!is_wts_packet(command.data(), command.size()))
      throw InvalidArgument("command", "is not an encoded WTS packet");
    const std::uint8_t id = command[3];
    for (int attempt = 0; attempt < settings_.attempts; ++attempt) {
      throw_if_lost();
      stream_.write(command.data(), command.size(), settings_.reply_timeout);
      const auto deadline = deadline_after(settings_.reply_timeout);
      for (;;) {
        while (auto m = parser_.next()) {
          if (auto* f = std::get_if<TactileFrame>(&*m)) {
            enqueue(std::move(*f));
          } else {
            auto& r = std::get<Reply>(*m);
            if (r.id == id) return std::move(r);
          }
        }
        const auto left = deadline - std::chrono::steady_clock::now();
        if (left <= std::chrono::steady_clock::duration::zero()) break;
        if (!pump(std::chrono::duration_cast<std::chrono::milliseconds>(left) + std::chrono::milliseconds(1)))
          throw_if_lost();
      }
    }
    throw WtsTimeout(stream_.name() + ": no reply to '" + wts_command_name(id) + "' after " +
                     std::to_string(settings_.attempts) + " attempt(s) of " +
                     std::to_string(settings_.reply_timeout.count()) + " ms");
  }

  /// request(), then WtsCommandError unless the status is 0.
  Reply request_ok(const Bytes& command) {
    Reply r = request(command);
    if (!r.ok()) throw WtsCommandError(r.id, r.status);
    return r;
  }

  /// Asks for the matrix info; the parser takes its grid from it unless a
  /// grid override was given.
  /// Throws InvalidArgument ("matrix info") when there is no override and
  /// the reported grid is unusable (a side of 0, or more taxels than a
  /// frame can carry), so callers never face a sensor without a grid.
  MatrixInfo query_matrix_info() {
    const MatrixInfo info = decode_matrix_info(request_ok(encode_get_matrix_info()));
    if (!parser_.grid_overridden() && (!parser_.grid() || *parser_.grid() != info.grid()))
      throw InvalidArgument("matrix info", "the sensor reports res_x=" + std::to_string(info.res_x) +
                                               ", res_y=" + std::to_string(info.res_y) + ", not a grid of 1 to " +
                                               std::to_string(WtsStreamParser::kMaxGridTaxels) + " taxels");
    return info;
  }

  /// Starts periodic frames at `rate` frames/s (delay_ms = 1000 / rate).
  /// Frames queued before the start command are discarded: they belong to
  /// an earlier stream (e.g. a sensor left streaming by a crashed run; stop
  /// it first so its frames are consumed before this call).
  void start_periodic_frames(double rate) {
    const std::uint16_t delay = delay_ms_for_rate(rate);
    discard_frames();
    // Streaming from the moment the command may have reached the sensor: a
    // start whose reply timed out may have started it, and the destructor
    // must then stop it. A refusal (the sensor answered) changed nothing.
    const bool was_streaming = streaming_;
    streaming_ = true;
    try {
      request_ok(encode_start_periodic_frames(delay));
    } catch (const WtsCommandError&) {
      streaming_ = was_streaming;
      throw;
    }
  }

  /// Stops periodic frames. Returns whether the sensor acknowledged (a
  /// silent sensor is not an error here: this also runs on the way out).
  /// Until it does, the sensor counts as streaming, so the destructor sends
  /// the stop again. Frames already queued stay queued. DeviceLost passes
  /// through.
  bool stop_periodic_frames() {
    try {
      request_ok(encode_stop_periodic_frames());
      streaming_ = false;
      return true;
    } catch (const WtsTimeout&) {
      return false;
    } catch (const WtsCommandError&) {
      return false;
    }
  }

  /// The next frame, waiting at most `timeout`; nothing on timeout (or when
  /// a signal interrupted the wait). The stream is read at least once, so a
  /// zero timeout polls: it returns a frame whose bytes have arrived.
  /// Throws DeviceLost once every frame received before a loss has been
  /// returned.
  std::optional<TactileFrame> next_frame(std::chrono::milliseconds timeout) {
    const auto deadline = deadline_after(timeout);
    for (bool read_once = false;; read_once = true) {
      while (queue_.empty()) {
        auto m = parser_.next();
        if (!m) break;
        if (auto* f = std::get_if<TactileFrame>(&*m)) enqueue(std::move(*f));
      }
      if (!queue_.empty()) {
        TactileFrame f = std::move(queue_.front());
        queue_.pop_front();
        return f;
      }
      throw_if_lost();
      const auto left = deadline - std::chrono::steady_clock::now();
      const bool expired = left <= std::chrono::steady_clock::duration::zero();
      if (expired && read_once) return std::nullopt;
      const auto wait = expired ? std::chrono::milliseconds(0)
                                : std::chrono::duration_cast<std::chrono::milliseconds>(left) +
                                      std::chrono::milliseconds(1);
      if (!pump(wait) && !lost_) return std::nullopt;  // timeout or signal
    }
  }

  /// Drops every queued frame (returns how many).
  std::size_t discard_frames() noexcept {
    const std::size_t n = queue_.size();
    queue_.clear();
    return n;
  }

  /// The grid frames are decoded with (after query_matrix_info() or an override).
  const std::optional<Grid>& grid() const noexcept { return parser_.grid(); }
  const WtsStreamParser& parser() const noexcept { return parser_; }
  ParserStats stats() const noexcept { return parser_.stats(); }
  /// Frames dropped because the queue was full.
  std::uint64_t frames_overflowed() const noexcept { return overflowed_; }
  /// Whether the sensor may be streaming frames this object started: from
  /// start_periodic_frames() (even one that timed out) until a stop the
  /// sensor acknowledged, or the loss of the device.
  bool streaming() const noexcept { return streaming_; }
  /// Whether the device was lost (the message of the loss in lost_reason()).
  bool lost() const noexcept { return lost_.has_value(); }
  std::string lost_reason() const { return lost_ ? lost_->what() : std::string(); }
  ByteStream& stream() noexcept { return stream_; }

 private:
  // Reads once (up to `timeout`) and feeds the parser. Returns whether any
  // byte arrived. On DeviceLost, finishes the parser and remembers the loss.
  bool pump(std::chrono::milliseconds timeout) {
    if (lost_) return false;
    try {
      const std::size_t n = stream_.read(buffer_.data(), buffer_.size(), timeout);
      parser_.feed(buffer_.data(), n);
      return n > 0;
    } catch (const DeviceLost& e) {
      lost_.emplace(e);
      streaming_ = false;
      parser_.finish();
      return false;
    }
  }

  void throw_if_lost() const {
    if (lost_) throw *lost_;
  }

  void enqueue(TactileFrame&& f) {
    if (queue_.size() >= settings_.max_queued_frames) {
      queue_.pop_front();
      ++overflowed_;
    }
    queue_.push_back(std::move(f));
  }

  ByteStream& stream_;
  Settings settings_;
  WtsStreamParser parser_;
  std::deque<TactileFrame> queue_;
  std::array<std::uint8_t, 4096> buffer_{};
  std::optional<DeviceLost> lost_;
  bool streaming_ = false;
  std::uint64_t overflowed_ = 0;
};

}  // namespace iclap::rig

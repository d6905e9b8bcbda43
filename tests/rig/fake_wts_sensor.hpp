// SPDX-License-Identifier: MIT
#pragma once
// A fake WTS sensor speaking the wire protocol on a pseudo-terminal, so the
// serial transport, the sensor session and `iclap record` are tested end to
// end through a real OS serial device. The sensor runs in a thread on the
// pty's master side; the code under test opens the slave path like a
// /dev/ttyACM* port.
//
// Frames are deterministic: frame `seq` has timestamp 1000 + 200 * seq ms,
// taxel (0,0) = seq % 4096, (0,1) = seq / 4096 and the other taxels drawn
// from Rng::derive(seed, seq), so a test can recompute every frame from the
// sequence numbers the fake reports as sent intact.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <limits>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/rig/packet_framer.hpp"
#include "iclap/rig/wts_message.hpp"
#include "iclap/rig/wts_protocol.hpp"
#include "pty_port.hpp"

namespace iclap::rig::test {

/// What the fake sensor does.
struct FakeSensorScript {
  MatrixInfo info{6, 14, 340, 340, 4095};  ///< what it answers to get matrix info
  bool answer_matrix_info = true;
  std::uint64_t seed = 1;
  int frame_interval_ms = 4;  ///< real pacing (tests run faster than the requested delay)
  std::size_t max_frames = std::numeric_limits<std::size_t>::max();  ///< frames per session, then silence
  std::size_t unplug_after = std::numeric_limits<std::size_t>::max();  ///< close the master after this many frames
  std::size_t corrupt_every = 0;   ///< every k-th frame (k > 0) gets one flipped bit
  std::size_t junk_every = 0;      ///< every k-th frame is preceded by junk bytes
  bool streaming_at_connect = false;  ///< already streaming (left over from a crashed run)
  std::size_t first_seq = 0;       ///< sequence number of the first frame
  std::size_t reset_after = 0;     ///< after this many frames (> 0), restart at sequence 0 (a sensor reset)
};

/// The frame the fake sends as number `seq`.
inline TactileFrame fake_frame(std::uint64_t seed, std::size_t seq, const Grid& grid) {
  TactileFrame f;
  f.timestamp_ms = static_cast<std::uint32_t>(1000 + 200 * seq);
  f.flags = 0;
  f.texels.resize(grid.rows, grid.cols);
  Rng rng = Rng::derive(seed, seq);
  for (Index i = 0; i < f.texels.size(); ++i) f.texels.data()[i] = static_cast<std::uint16_t>(rng.below(4096));
  f.texels.data()[0] = static_cast<std::uint16_t>(seq % 4096);
  if (f.texels.size() > 1) f.texels.data()[1] = static_cast<std::uint16_t>((seq / 4096) % 4096);
  return f;
}

/// The sequence number encoded in a recorded frame's pressures.
inline std::size_t fake_frame_seq(double p00, double p01) {
  return static_cast<std::size_t>(p00) + 4096 * static_cast<std::size_t>(p01);
}

/// The fake sensor on a pseudo-terminal, in its own thread.
class PtyFakeSensor {
 public:
  explicit PtyFakeSensor(FakeSensorScript script) : script_(script), seq_(script.first_seq) {
    streaming_ = script_.streaming_at_connect;
    thread_ = std::thread([this] { run(); });
  }
  ~PtyFakeSensor() {
    quit_ = true;
    if (thread_.joinable()) thread_.join();
  }
  PtyFakeSensor(const PtyFakeSensor&) = delete;
  PtyFakeSensor& operator=(const PtyFakeSensor&) = delete;

  /// The slave device path (/dev/pts/N), to open like /dev/ttyACM0.
  const std::string& path() const { return port_.path(); }

  /// Frames sent intact / corrupted since the last start command (sequence numbers).
  std::vector<std::size_t> intact() const { return locked(intact_); }
  std::vector<std::size_t> corrupted() const { return locked(corrupted_); }
  /// Frames sent before any start command (a stream left over from before).
  std::size_t stale_frames() const { return stale_; }
  /// Packets received from the host (id and payload), in order.
  std::vector<RawPacket> commands() const { return locked(commands_); }
  std::vector<std::uint8_t> command_ids() const {
    std::vector<std::uint8_t> ids;
    for (const auto& c : commands()) ids.push_back(c.id);
    return ids;
  }
  bool unplugged() const { return unplugged_; }
  bool streaming() const { return streaming_; }

  /// Waits until `pred()` holds or `timeout` passes; returns pred().
  template <class Pred>
  bool wait_for(Pred pred, std::chrono::milliseconds timeout = std::chrono::milliseconds(10000)) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!pred() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    return pred();
  }

 private:
  template <class T>
  T locked(const T& v) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return v;
  }

  void run() {
    using clock = std::chrono::steady_clock;
    auto next_frame = clock::now();
    Rng damage = Rng::derive(script_.seed, 0xDA11A6E);
    std::uint8_t buf[512];
    while (!quit_ && port_.is_open()) {
      port_.flush();
      if (const std::size_t n = port_.read(buf, sizeof buf, std::chrono::milliseconds(2))) {
        framer_.feed(buf, n);
        while (auto packet = framer_.next()) handle(*packet);
      }
      const bool may_send = port_.drained() && sent_in_session_ < script_.max_frames;
      if (streaming_ && may_send && clock::now() >= next_frame) {
        next_frame = clock::now() + std::chrono::milliseconds(script_.frame_interval_ms);
        send_frame(damage);
        if (frames_total_ >= script_.unplug_after) {
          unplug();
          return;
        }
      }
    }
  }

  void handle(const RawPacket& packet) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      commands_.push_back(packet);
    }
    Reply reply{packet.id, 0, {}};
    switch (packet.id) {
      case wts_id::kGetMatrixInfo:
        if (!script_.answer_matrix_info) return;
        reply.payload = encode_matrix_info_payload(script_.info);
        break;
      case wts_id::kStartPeriodicFrames:
        if (packet.payload.size() != 3) {
          reply.status = 4;  // command format error
          break;
        }
        {
          std::lock_guard<std::mutex> lock(mutex_);
          intact_.clear();
          corrupted_.clear();
        }
        sent_in_session_ = 0;
        started_ = true;
        streaming_ = true;
        break;
      case wts_id::kStopPeriodicFrames: streaming_ = false; break;
      case wts_id::kLoop: reply.payload = packet.payload; break;
      case wts_id::kTare:
      case wts_id::kReadSingleFrame:
      case wts_id::kSetThreshold:
      case wts_id::kSetFrontEndGain: break;
      default: reply.status = 3;  // unknown command
    }
    port_.queue(encode_reply(reply));
  }

  void send_frame(Rng& damage) {
    if (script_.reset_after && frames_total_ == script_.reset_after) seq_ = 0;
    const std::size_t seq = seq_++;
    ++frames_total_;
    ++sent_in_session_;
    const Grid grid = script_.info.grid();
    Bytes packet = encode_frame(fake_frame(script_.seed, seq, grid));
    const std::size_t k = frames_total_;
    if (script_.junk_every && k % script_.junk_every == 0) {
      Bytes junk(1 + damage.below(40));
      for (auto& b : junk) b = damage.below(3) == 0 ? 0xAA : static_cast<std::uint8_t>(damage.below(256));
      port_.queue(junk);
    }
    const bool corrupt = script_.corrupt_every && k % script_.corrupt_every == 0;
    if (corrupt) {
      // One flipped bit after the preamble: the CRC catches every single-bit error.
      const std::size_t at = 3 + damage.below(packet.size() - 3);
      packet[at] ^= static_cast<std::uint8_t>(1u << damage.below(8));
    }
    {  // bookkeeping first: the host may see the frame as soon as it is written
      std::lock_guard<std::mutex> lock(mutex_);
      if (!started_) ++stale_;
      else (corrupt ? corrupted_ : intact_).push_back(seq);
    }
    port_.queue(packet);
    port_.flush(std::chrono::milliseconds(2000));
  }

  // Closes the port once the host has read what was sent: the test checks
  // that everything that reached the host is recorded.
  void unplug() {
    port_.unplug([this] { unplugged_ = true; });
  }

  FakeSensorScript script_;
  PtyPort port_;
  std::thread thread_;
  std::atomic<bool> quit_{false};
  std::atomic<bool> streaming_{false};
  std::atomic<bool> unplugged_{false};
  std::atomic<std::size_t> stale_{0};
  bool started_ = false;
  std::size_t seq_ = 0;
  std::size_t frames_total_ = 0;
  std::size_t sent_in_session_ = 0;
  PacketFramer framer_;
  mutable std::mutex mutex_;
  std::vector<std::size_t> intact_;
  std::vector<std::size_t> corrupted_;
  std::vector<RawPacket> commands_;
};

}  // namespace iclap::rig::test

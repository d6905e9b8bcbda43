// SPDX-License-Identifier: MIT
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "iclap/core/error.hpp"
#include "iclap/rig/frame_source.hpp"
#include "iclap/rig/pose_source.hpp"
#include "iclap/rig/wts_sensor.hpp"

namespace iclap::rig {

/// Frames from a WTS sensor, each paired with the pose its PoseSource gives
/// at the moment the frame is decoded (so the pose lags the touch by the
/// transport latency, a few milliseconds over USB). `time` is the sensor's
/// timestamp in seconds, unwrapped: the sensor counts milliseconds in 32
/// bits, which wrap every 49.7 days, so each frame adds its distance from
/// the previous one modulo 2^32 and time never runs backwards across a
/// wrap. A clock that steps back (by more than 2^31 ms modulo 2^32: a
/// sensor reset) is taken as no time passed and counted (clock_resets()).
/// Ends (kEnd) when the pose
/// source is exhausted.
///
/// The sensor must already know its grid (query_matrix_info() or an
/// override) and is started/stopped by the caller; sensor and pose source
/// must outlive this object. Not thread-safe.
class SensorFrameSource final : public FrameSource {
 public:
  /// Throws InvalidArgument ("sensor") if the sensor has no grid yet.
  SensorFrameSource(WtsSensor& sensor, PoseSource& poses) : sensor_(sensor), poses_(poses) {
    if (!sensor_.grid()) throw InvalidArgument("sensor", "has no grid yet: query its matrix info or set a grid first");
    grid_ = *sensor_.grid();
  }

  Status next(PosedFrame& out, std::chrono::milliseconds timeout) override {
    if (ended_) return Status::kEnd;
    auto frame = sensor_.next_frame(timeout);
    if (!frame) return Status::kTimeout;
    auto pose = poses_.next();
    if (!pose) {
      ended_ = true;
      return Status::kEnd;
    }
    out.pressures = frame->pressures();
    out.pose = std::move(*pose);
    if (!started_) {
      elapsed_ms_ = frame->timestamp_ms;
      started_ = true;
    } else {
      const std::uint32_t step = frame->timestamp_ms - last_timestamp_ms_;  // modulo 2^32
      if (step < 0x80000000u)
        elapsed_ms_ += step;
      else
        ++clock_resets_;
    }
    out.time = static_cast<double>(elapsed_ms_) / 1000.0;  // correctly rounded: 1400 ms -> 1.4
    last_timestamp_ms_ = frame->timestamp_ms;
    return Status::kFrame;
  }

  Grid grid() const override { return grid_; }
  bool has_time() const override { return true; }
  bool has_orientation() const override { return poses_.has_orientation(); }
  std::string description() const override {
    return "WTS sensor on " + sensor_.stream().name() + ", poses: " + poses_.description();
  }
  /// Sensor timestamp of the last frame returned (ms).
  std::uint32_t last_timestamp_ms() const noexcept { return last_timestamp_ms_; }
  /// How many times the sensor clock stepped back (a reset) between two
  /// frames returned so far; each such step added no time. A recorder can
  /// compare it before and after next() to say where a reset happened.
  std::uint64_t clock_resets() const noexcept { return clock_resets_; }

 private:
  WtsSensor& sensor_;
  PoseSource& poses_;
  Grid grid_;
  bool ended_ = false;
  std::uint32_t last_timestamp_ms_ = 0;
  bool started_ = false;
  std::uint64_t elapsed_ms_ = 0;  // the unwrapped clock; exact in a double for 285 000 years
  std::uint64_t clock_resets_ = 0;
};

}  // namespace iclap::rig

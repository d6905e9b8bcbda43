// SPDX-License-Identifier: MIT
#pragma once

#include <chrono>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "iclap/rig/pose_source.hpp"
#include "iclap/rig/wts_message.hpp"

namespace iclap::rig {

/// One touch sample: what the pad felt and where it was.
struct PosedFrame {
  Eigen::MatrixXd pressures;  ///< rows x cols, the sensor's raw units, >= 0
  Pose pose;                  ///< pad pose when the frame arrived
  std::optional<double> time; ///< seconds (sensor clock for a device, `t` for a replay)
};

/// A source of (tactile frame, pose) pairs: the live sensor with a pose
/// source (SensorFrameSource), a replayed dataset (DatasetFrameSource), a
/// simulator. The recorder (`iclap record`) and live recognition consume
/// this interface only.
///
/// next() waits at most `timeout`: kFrame fills `out`; kTimeout means
/// nothing yet (also returned when a signal interrupts the wait, so callers
/// can check a stop flag); kEnd means the source is exhausted for good. A
/// device source throws DeviceLost (byte_stream.hpp) once every frame that
/// reached the host intact has been returned. grid(), has_time() and
/// has_orientation() are fixed once the source is constructed. Not
/// thread-safe.
class FrameSource {
 public:
  enum class Status { kFrame, kTimeout, kEnd };
  virtual ~FrameSource() = default;
  virtual Status next(PosedFrame& out, std::chrono::milliseconds timeout) = 0;
  virtual Grid grid() const = 0;
  virtual bool has_time() const = 0;
  virtual bool has_orientation() const = 0;
  /// A short description for logs and dataset comments.
  virtual std::string description() const = 0;
};

}  // namespace iclap::rig

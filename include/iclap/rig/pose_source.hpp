// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <charconv>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iclap/core/error.hpp"
#include "iclap/data/dataset.hpp"

namespace iclap::rig {

/// Where the sensor pad is: its centre in the world frame (metres) and,
/// when the source knows it, its orientation (unit quaternion).
struct Pose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::optional<Eigen::Quaterniond> orientation;
};

/// Checks a pose: finite position, unit quaternion (|q| within 1e-6 of 1).
/// Throws InvalidArgument naming `argument` and the value.
inline void check_pose(const Pose& pose, const std::string& argument) {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(pose.position[i]))
      throw InvalidArgument(argument, "position coordinate " + std::to_string(i) + " is not finite");
  if (pose.orientation) {
    const double n = pose.orientation->norm();
    if (!std::isfinite(n) || std::abs(n - 1.0) > 1e-6)
      throw InvalidArgument(argument, "orientation quaternion has norm " + format_exact(n) + ", expected 1 within 1e-6");
  }
}

/// Where poses come from when frames are recorded: the arm's encoders, a
/// fixed jig, a replayed file, a simulator. One interface so the recorder
/// and live recognition do not care which.
///
/// next() is called once per tactile frame, when the frame arrives, and
/// returns the pose to pair with it, or nothing when the source is exhausted
/// (a replay at its end), which ends a recording. Throws on device errors.
/// has_orientation() is fixed for the source's lifetime, so writers can
/// choose their columns up front. Not thread-safe unless stated.
class PoseSource {
 public:
  virtual ~PoseSource() = default;
  virtual std::optional<Pose> next() = 0;
  virtual bool has_orientation() const = 0;
  /// A short description for logs and dataset comments ("fixed 0.1,0.2,0.3"),
  /// on one line.
  virtual std::string description() const = 0;
};

/// The same pose for every frame: a sensor on a fixed jig, or a rig without
/// an arm.
class FixedPoseSource final : public PoseSource {
 public:
  /// Throws InvalidArgument ("pose") for a non-finite position or a
  /// non-unit quaternion.
  explicit FixedPoseSource(Pose pose) : pose_(std::move(pose)) { check_pose(pose_, "pose"); }
  std::optional<Pose> next() override { return pose_; }
  bool has_orientation() const override { return pose_.orientation.has_value(); }
  std::string description() const override {
    const auto num = [](double v) { return format_exact(v); };
    std::string d = "fixed " + num(pose_.position.x()) + "," + num(pose_.position.y()) + "," + num(pose_.position.z());
    if (pose_.orientation) {
      const auto& q = *pose_.orientation;
      d += "," + num(q.w()) + "," + num(q.x()) + "," + num(q.y()) + "," + num(q.z());
    }
    return d;
  }

 private:
  Pose pose_;
};

/// Poses in order, one per call, then nothing: e.g. the poses of a recorded
/// dataset, to re-record a touch sequence on the real sensor.
class ReplayPoseSource final : public PoseSource {
 public:
  /// Throws EmptyInput for no poses, InvalidArgument ("poses") for a bad
  /// pose (naming its index) or a mix of poses with and without orientation.
  ReplayPoseSource(std::vector<Pose> poses, std::string description)
      : poses_(std::move(poses)), description_(std::move(description)) {
    if (poses_.empty()) throw EmptyInput("poses", "has no poses to replay");
    orientation_ = poses_.front().orientation.has_value();
    for (std::size_t i = 0; i < poses_.size(); ++i) {
      check_pose(poses_[i], "poses[" + std::to_string(i) + "]");
      if (poses_[i].orientation.has_value() != orientation_)
        throw InvalidArgument("poses", "pose " + std::to_string(i) + " differs from pose 0 in having an orientation");
    }
  }

  /// The positions (and orientations) of `dataset`'s frames in file order.
  static ReplayPoseSource from_dataset(const Dataset& dataset, const std::string& name) {
    std::vector<Pose> poses;
    poses.reserve(dataset.frames.size());
    // The reader accepts quaternions within 1e-3 of unit norm (4 printed
    // digits); poses are unit to 1e-6, so they are normalised here.
    for (const auto& f : dataset.frames)
      poses.push_back(Pose{f.position, f.orientation ? std::optional<Eigen::Quaterniond>(f.orientation->normalized())
                                                     : std::nullopt});
    if (poses.empty()) throw EmptyInput(name, "has no frames to replay poses from");
    // Quoted: a file name may hold a line break, which no dataset comment
    // may (the recorder writes the description into one).
    return ReplayPoseSource(std::move(poses), "replay of " + quote_text(name));
  }

  std::optional<Pose> next() override {
    if (next_ >= poses_.size()) return std::nullopt;
    return poses_[next_++];
  }
  bool has_orientation() const override { return orientation_; }
  std::string description() const override {
    return description_ + " (" + std::to_string(poses_.size()) + " poses)";
  }
  /// Poses returned so far and in total.
  std::size_t position() const noexcept { return next_; }
  std::size_t size() const noexcept { return poses_.size(); }

 private:
  std::vector<Pose> poses_;
  std::string description_;
  bool orientation_ = false;
  std::size_t next_ = 0;
};

}  // namespace iclap::rig

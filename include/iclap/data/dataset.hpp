// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iclap/core/types.hpp"

namespace iclap {

/// One tactile frame of a haptic exploration, as one row of the dataset CSV
/// (see README, "Dataset format"): where the pad was and what it felt.
struct Frame {
  std::string object;        ///< the object's name, its class label (no commas or quotes)
  std::int64_t exploration = 0;  ///< id of the exploration run of that object
  std::int64_t frame = 0;    ///< index of the frame inside its exploration (time order)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< pad centre, world frame, metres
  std::optional<double> time;                          ///< column `t`, seconds
  std::optional<Eigen::Quaterniond> orientation;       ///< columns qw,qx,qy,qz (unit)
  /// Taxel pressures, rows x cols, row r / column c as in `p<r>_<c>`, in the
  /// sensor's raw units (0..4095 for the WTS), non-negative.
  Eigen::MatrixXd pressures;
};

/// A whole dataset file: any number of objects and explorations.
struct Dataset {
  Index rows = 0;  ///< taxel grid rows (WTS 0614-34A: 14)
  Index cols = 0;  ///< taxel grid columns (WTS 0614-34A: 6)
  /// Comment lines before the header, without the leading '#' and one space.
  std::vector<std::string> comments;
  /// Frames in file order.
  std::vector<Frame> frames;
};

}  // namespace iclap

// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
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

/// Default contact threshold, in the sensor's raw units: a frame is a
/// contact (a touch) when its largest taxel pressure is above it. 20 is about
/// 0.5 % of the WTS's 12-bit full scale (4095), above its idle noise and the
/// simulator's dead band, below the lightest deliberate touch.
inline constexpr double kDefaultContactThreshold = 20.0;

/// True when the frame's largest taxel pressure is above `threshold` (raw
/// units). A frame without taxels is never a contact. O(taxels).
inline bool is_contact(const Frame& f, double threshold = kDefaultContactThreshold) {
  return f.pressures.size() > 0 && f.pressures.maxCoeff() > threshold;
}

/// Number of contact frames (see is_contact) in `ds`. O(frames x taxels).
inline std::size_t contact_frame_count(const Dataset& ds, double threshold = kDefaultContactThreshold) {
  return static_cast<std::size_t>(std::count_if(
      ds.frames.begin(), ds.frames.end(), [&](const Frame& f) { return is_contact(f, threshold); }));
}

/// Object names in order of first appearance in the file. O(frames).
inline std::vector<std::string> object_names(const Dataset& ds) {
  std::vector<std::string> names;
  std::unordered_map<std::string, std::size_t> seen;
  for (const Frame& f : ds.frames)
    if (seen.emplace(f.object, names.size()).second) names.push_back(f.object);
  return names;
}

/// Exploration ids of `object`, in order of first appearance. O(frames).
inline std::vector<std::int64_t> explorations_of(const Dataset& ds, const std::string& object) {
  std::vector<std::int64_t> ids;
  for (const Frame& f : ds.frames)
    if (f.object == object && std::find(ids.begin(), ids.end(), f.exploration) == ids.end())
      ids.push_back(f.exploration);
  return ids;
}

/// Counts of one object in a dataset.
struct ObjectSummary {
  std::string name;
  std::vector<std::int64_t> explorations;  ///< ids in order of first appearance
  std::size_t frames = 0;
  std::size_t contact_frames = 0;  ///< frames with max pressure > threshold
};

/// Per-object counts, objects in order of first appearance. O(frames x taxels).
inline std::vector<ObjectSummary> summarize(const Dataset& ds,
                                            double threshold = kDefaultContactThreshold) {
  std::vector<ObjectSummary> out;
  std::unordered_map<std::string, std::size_t> index;
  for (const Frame& f : ds.frames) {
    const auto it = index.emplace(f.object, out.size());
    if (it.second) out.push_back(ObjectSummary{f.object, {}, 0, 0});
    ObjectSummary& s = out[it.first->second];
    if (std::find(s.explorations.begin(), s.explorations.end(), f.exploration) == s.explorations.end())
      s.explorations.push_back(f.exploration);
    ++s.frames;
    if (is_contact(f, threshold)) ++s.contact_frames;
  }
  return out;
}

}  // namespace iclap

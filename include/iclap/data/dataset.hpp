// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iclap/core/check.hpp"
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

/// How far from 1 the norm of a dataset quaternion may be: values written
/// with 4 significant digits are within it, a zero or a scaled quaternion is
/// not.
inline constexpr double kQuaternionNormTolerance = 1e-3;

/// Empty if `q` is a unit quaternion (within kQuaternionNormTolerance), else
/// what is wrong with it.
inline std::string quaternion_problem(const Eigen::Quaterniond& q) {
  const double norm = q.norm();
  if (std::abs(norm - 1.0) <= kQuaternionNormTolerance) return {};
  char buf[96];
  std::snprintf(buf, sizeof buf, "has norm %.6g; the pad orientation must be a unit quaternion (norm 1 +- %g)", norm,
                kQuaternionNormTolerance);
  return buf;
}

namespace detail {
/// is_contact for a threshold the caller has checked: the loops over a
/// dataset's frames check it once, not once per frame. Throws
/// NonFiniteValue naming `name` (a string, or a callable returning one) for
/// a NaN or infinite pressure, which no recording has: the largest of
/// pressures with a NaN among them (Eigen's maxCoeff) depends on where the
/// NaN sits, so a frame counted as a contact or not by the taxels' order.
template <typename Name>
bool is_contact_unchecked(const Frame& frame, double threshold, const Name& name) {
  const Eigen::MatrixXd& p = frame.pressures;
  // The name is built only for the error: a dataset's loops call this per frame.
  if (!p.allFinite()) check_finite(p, argument_name(name));
  return p.size() > 0 && p.maxCoeff() > threshold;
}

/// The name of frame i's pressures in a dataset's errors.
inline auto frame_pressures_name(std::size_t i) {
  return [i] { return "frames[" + std::to_string(i) + "].pressures"; };
}
}  // namespace detail

/// True when the frame's largest taxel pressure is above `threshold` (raw
/// units). A frame without taxels is never a contact. Throws InvalidArgument
/// naming "threshold" unless it is finite and >= 0 (a NaN made no frame a
/// contact, a negative one every blank frame), as exploration_overlap and
/// the tactile is_contact do, and NonFiniteValue naming "frame.pressures"
/// for a NaN or infinite pressure. O(taxels).
inline bool is_contact(const Frame& frame, double threshold = kDefaultContactThreshold) {
  check_non_negative(threshold, "threshold");
  return detail::is_contact_unchecked(frame, threshold, "frame.pressures");
}

/// Number of contact frames (see is_contact) in `ds`. Throws InvalidArgument
/// naming "threshold" unless it is finite and >= 0, even for a dataset
/// without frames, and NonFiniteValue naming `frames[i].pressures` for the
/// first frame i with a NaN or infinite pressure. O(frames x taxels).
inline std::size_t contact_frame_count(const Dataset& ds, double threshold = kDefaultContactThreshold) {
  check_non_negative(threshold, "threshold");
  std::size_t count = 0;
  for (std::size_t i = 0; i < ds.frames.size(); ++i)
    if (detail::is_contact_unchecked(ds.frames[i], threshold, detail::frame_pressures_name(i))) ++count;
  return count;
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
  std::unordered_set<std::int64_t> seen;  // a search of `ids` made it O(frames x explorations)
  for (const Frame& f : ds.frames)
    if (f.object == object && seen.insert(f.exploration).second) ids.push_back(f.exploration);
  return ids;
}

/// The frames of one exploration: indices into Dataset::frames, in file order.
struct ExplorationFrames {
  std::int64_t id = 0;
  std::vector<std::size_t> frames;
};

/// The frames of one object, its explorations in order of first appearance.
struct ObjectFrames {
  std::string name;
  std::vector<ExplorationFrames> explorations;
};

/// The frames of `ds` grouped by object, then by exploration, both in order
/// of first appearance (an exploration's frames need not be contiguous in
/// the file). O(frames).
inline std::vector<ObjectFrames> group_frames(const Dataset& ds) {
  std::vector<ObjectFrames> out;
  std::unordered_map<std::string, std::size_t> object_index;
  std::vector<std::unordered_map<std::int64_t, std::size_t>> exploration_index;
  for (std::size_t i = 0; i < ds.frames.size(); ++i) {
    const Frame& f = ds.frames[i];
    const auto [o, new_object] = object_index.emplace(f.object, out.size());
    if (new_object) {
      out.push_back(ObjectFrames{f.object, {}});
      exploration_index.emplace_back();
    }
    ObjectFrames& object = out[o->second];
    const auto [e, new_exploration] = exploration_index[o->second].emplace(f.exploration, object.explorations.size());
    if (new_exploration) object.explorations.push_back(ExplorationFrames{f.exploration, {}});
    object.explorations[e->second].frames.push_back(i);
  }
  return out;
}

/// Counts of one object in a dataset.
struct ObjectSummary {
  std::string name;
  std::vector<std::int64_t> explorations;  ///< ids in order of first appearance
  std::size_t frames = 0;
  std::size_t contact_frames = 0;  ///< frames with max pressure > threshold
};

/// Per-object counts, objects in order of first appearance. Throws
/// InvalidArgument naming "threshold" unless it is finite and >= 0, even for
/// a dataset without frames, and NonFiniteValue naming `frames[i].pressures`
/// for a frame i with a NaN or infinite pressure. O(frames x taxels).
inline std::vector<ObjectSummary> summarize(const Dataset& ds,
                                            double threshold = kDefaultContactThreshold) {
  check_non_negative(threshold, "threshold");
  std::vector<ObjectSummary> out;
  for (const ObjectFrames& o : group_frames(ds)) {
    ObjectSummary s{o.name, {}, 0, 0};
    for (const ExplorationFrames& e : o.explorations) {
      s.explorations.push_back(e.id);
      s.frames += e.frames.size();
      for (const std::size_t i : e.frames)
        if (detail::is_contact_unchecked(ds.frames[i], threshold, detail::frame_pressures_name(i))) ++s.contact_frames;
    }
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace iclap

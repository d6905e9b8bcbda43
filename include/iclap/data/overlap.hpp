// SPDX-License-Identifier: MIT
#pragma once

/// \file
/// How much of each exploration lies where the same object's other
/// explorations also touched. In the paper's leave-one-exploration-out
/// experiment the references of an object are built from its other
/// explorations, so this is the part of a held-out exploration that a
/// position-based classifier (ICP, iCLAP) can match at all.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/types.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/search/kdtree.hpp"

namespace iclap {

/// One exploration's contacts and how many of them lie near another
/// exploration of the same object.
struct ExplorationOverlap {
  std::string object;
  std::int64_t exploration = 0;
  std::size_t contacts = 0;  ///< contact frames (is_contact) of this exploration
  std::size_t near = 0;      ///< of them, within the radius of a contact frame of another exploration of the object
};

/// For every exploration of `ds` (objects and explorations in order of first
/// appearance, as summarize()), its contact frames and how many of them have
/// their pad centre within `radius` (metres) of the pad centre of a contact
/// frame of another exploration of the same object. Positions are compared
/// as recorded (world frame): an object put down differently between
/// explorations counts as it lay. An exploration without contacts has
/// contacts = near = 0; an object with one exploration has near = 0.
///
/// Distances are compared squared, so `radius` must lie in
/// [smallest_spread<double>(), largest_coordinate<double>()] (about 6.7e-139
/// to 1.34e150 m, see check.hpp), where radius^2 is a normal double far from
/// overflow: then "within `radius`" holds for any finite positions (a
/// squared distance that overflows is beyond the radius, one that underflows
/// within it). Outside it radius^2 underflowed to 0 (radius 1e-200: contacts
/// twice the radius apart counted as near) or overflowed to inf (radius
/// 1e200: contacts 1e300 apart counted as near).
///
/// Throws InvalidArgument naming `radius` unless it is finite, positive and
/// in that range, or `threshold` unless it is finite and >= 0, and
/// NonFiniteValue naming `frames[i].position` for a contact frame i at a NaN
/// or infinite position or `frames[i].pressures` for a frame i with a NaN or
/// infinite pressure. One kd-tree per exploration:
/// O(E n log n) per object of E explorations and n contact frames.
inline std::vector<ExplorationOverlap> exploration_overlap(const Dataset& ds, double radius,
                                                           double threshold = kDefaultContactThreshold) {
  check_positive(radius, "radius");
  const double smallest_radius = smallest_spread<double>(), largest_radius = largest_coordinate<double>();
  if (radius < smallest_radius || radius > largest_radius)
    throw InvalidArgument("radius", format_value(radius) + " m is outside [" + format_value(smallest_radius) + ", " +
                                        format_value(largest_radius) +
                                        "] m, where its square stays in the double range; rescale the positions");
  check_non_negative(threshold, "threshold");
  const double r2 = radius * radius;

  // Which frames are contacts, in file order, so that a contact frame at a
  // non-finite position is refused before any work, the first one named.
  std::vector<bool> contact(ds.frames.size());
  for (std::size_t i = 0; i < ds.frames.size(); ++i) {
    contact[i] = detail::is_contact_unchecked(ds.frames[i], threshold, detail::frame_pressures_name(i));
    if (contact[i]) check_finite(ds.frames[i].position, "frames[" + std::to_string(i) + "].position");
  }

  std::vector<ExplorationOverlap> out;
  std::vector<std::vector<std::size_t>> contacts;  // per exploration of one object: its contact frames
  for (const ObjectFrames& o : group_frames(ds)) {
    contacts.assign(o.explorations.size(), {});
    // One kd-tree per exploration with contacts (pad centres).
    std::vector<std::optional<KdTreeSearch<double, 3>>> trees(o.explorations.size());
    for (std::size_t e = 0; e < o.explorations.size(); ++e) {
      for (const std::size_t i : o.explorations[e].frames)
        if (contact[i]) contacts[e].push_back(i);
      const auto& c = contacts[e];
      if (c.empty()) continue;
      Cloud<double, 3> points(3, static_cast<Index>(c.size()));
      for (std::size_t k = 0; k < c.size(); ++k) points.col(static_cast<Index>(k)) = ds.frames[c[k]].position;
      trees[e].emplace(std::move(points));
    }
    for (std::size_t e = 0; e < o.explorations.size(); ++e) {
      ExplorationOverlap r{o.name, o.explorations[e].id, contacts[e].size(), 0};
      for (const std::size_t i : contacts[e]) {
        const Eigen::Vector3d& p = ds.frames[i].position;
        for (std::size_t g = 0; g < trees.size(); ++g)
          if (g != e && trees[g] && trees[g]->nearest(p.data()).squared_distance <= r2) {
            ++r.near;
            break;
          }
      }
      out.push_back(std::move(r));
    }
  }
  return out;
}

}  // namespace iclap

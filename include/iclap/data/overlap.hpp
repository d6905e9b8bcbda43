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
#include <unordered_map>
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
/// Throws InvalidArgument naming `radius` unless it is finite and positive,
/// or `threshold` unless it is finite and >= 0, and NonFiniteValue naming
/// `frames[i].position` for a contact frame i at a NaN or infinite position.
/// One kd-tree per exploration:
/// O(E n log n) per object of E explorations and n contact frames.
inline std::vector<ExplorationOverlap> exploration_overlap(const Dataset& ds, double radius,
                                                           double threshold = kDefaultContactThreshold) {
  check_positive(radius, "radius");
  check_non_negative(threshold, "threshold");
  const double r2 = radius * radius;

  // Contact positions grouped by object, then by exploration, in order of
  // first appearance.
  struct Exploration {
    std::int64_t id = 0;
    std::vector<Eigen::Vector3d> contacts;
  };
  struct Object {
    std::string name;
    std::vector<Exploration> explorations;
    std::unordered_map<std::int64_t, std::size_t> index;
  };
  std::vector<Object> objects;
  std::unordered_map<std::string, std::size_t> object_index;
  for (std::size_t i = 0; i < ds.frames.size(); ++i) {
    const Frame& f = ds.frames[i];
    const auto [oit, onew] = object_index.emplace(f.object, objects.size());
    if (onew) objects.push_back(Object{f.object, {}, {}});
    Object& o = objects[oit->second];
    const auto [eit, enew] = o.index.emplace(f.exploration, o.explorations.size());
    if (enew) o.explorations.push_back(Exploration{f.exploration, {}});
    if (!is_contact(f, threshold)) continue;
    check_finite(f.position, "frames[" + std::to_string(i) + "].position");
    o.explorations[eit->second].contacts.push_back(f.position);
  }

  std::vector<ExplorationOverlap> out;
  for (const Object& o : objects) {
    // One kd-tree per exploration with contacts (pad centres).
    std::vector<std::optional<KdTreeSearch<double, 3>>> trees(o.explorations.size());
    for (std::size_t e = 0; e < o.explorations.size(); ++e) {
      const auto& c = o.explorations[e].contacts;
      if (c.empty()) continue;
      Cloud<double, 3> points(3, static_cast<Index>(c.size()));
      for (std::size_t i = 0; i < c.size(); ++i) points.col(static_cast<Index>(i)) = c[i];
      trees[e].emplace(std::move(points));
    }
    for (std::size_t e = 0; e < o.explorations.size(); ++e) {
      const Exploration& ex = o.explorations[e];
      ExplorationOverlap r{o.name, ex.id, ex.contacts.size(), 0};
      for (const Eigen::Vector3d& p : ex.contacts) {
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

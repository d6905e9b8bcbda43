// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/core/progress.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/recognition/touch_set.hpp"
#include "iclap/tactile/descriptor.hpp"
#include "iclap/tactile/tactile_image.hpp"

namespace iclap {

/// Every touch (contact frame) of a dataset, described once: positions and
/// descriptor features in `touches` (words are per codebook, so left empty),
/// with the object, exploration and frame each touch came from.
struct TouchTable {
  /// Object names in order of first appearance in the dataset.
  std::vector<std::string> objects;
  TouchSet touches;
  std::vector<Index> object;               ///< object index of each touch
  std::vector<std::int64_t> exploration;   ///< exploration id of each touch
  std::vector<std::int64_t> frame;         ///< frame index of each touch
  /// Frames of the dataset that were not contacts (kept in the file, dropped here).
  std::size_t idle_frames = 0;

  Index size() const noexcept { return touches.size(); }

  /// Sorted exploration ids of object `o`.
  std::vector<std::int64_t> explorations_of(Index o) const {
    std::vector<std::int64_t> ids;
    for (std::size_t i = 0; i < object.size(); ++i)
      if (object[i] == o) ids.push_back(exploration[i]);
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    return ids;
  }
};

/// Builds the touch table of `dataset`: keeps the frames whose largest taxel
/// is above `contact_threshold` (raw units) and runs `descriptor` on each.
/// Throws EmptyInput naming "dataset" when no frame is a contact.
/// `progress` gets (frames done, frames).
template <typename Descriptor>
TouchTable make_touch_table(const Dataset& dataset, const Descriptor& descriptor,
                            double contact_threshold = kDefaultContactThreshold,
                            const ProgressCallback& progress = {}) {
  ICLAP_CHECK_DESCRIPTOR(Descriptor);
  TouchTable t;
  std::map<std::string, Index> index;
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < dataset.frames.size(); ++i) {
    const Frame& f = dataset.frames[i];
    if (!index.count(f.object)) {
      index[f.object] = static_cast<Index>(t.objects.size());
      t.objects.push_back(f.object);
    }
    if (is_contact(f, contact_threshold)) kept.push_back(i);
    else ++t.idle_frames;
  }
  if (kept.empty())
    throw EmptyInput("dataset", "has no contact frame (no taxel above " + std::to_string(contact_threshold) + ")");
  const auto n = static_cast<Index>(kept.size());
  t.touches.positions.resize(3, n);
  t.object.resize(kept.size());
  t.exploration.resize(kept.size());
  t.frame.resize(kept.size());
  for (Index j = 0; j < n; ++j) {
    const Frame& f = dataset.frames[kept[static_cast<std::size_t>(j)]];
    const auto ju = static_cast<std::size_t>(j);
    t.touches.positions.col(j) = f.position;
    t.object[ju] = index[f.object];
    t.exploration[ju] = f.exploration;
    t.frame[ju] = f.frame;
    const auto feature = descriptor.compute(TactileImage(f.pressures));
    if (j == 0) t.touches.features.resize(feature.size(), n);
    t.touches.features.col(j) = feature.template cast<float>();
    if (progress && (j % 256 == 0 || j + 1 == n)) progress(static_cast<std::size_t>(j + 1), kept.size());
  }
  check_finite(t.touches.features, "features");
  return t;
}

}  // namespace iclap

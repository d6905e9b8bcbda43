// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/types.hpp"
#include "iclap/tactile/quantizer.hpp"

namespace iclap {

/// A set of touches, as every classifier sees them: where each touch was
/// (pad centre, metres), what it felt (its descriptor) and its word (the
/// codebook's label of that descriptor). Column / element i is touch i.
/// A classifier reads only what it needs (ICP: positions; BoW: words;
/// iCLAP: positions and words; iCLAP-N: positions and features; the patch
/// classifiers: contact points; the height classifier: positions and normals).
///
/// Contact points (optional) are where the object met the pad: the world
/// positions of the taxels of each touch that were pressed, so one touch
/// tells of a patch of surface instead of one point. Touch i owns columns
/// [contact_offsets[i], contact_offsets[i + 1]) of `contact_points`;
/// `contact_offsets` is empty when no touch has them.
///
/// Normals (optional) are the pad's normal at each touch: the unit z axis of
/// the pad frame in the world, pointing from the pad into the object (world
/// -z when the pad presses straight down); empty when the touches carry no
/// orientation.
struct TouchSet {
  Eigen::Matrix3Xd positions;
  Eigen::MatrixXf features;
  WordIds words;
  Eigen::Matrix3Xd contact_points;
  std::vector<Index> contact_offsets;
  Eigen::Matrix3Xd normals;

  Index size() const noexcept { return positions.cols(); }
  bool has_contacts() const noexcept { return !contact_offsets.empty(); }
  bool has_normals() const noexcept { return normals.cols() > 0; }
  /// Number of contact points of touch i (0 without contact points).
  Index contacts_of(Index i) const {
    return has_contacts() ? contact_offsets[static_cast<std::size_t>(i) + 1] - contact_offsets[static_cast<std::size_t>(i)]
                          : 0;
  }

  /// Throws EmptyInput / DimensionMismatch / NonFiniteValue naming
  /// `argument` when the set is empty, its parts disagree in length (parts
  /// left empty are allowed: a classifier that needs them checks), or a
  /// coordinate is not finite.
  void validate(const std::string& argument) const {
    if (positions.cols() == 0) throw EmptyInput(argument, "holds no touch");
    check_finite(positions, argument + ".positions");
    if (features.size() > 0) {
      check_dimension(features.cols(), positions.cols(), argument + ".features (touches)");
      check_finite(features, argument + ".features");
    }
    if (words.size() > 0) check_dimension(words.size(), positions.cols(), argument + ".words (touches)");
    if (has_contacts()) {
      check_dimension(static_cast<Index>(contact_offsets.size()), positions.cols() + 1,
                      argument + ".contact_offsets (touches + 1)");
      if (contact_offsets.front() != 0 || contact_offsets.back() != contact_points.cols() ||
          !std::is_sorted(contact_offsets.begin(), contact_offsets.end()))
        throw InvalidArgument(argument + ".contact_offsets",
                              "must rise from 0 to the number of contact points (" +
                                  std::to_string(contact_points.cols()) + ")");
      check_finite(contact_points, argument + ".contact_points");
    }
    if (has_normals()) {
      check_dimension(normals.cols(), positions.cols(), argument + ".normals (touches)");
      check_finite(normals, argument + ".normals");
      for (Index i = 0; i < normals.cols(); ++i)
        if (std::abs(normals.col(i).norm() - 1.0) > 1e-6)
          throw InvalidArgument(argument + ".normals", "column " + std::to_string(i) + " is not a unit vector (norm " +
                                                           std::to_string(normals.col(i).norm()) + ")");
    }
  }
};

/// The touches of `source` selected by `indices`, in that order.
template <typename Indices>
TouchSet select_touches(const TouchSet& source, const Indices& indices) {
  TouchSet out;
  const auto n = static_cast<Index>(std::size(indices));
  out.positions.resize(3, n);
  if (source.features.size() > 0) out.features.resize(source.features.rows(), n);
  if (source.words.size() > 0) out.words.resize(n);
  if (source.has_normals()) out.normals.resize(3, n);
  Index j = 0;
  for (const auto i : indices) {
    const auto s = static_cast<Index>(i);
    out.positions.col(j) = source.positions.col(s);
    if (source.features.size() > 0) out.features.col(j) = source.features.col(s);
    if (source.words.size() > 0) out.words(j) = source.words(s);
    if (source.has_normals()) out.normals.col(j) = source.normals.col(s);
    ++j;
  }
  if (source.has_contacts()) {
    out.contact_offsets.reserve(static_cast<std::size_t>(n) + 1);
    out.contact_offsets.push_back(0);
    Index total = 0;
    for (const auto i : indices) total += source.contacts_of(static_cast<Index>(i));
    out.contact_points.resize(3, total);
    Index k = 0;
    for (const auto i : indices) {
      const auto s = static_cast<Index>(i);
      const Index m = source.contacts_of(s);
      out.contact_points.middleCols(k, m) =
          source.contact_points.middleCols(source.contact_offsets[static_cast<std::size_t>(s)], m);
      k += m;
      out.contact_offsets.push_back(k);
    }
  }
  return out;
}

}  // namespace iclap

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
/// classifiers: contact points; the height classifier: positions and normals;
/// the occupancy classifier: contact and free points).
///
/// Contact points (optional) are where the object met the pad: the world
/// positions of the taxels of each touch that were pressed, so one touch
/// tells of a patch of surface instead of one point. Touch i owns columns
/// [contact_offsets[i], contact_offsets[i + 1]) of `contact_points`;
/// `contact_offsets` is empty when no touch has them.
///
/// Free points (optional, beyond the paper) are the other taxels of the same
/// pads: the world positions of the taxels of each touch that were not
/// pressed, where the pad was and the object was not (OccupancyClassifier
/// reads them). Touch i owns columns [free_offsets[i], free_offsets[i + 1])
/// of `free_points`; `free_offsets` is empty when no touch has them. A
/// touch's contact and free points together are its whole taxel grid.
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
  Eigen::Matrix3Xd free_points;
  std::vector<Index> free_offsets;

  Index size() const noexcept { return positions.cols(); }
  bool has_contacts() const noexcept { return !contact_offsets.empty(); }
  bool has_normals() const noexcept { return normals.cols() > 0; }
  bool has_free() const noexcept { return !free_offsets.empty(); }
  /// Number of contact points of touch i (0 without contact points).
  Index contacts_of(Index i) const { return has_contacts() ? span(contact_offsets, i) : 0; }
  /// Number of free points of touch i (0 without free points).
  Index free_of(Index i) const { return has_free() ? span(free_offsets, i) : 0; }

  /// Throws EmptyInput naming `argument` when the set is empty, what
  /// validate_layout() throws when its parts disagree in length (parts left
  /// empty are allowed: a classifier that needs them checks), NonFiniteValue
  /// for a coordinate that is not finite and InvalidArgument for a normal
  /// that is not a unit vector, in that order.
  void validate(const std::string& argument) const {
    if (positions.cols() == 0) throw EmptyInput(argument, "holds no touch");
    validate_layout(argument);
    check_finite(positions, argument + ".positions");
    if (features.size() > 0) check_finite(features, argument + ".features");
    if (has_contacts()) check_finite(contact_points, argument + ".contact_points");
    if (has_free()) check_finite(free_points, argument + ".free_points");
    if (has_normals()) {
      check_finite(normals, argument + ".normals");
      for (Index i = 0; i < normals.cols(); ++i)
        if (std::abs(normals.col(i).norm() - 1.0) > 1e-6)
          throw InvalidArgument(argument + ".normals", "column " + std::to_string(i) + " is not a unit vector (norm " +
                                                           format_exact(normals.col(i).norm()) + ")");
    }
  }

  /// The part of validate() that selecting touches relies on, O(touches):
  /// features, words and normals of one column per touch, and contact and
  /// free offsets (one per touch and one more) that rise from 0 to the
  /// number of their points. Throws DimensionMismatch / InvalidArgument
  /// naming `argument`.<part>.
  void validate_layout(const std::string& argument) const {
    if (features.size() > 0) check_dimension(features.cols(), positions.cols(), argument + ".features (touches)");
    if (words.size() > 0) check_dimension(words.size(), positions.cols(), argument + ".words (touches)");
    if (has_normals()) check_dimension(normals.cols(), positions.cols(), argument + ".normals (touches)");
    if (has_contacts()) check_offsets(contact_points, contact_offsets, argument, "contact");
    if (has_free()) check_offsets(free_points, free_offsets, argument, "free");
  }

 private:
  static Index span(const std::vector<Index>& offsets, Index i) {
    return offsets[static_cast<std::size_t>(i) + 1] - offsets[static_cast<std::size_t>(i)];
  }
  /// The offsets of one kind of per-touch points: one per touch and one
  /// more, rising from 0 to the number of points.
  void check_offsets(const Eigen::Matrix3Xd& points, const std::vector<Index>& offsets, const std::string& argument,
                     const std::string& kind) const {
    check_dimension(static_cast<Index>(offsets.size()), positions.cols() + 1,
                    argument + "." + kind + "_offsets (touches + 1)");
    if (offsets.front() != 0 || offsets.back() != points.cols() || !std::is_sorted(offsets.begin(), offsets.end()))
      throw InvalidArgument(argument + "." + kind + "_offsets",
                            "must rise from 0 to the number of " + kind + " points (" + std::to_string(points.cols()) + ")");
  }
};

namespace detail {

/// Per-touch points (`points`, `offsets` as TouchSet's contact or free
/// points) of the touches `indices`, in that order, into `out_points` /
/// `out_offsets`.
template <typename Indices>
void select_touch_points(const Eigen::Matrix3Xd& points, const std::vector<Index>& offsets, const Indices& indices,
                         Eigen::Matrix3Xd& out_points, std::vector<Index>& out_offsets) {
  auto count = [&](Index s) { return offsets[static_cast<std::size_t>(s) + 1] - offsets[static_cast<std::size_t>(s)]; };
  out_offsets.clear();
  out_offsets.reserve(static_cast<std::size_t>(std::size(indices)) + 1);
  out_offsets.push_back(0);
  Index total = 0;
  for (const auto i : indices) total += count(static_cast<Index>(i));
  out_points.resize(3, total);
  Index k = 0;
  for (const auto i : indices) {
    const auto s = static_cast<Index>(i);
    const Index m = count(s);
    out_points.middleCols(k, m) = points.middleCols(offsets[static_cast<std::size_t>(s)], m);
    k += m;
    out_offsets.push_back(k);
  }
}

}  // namespace detail

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
  if (source.has_contacts())
    detail::select_touch_points(source.contact_points, source.contact_offsets, indices, out.contact_points,
                                out.contact_offsets);
  if (source.has_free())
    detail::select_touch_points(source.free_points, source.free_offsets, indices, out.free_points, out.free_offsets);
  return out;
}

}  // namespace iclap

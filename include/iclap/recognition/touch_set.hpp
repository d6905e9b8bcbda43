// SPDX-License-Identifier: MIT
#pragma once

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
/// iCLAP: positions and words; iCLAP-N: positions and features).
struct TouchSet {
  Eigen::Matrix3Xd positions;
  Eigen::MatrixXf features;
  WordIds words;

  Index size() const noexcept { return positions.cols(); }

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
  Index j = 0;
  for (const auto i : indices) {
    const auto s = static_cast<Index>(i);
    out.positions.col(j) = source.positions.col(s);
    if (source.features.size() > 0) out.features.col(j) = source.features.col(s);
    if (source.words.size() > 0) out.words(j) = source.words(s);
    ++j;
  }
  return out;
}

}  // namespace iclap

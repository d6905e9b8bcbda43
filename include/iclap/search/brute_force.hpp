// SPDX-License-Identifier: MIT
#pragma once

#include <utility>

#include "iclap/core/check.hpp"
#include "iclap/core/types.hpp"
#include "iclap/search/neighbor.hpp"

namespace iclap {

/// Exhaustive nearest-neighbour search: O(n) per query, no build cost.
///
/// The test oracle for `KdTreeSearch` (same distances, same tie rule, so the
/// same answers), and the faster choice for very small clouds or very high
/// dimensions. Owns its points. Queries are const and thread-safe.
template <typename Scalar, int Dim = Eigen::Dynamic>
class BruteForceSearch {
  ICLAP_CHECK_SCALAR_AND_DIM(Scalar, Dim);

 public:
  using CloudType = Cloud<Scalar, Dim>;
  struct Settings {};

  BruteForceSearch() = default;

  /// Takes the points (one per column). Throws EmptyInput for an empty cloud
  /// and NonFiniteValue for NaN or infinite coordinates, naming `points`.
  explicit BruteForceSearch(CloudType points, const Settings& /*settings*/ = {})
      : points_(std::move(points)) {
    check_not_empty(points_, "points");
    check_finite(points_, "points");
  }

  Index size() const noexcept { return points_.cols(); }
  Index dim() const noexcept { return points_.rows(); }
  const CloudType& points() const noexcept { return points_; }

  /// The closest point to `query` (length `dim()`), ties to the smaller index.
  Neighbor<Scalar> nearest(const Scalar* query) const noexcept {
    Neighbor<Scalar> best;
    const Index d = points_.rows();
    for (Index j = 0; j < points_.cols(); ++j) {
      const Scalar dist = detail::squared_distance<Dim>(query, points_.col(j).data(), d);
      if (detail::closer(dist, j, best.squared_distance, best.index)) {
        best.index = j;
        best.squared_distance = dist;
      }
    }
    return best;
  }

  /// Same as above for an Eigen vector; it is evaluated into a contiguous
  /// temporary first if it is an expression.
  template <typename Derived>
  Neighbor<Scalar> nearest(const Eigen::MatrixBase<Derived>& query) const {
    const Point<Scalar, Dim> q = query;
    return nearest(q.data());
  }

 private:
  CloudType points_;
};

}  // namespace iclap

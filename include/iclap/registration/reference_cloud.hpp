// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/point_cloud.hpp"
#include "iclap/core/types.hpp"
#include "iclap/search/adaptive.hpp"

namespace iclap {

/// Whether search policy `Search` keeps its points as the Cloud<Scalar,
/// Dim> that a ReferenceCloud<Scalar, Dim, Search> reads back as its
/// working points (KdTreeSearch<double, 3> does for <double, 3>;
/// KdTreeSearch<double>, whose Dim is Dynamic, does not).
template <typename Search, typename Scalar, int Dim>
inline constexpr bool search_keeps_cloud_v = std::is_same_v<typename Search::CloudType, Cloud<Scalar, Dim>>;

/// The model side of a registration, prepared once and shared by any number
/// of registrations (recognition registers every test against the same
/// references): the points, centred on their centroid and scaled by the
/// per-axis weights, inside a search structure. The default,
/// `AdaptiveSearch`, scans clouds of up to 2048 coordinates by brute force
/// and builds a kd-tree for larger ones; `KdTreeSearch` and
/// `BruteForceSearch` force either. All three give the same answers, so the
/// choice changes only the time.
///
/// Per-axis weights w define the metric of both the closest-point search and
/// the error: d(p, q)^2 = sum_k (w_k (p_k - q_k))^2. A weight is a scale,
/// e.g. (1, 1, 1, 0.002) makes one word-label step count as 2 mm. Transforms
/// are estimated in that weighted space, so a model that rotates axes with
/// different weights returns W^-1 R_w W (see `RigidTransform`).
///
/// Centring on the centroid keeps the arithmetic at the object's scale when
/// the coordinates carry a large offset (a rig far from the world origin).
/// The scale itself must suit the scalar type: a cloud whose largest
/// weighted distance from its centroid is below sqrt(min normal) / epsilon
/// (about 1e-12 in float, 1e-138 in double) is refused, since its squared
/// distances underflow and a registration would stop at once, "converged"
/// at its initial transform; so is one whose largest weighted distance is
/// beyond `largest_coordinate<Scalar>()` (1.8e15 in float, 1.3e150 in
/// double), whose squared distances would overflow (given in double to a
/// float cloud, 1e39 became inf).
///
/// Immutable after construction; copies share the search structure; const
/// use is thread-safe. `Search` keeps the working points as a
/// Cloud<Scalar, Dim> (search_keeps_cloud_v; checked at compile time).
template <typename Scalar, int Dim, typename Search = AdaptiveSearch<Scalar, Dim>>
class ReferenceCloud {
  ICLAP_CHECK_SCALAR_AND_DIM(Scalar, Dim);
  static_assert(search_keeps_cloud_v<Search, Scalar, Dim>,
                "ReferenceCloud<Scalar, Dim, Search>: the search must keep its points as a Cloud<Scalar, Dim> "
                "(give it the same Scalar and Dim, e.g. KdTreeSearch<Scalar, Dim>, not KdTreeSearch<Scalar>)");

 public:
  using CloudType = Cloud<Scalar, Dim>;
  using Vector = Point<Scalar, Dim>;
  using SearchType = Search;
  using Acc = Accumulator<Scalar>;

  ReferenceCloud() = default;

  /// Unit weights. Throws EmptyInput / NonFiniteValue / DimensionMismatch
  /// naming `points`.
  template <typename Derived>
  explicit ReferenceCloud(const Eigen::MatrixBase<Derived>& points,
                          const typename Search::Settings& search_settings = {})
      : ReferenceCloud(points, Vector::Ones(Dim > 0 ? Index(Dim) : points.rows()), search_settings) {}

  /// A cloud of your own type (a PointCloudTraits specialisation, see
  /// iclap/core/point_cloud.hpp), read once as `to_cloud` reads it, in
  /// double; unit weights. The reference is the one built from a matrix of
  /// the same values. Throws what to_cloud throws, naming `points`, then as
  /// the matrix constructors.
  template <typename C, typename = std::enable_if_t<is_point_cloud_v<C>>>
  explicit ReferenceCloud(const C& points, const typename Search::Settings& search_settings = {})
      : ReferenceCloud(to_cloud<double, Dim>(points, "points"), search_settings) {}

  /// The same with a weighted metric (below).
  template <typename C, typename WeightsDerived, typename = std::enable_if_t<is_point_cloud_v<C>>>
  ReferenceCloud(const C& points, const Eigen::MatrixBase<WeightsDerived>& weights,
                 const typename Search::Settings& search_settings = {})
      : ReferenceCloud(to_cloud<double, Dim>(points, "points"), weights, search_settings) {}

  /// Weighted metric. Weights must be finite and > 0, one per coordinate
  /// (errors name `weights`). InvalidArgument naming `points` for a cloud
  /// too small or too large for the scalar type (see above).
  template <typename Derived, typename WeightsDerived>
  ReferenceCloud(const Eigen::MatrixBase<Derived>& points, const Eigen::MatrixBase<WeightsDerived>& weights,
                 const typename Search::Settings& search_settings = {}) {
    check_not_empty(points, "points");
    if (Dim > 0) check_dimension(points.rows(), Dim, "points");
    check_finite(points, "points");
    check_dimension(weights.size(), points.rows(), "weights");
    check_finite(weights, "weights");
    for (Index k = 0; k < weights.size(); ++k) {
      if (!(weights(k) > 0))
        throw InvalidArgument("weights", "must be > 0, got " + format_value(static_cast<double>(weights(k))) +
                                             " for coordinate " + std::to_string(k));
      // The transform divides by the weights (undoing the weighting): a
      // finite normal weight has a finite reciprocal.
      static_assert(Scalar(1) / std::numeric_limits<Scalar>::min() < std::numeric_limits<Scalar>::max());
      const auto w = static_cast<Scalar>(weights(k));
      if (!std::isfinite(w) || !(w >= std::numeric_limits<Scalar>::min()))
        throw InvalidArgument("weights", "weight " + format_value(static_cast<double>(weights(k))) +
                                             " of coordinate " + std::to_string(k) +
                                             " is out of the scalar type's range (it overflows, or it is "
                                             "subnormal and its reciprocal may overflow)");
    }
    weights_ = weights.template cast<Scalar>();
    // The transform holds ratios w_j / w_i of the weights (W^-1 R_w W).
    const Acc ratio = static_cast<Acc>(weights_.maxCoeff()) / static_cast<Acc>(weights_.minCoeff());
    if (!std::isfinite(static_cast<Scalar>(ratio)))
      throw InvalidArgument("weights", "the largest weight is " + format_value(static_cast<double>(ratio)) +
                                           " times the smallest, beyond the scalar type's range");
    centroid_ = centroid_of(points);
    if (!centroid_.allFinite())
      throw InvalidArgument("points", "their centroid is beyond the scalar type's range (given in double to a float "
                                      "cloud, or near the largest double); shift the points nearer the origin");
    CloudType work(points.rows(), points.cols());
    const Point<Acc, Dim> c = centroid_acc_;
    const Point<Acc, Dim> w = weights_.template cast<Acc>();
    Acc exact_spread = 0;  // before the cast to Scalar, where a tiny cloud rounds to 0
    Point<Acc, Dim> centred(points.rows());
    for (Index j = 0; j < points.cols(); ++j) {
      centred = w.cwiseProduct(points.col(j).template cast<Acc>() - c);
      exact_spread = std::max(exact_spread, centred.cwiseAbs().maxCoeff());
      work.col(j) = centred.template cast<Scalar>();
    }
    // (Not finite when the centring or the cast overflowed.)
    const Acc spread = work.allFinite() ? static_cast<Acc>(work.cwiseAbs().maxCoeff())
                                        : std::numeric_limits<Acc>::infinity();
    const auto smallest = static_cast<Acc>(smallest_spread<Scalar>());
    if (exact_spread > 0 && exact_spread < smallest)
      throw InvalidArgument("points", "largest weighted distance from the centroid is " +
                                          format_value(static_cast<double>(exact_spread)) + ", below " +
                                          format_value(static_cast<double>(smallest)) +
                                          ": squared distances at this scale underflow the scalar type; rescale "
                                          "the points or the weights");
    const double largest = largest_coordinate<Scalar>();
    if (!(static_cast<double>(spread) <= largest)) {
      // Name the farthest coordinate, measured before the cast to Scalar
      // (where a float cloud's 1e39 became inf).
      Acc far = -1;
      Index far_point = 0, far_coordinate = 0;
      for (Index j = 0; j < points.cols(); ++j)
        for (Index k = 0; k < points.rows(); ++k) {
          const Acc v = std::abs(w(k) * (static_cast<Acc>(points(k, j)) - c(k)));
          if (v > far) {
            far = v;
            far_point = j;
            far_coordinate = k;
          }
        }
      throw InvalidArgument("points", "largest weighted distance from the centroid is " +
                                          format_value(static_cast<double>(far)) + " (coordinate " +
                                          std::to_string(far_coordinate) + " of point " + std::to_string(far_point) +
                                          "), beyond " + format_value(largest) +
                                          ": squared distances at this scale overflow the scalar type; rescale "
                                          "the points or the weights");
    }
    spread_ = static_cast<double>(spread);
    search_ = Search(std::move(work), search_settings);
  }

  Index size() const noexcept { return search_.size(); }
  Index dim() const noexcept { return weights_.size(); }
  /// Centroid of the points, original coordinates.
  const Vector& centroid() const noexcept { return centroid_; }
  /// The same, in the accumulation precision it was computed in.
  const Point<Acc, Dim>& centroid_accurate() const noexcept { return centroid_acc_; }
  const Vector& weights() const noexcept { return weights_; }
  /// The search structure over the working points W (p - centroid).
  const Search& search() const noexcept { return search_; }
  /// The working points W (p - centroid), one per column.
  const CloudType& working_points() const noexcept { return search_.points(); }
  /// The largest magnitude of a working coordinate (0 for a single point):
  /// the scale at which the registration's arithmetic rounds.
  double spread() const noexcept { return spread_; }

 private:
  template <typename Derived>
  Vector centroid_of(const Eigen::MatrixBase<Derived>& points) {
    // Two-pass mean around the first point: exact enough at any offset.
    const Point<Acc, Dim> p0 = points.col(0).template cast<Acc>();
    Point<Acc, Dim> sum = Point<Acc, Dim>::Zero(points.rows());
    for (Index j = 0; j < points.cols(); ++j) sum += points.col(j).template cast<Acc>() - p0;
    centroid_acc_ = p0 + sum / static_cast<Acc>(points.cols());
    return centroid_acc_.template cast<Scalar>();
  }

  Vector centroid_;
  Point<Acc, Dim> centroid_acc_;
  Vector weights_;
  double spread_ = 0;
  Search search_;
};

}  // namespace iclap

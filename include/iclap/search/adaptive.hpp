// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <type_traits>
#include <utility>

#include "iclap/core/check.hpp"
#include "iclap/core/point_cloud.hpp"
#include "iclap/core/types.hpp"
#include "iclap/search/brute_force.hpp"
#include "iclap/search/kdtree.hpp"
#include "iclap/search/neighbor.hpp"

namespace iclap {

/// Brute force for small clouds, a kd-tree for the others: the vectorised
/// scan of `BruteForceSearch` beats a tree's branching on a few hundred
/// low-dimensional points, and loses to it as the cloud grows. The choice is
/// made once, from the cloud's size (points x coordinates); the answers are
/// those of either policy (same distances, same tie rule), so it only
/// changes the time.
///
/// Where the crossover lies (`bench_recognition`, BM_SearchSize): random
/// queries around uniform 3-D and 4-D clouds cost the same in both at 500
/// to 1000 points; the recognition references of the built-in objects
/// (about 280 points) take half the time by brute force, the contact-patch
/// references (thousands of points) and the 75-coordinate iCLAP-N
/// references are faster in the tree.
template <typename Scalar, int Dim = Eigen::Dynamic>
class AdaptiveSearch {
  ICLAP_CHECK_SCALAR_AND_DIM(Scalar, Dim);

 public:
  using CloudType = Cloud<Scalar, Dim>;

  struct Settings {
    /// Largest cloud, in coordinates (points x dimension), searched by
    /// brute force; larger clouds get a kd-tree. 0: always the tree.
    std::size_t brute_force_max_coordinates = 2048;
    /// Points per kd-tree leaf (see KdTreeSearch::Settings).
    std::size_t leaf_max_size = 10;
    /// See BruteForceSearch::Settings.
    bool use_avx2 = true;
  };

  AdaptiveSearch() = default;

  /// Takes the points (one per column); throws what the chosen policy
  /// throws (EmptyInput, NonFiniteValue, InvalidArgument naming `points` or
  /// `settings.leaf_max_size`).
  explicit AdaptiveSearch(CloudType points, const Settings& settings = {}) {
    // Refused whichever policy the cloud gets, so that a bad setting does
    // not wait for a larger cloud to show.
    if (settings.leaf_max_size == 0) throw InvalidArgument("settings.leaf_max_size", "must be at least 1");
    const auto coordinates = static_cast<std::size_t>(points.size());
    if (points.cols() > 0 && coordinates <= settings.brute_force_max_coordinates) {
      typename BruteForceSearch<Scalar, Dim>::Settings s;
      s.use_avx2 = settings.use_avx2;
      brute_ = BruteForceSearch<Scalar, Dim>(std::move(points), s);
      tree_ = false;
    } else {
      typename KdTreeSearch<Scalar, Dim>::Settings s;
      s.leaf_max_size = settings.leaf_max_size;
      kdtree_ = KdTreeSearch<Scalar, Dim>(std::move(points), s);
      tree_ = true;
    }
  }

  /// The same for another Eigen type (a MatrixXd, a block, a map); with a
  /// fixed Dim, DimensionMismatch naming `points` for another row count.
  template <typename Derived, typename = std::enable_if_t<!std::is_same_v<Derived, CloudType>>>
  explicit AdaptiveSearch(const Eigen::MatrixBase<Derived>& points, const Settings& settings = {})
      : AdaptiveSearch(detail::checked_rows<CloudType>(points, "points"), settings) {}

  /// A cloud of your own type (a PointCloudTraits specialisation, see
  /// iclap/core/point_cloud.hpp), read once as `to_cloud<Scalar, Dim>` reads
  /// it: the search of a matrix of the same values. Throws what to_cloud
  /// throws, naming `points`, then as the matrix constructor.
  template <typename C, typename = std::enable_if_t<is_point_cloud_v<C>>>
  explicit AdaptiveSearch(const C& points, const Settings& settings = {})
      : AdaptiveSearch(to_cloud<Scalar, Dim>(points, "points"), settings) {}

  /// True when the cloud is searched through a kd-tree.
  bool uses_tree() const noexcept { return tree_; }

  Index size() const noexcept { return tree_ ? kdtree_.size() : brute_.size(); }
  Index dim() const noexcept { return tree_ ? kdtree_.dim() : brute_.dim(); }
  const CloudType& points() const noexcept { return tree_ ? kdtree_.points() : brute_.points(); }

  /// The closest point to `query` (length `dim()`), ties to the smaller index.
  Neighbor<Scalar> nearest(const Scalar* query) const { return tree_ ? kdtree_.nearest(query) : brute_.nearest(query); }

  /// Warm-started query (see KdTreeSearch); brute force ignores the hint.
  /// The same answer as nearest(query) either way.
  Neighbor<Scalar> nearest(const Scalar* query, Index hint) const {
    return tree_ ? kdtree_.nearest(query, hint) : brute_.nearest(query);
  }

  /// The same for an Eigen vector (a column or a row); DimensionMismatch
  /// naming "query" unless it is one of length `dim()` (a search without
  /// points answers index -1 to any query).
  template <typename Derived>
  Neighbor<Scalar> nearest(const Eigen::MatrixBase<Derived>& query) const {
    if (size() == 0) return {};  // no point: index -1, whatever the query's length
    const Point<Scalar, Dim> q = detail::query_point<Scalar, Dim>(query, dim());
    return nearest(q.data());
  }

 private:
  BruteForceSearch<Scalar, Dim> brute_;
  KdTreeSearch<Scalar, Dim> kdtree_;
  bool tree_ = false;
};

}  // namespace iclap

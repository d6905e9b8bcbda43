// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>

#include <nanoflann.hpp>

#include "iclap/core/check.hpp"
#include "iclap/core/point_cloud.hpp"
#include "iclap/core/types.hpp"
#include "iclap/search/neighbor.hpp"
#include "iclap/search/shared_cloud.hpp"

namespace iclap {

namespace detail {

/// nanoflann dataset adaptor over a column-major Eigen cloud.
template <typename Scalar, int Dim>
struct EigenCloudAdaptor {
  const Cloud<Scalar, Dim>* points;
  std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(points->cols()); }
  Scalar kdtree_get_pt(std::uint32_t idx, std::size_t d) const {
    return (*points)(static_cast<Index>(d), static_cast<Index>(idx));
  }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};

/// nanoflann metric that uses the shared squared-distance kernel, so tree
/// and brute force agree bit for bit.
template <typename Scalar, int Dim>
struct SharedL2Metric {
  using ElementType = Scalar;
  using DistanceType = Scalar;
  const EigenCloudAdaptor<Scalar, Dim>& data_source;
  explicit SharedL2Metric(const EigenCloudAdaptor<Scalar, Dim>& source) : data_source(source) {}
  Scalar evalMetric(const Scalar* a, std::uint32_t b_idx, std::size_t size) const {
    return squared_distance<Dim>(a, data_source.points->col(static_cast<Index>(b_idx)).data(),
                                 static_cast<Index>(size));
  }
  template <typename U, typename V>
  Scalar accum_dist(const U a, const V b, const std::size_t) const {
    return (a - b) * (a - b);
  }
};

/// Single-nearest result set with the shared tie rule. nanoflann only offers
/// a point to the set when it is strictly closer than `worstDist()`, so the
/// bound is inflated by a few ulps: equidistant points still reach
/// `addPoint`, which keeps the smaller index. The inflation only widens the
/// search, it never changes which point wins.
template <typename Scalar>
struct NearestTieAwareResultSet {
  using DistanceType = Scalar;
  using IndexType = std::uint32_t;
  Scalar best = std::numeric_limits<Scalar>::infinity();
  Scalar bound = std::numeric_limits<Scalar>::infinity();
  IndexType index = std::numeric_limits<IndexType>::max();

  bool full() const { return index != std::numeric_limits<IndexType>::max(); }
  bool addPoint(Scalar d, IndexType i) {
    if (d < best || (d == best && i < index)) {
      best = d;
      index = i;
      constexpr Scalar slack = Scalar(1) + Scalar(64) * std::numeric_limits<Scalar>::epsilon();
      // The smallest normal, not denorm_min: under flush-to-zero (a program
      // built with -ffast-math starts in it) a subnormal reads as 0, the
      // bound of a zero distance became 0 and a duplicate point of smaller
      // index in another leaf was never offered (answers unlike
      // BruteForceSearch's).
      bound = best * slack + std::numeric_limits<Scalar>::min();
    }
    return true;
  }
  Scalar worstDist() const { return bound; }
};

/// KdTreeSearch's shared block: the points and the tree over them.
template <typename Scalar, int Dim>
struct KdTreeBlock {
  using Adaptor = EigenCloudAdaptor<Scalar, Dim>;
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<SharedL2Metric<Scalar, Dim>, Adaptor, (Dim > 0 ? Dim : -1),
                                                   std::uint32_t>;
  Cloud<Scalar, Dim> points;
  Adaptor adaptor;
  Tree tree;
  KdTreeBlock(Cloud<Scalar, Dim> p, std::size_t leaf_max_size)
      : points(std::move(p)),
        adaptor{&points},
        tree(static_cast<int>(points.rows()), adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(leaf_max_size)) {}
  KdTreeBlock(const KdTreeBlock&) = delete;
  KdTreeBlock& operator=(const KdTreeBlock&) = delete;
};

}  // namespace detail

/// Nearest-neighbour search through a nanoflann kd-tree (nanoflann 1.4.3),
/// built once from the points and reused for any number of queries.
///
/// Build O(n log n); query O(log n) expected for low dimensions (it degrades
/// towards brute force as the dimension grows). Same distances and tie rule
/// as `BruteForceSearch`, so the answers are identical.
///
/// The tree and its points live in one immutable, shared block: copying a
/// `KdTreeSearch` is cheap and the copies share the tree; queries are const
/// and thread-safe, so one reference serves every thread.
template <typename Scalar, int Dim = Eigen::Dynamic>
class KdTreeSearch
    : public detail::SharedCloudSearch<KdTreeSearch<Scalar, Dim>, Scalar, Dim, detail::KdTreeBlock<Scalar, Dim>> {
  ICLAP_CHECK_SCALAR_AND_DIM(Scalar, Dim);
  using Base = detail::SharedCloudSearch<KdTreeSearch, Scalar, Dim, detail::KdTreeBlock<Scalar, Dim>>;
  using Base::block_;

 public:
  using typename Base::CloudType;
  using Base::nearest;  // the Eigen-vector overload

  struct Settings {
    /// Points per leaf: larger builds faster and searches a little slower.
    std::size_t leaf_max_size = 10;
  };

  KdTreeSearch() = default;

  /// Takes the points (one per column) and builds the tree. Throws EmptyInput
  /// for an empty cloud, NonFiniteValue for NaN or infinite coordinates and
  /// InvalidArgument for 2^32 - 1 points or more (the index type is 32-bit;
  /// its largest value stays unused), naming `points`.
  explicit KdTreeSearch(CloudType points, const Settings& settings = {}) {
    check_not_empty(points, "points");
    check_finite(points, "points");
    if (points.cols() >= static_cast<Index>(std::numeric_limits<std::uint32_t>::max()))
      throw InvalidArgument("points", "too many points for the kd-tree index type");
    if (settings.leaf_max_size == 0)
      throw InvalidArgument("settings.leaf_max_size", "must be at least 1");
    block_ = std::make_shared<const detail::KdTreeBlock<Scalar, Dim>>(std::move(points), settings.leaf_max_size);
  }

  /// The same for another Eigen type (a MatrixXd, a block, a map); with a
  /// fixed Dim, DimensionMismatch naming `points` for another row count.
  template <typename Derived, typename = std::enable_if_t<!std::is_same_v<Derived, CloudType>>>
  explicit KdTreeSearch(const Eigen::MatrixBase<Derived>& points, const Settings& settings = {})
      : KdTreeSearch(detail::checked_rows<CloudType>(points, "points"), settings) {}

  /// A cloud of your own type (a PointCloudTraits specialisation, see
  /// iclap/core/point_cloud.hpp), read once as `to_cloud<Scalar, Dim>` reads
  /// it: the search of a matrix of the same values. Throws what to_cloud
  /// throws, naming `points`, then as the matrix constructor.
  template <typename C, typename = std::enable_if_t<is_point_cloud_v<C>>>
  explicit KdTreeSearch(const C& points, const Settings& settings = {})
      : KdTreeSearch(to_cloud<Scalar, Dim>(points, "points"), settings) {}

  /// The closest point to `query` (length `dim()`), ties to the smaller index.
  Neighbor<Scalar> nearest(const Scalar* query) const { return nearest(query, Index(-1)); }

  /// Warm-started query: the same answer as `nearest(query)` (same distance,
  /// same tie rule), but the search starts with `hint`'s distance as its bound,
  /// so subtrees farther than the hint are never visited. ICP passes each test
  /// point's previous match, which after a small motion is at or near the
  /// nearest point. A hint outside [0, size()) means no hint.
  Neighbor<Scalar> nearest(const Scalar* query, Index hint) const {
    Neighbor<Scalar> result;
    if (!block_) return result;
    detail::NearestTieAwareResultSet<Scalar> set;
    if (hint >= 0 && hint < block_->points.cols()) {
      // A hint whose squared distance overflows is no neighbour (the
      // unhinted search reports none when every distance overflows).
      const Scalar d = detail::squared_distance<Dim>(query, block_->points.col(hint).data(), block_->points.rows());
      if (d < std::numeric_limits<Scalar>::infinity()) set.addPoint(d, static_cast<std::uint32_t>(hint));
    }
    block_->tree.findNeighbors(set, query, nanoflann::SearchParams());
    if (set.full()) {
      result.index = static_cast<Index>(set.index);
      result.squared_distance = set.best;
    }
    return result;
  }
};

}  // namespace iclap

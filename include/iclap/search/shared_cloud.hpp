// SPDX-License-Identifier: MIT
#pragma once

#include <memory>

#include "iclap/core/check.hpp"
#include "iclap/core/types.hpp"
#include "iclap/search/neighbor.hpp"

namespace iclap::detail {

/// What `KdTreeSearch` and `BruteForceSearch` share: the points, kept with
/// whatever the policy builds from them in one immutable block (`Block`, a
/// struct with a member `points`) that copies share, so copying a search is
/// cheap and any number of threads may query one; the accessors; and
/// nearest() for an Eigen vector, evaluated into a contiguous point first
/// and answered by `Search::nearest(const Scalar*)` (CRTP).
template <typename Search, typename Scalar, int Dim, typename Block>
class SharedCloudSearch {
 public:
  using CloudType = Cloud<Scalar, Dim>;

  Index size() const noexcept { return block_ ? block_->points.cols() : 0; }
  Index dim() const noexcept { return block_ ? block_->points.rows() : 0; }
  /// The points as given (empty for a default-constructed search).
  const CloudType& points() const noexcept {
    static const CloudType empty;
    return block_ ? block_->points : empty;
  }

  /// The closest point to an Eigen vector of length `dim()`, ties to the
  /// smaller index. DimensionMismatch naming "query" for another length
  /// (the search over an empty cloud answers index -1 to any query).
  template <typename Derived>
  Neighbor<Scalar> nearest(const Eigen::MatrixBase<Derived>& query) const {
    if (!block_) return {};  // no point: index -1, whatever the query's length
    check_dimension(query.size(), dim(), "query");
    const Point<Scalar, Dim> q = query;
    return static_cast<const Search&>(*this).nearest(q.data());
  }

 protected:
  std::shared_ptr<const Block> block_;
};

}  // namespace iclap::detail

// SPDX-License-Identifier: MIT
#pragma once

#include <memory>
#include <type_traits>

#include "iclap/core/check.hpp"
#include "iclap/core/types.hpp"
#include "iclap/search/neighbor.hpp"

namespace iclap::detail {

/// `query` (a column or a row, also one only at run time) as a point of
/// `dim` coordinates. Throws DimensionMismatch naming "query" for another
/// length, or naming "query (columns)" for a matrix that is not a vector:
/// assigning a 1 x 3 MatrixXd to a column read one coordinate and two
/// uninitialised ones, and a 2 x 2 one was read as four coordinates.
template <typename Scalar, int Dim, typename Derived>
Point<Scalar, Dim> query_point(const Eigen::MatrixBase<Derived>& query, Index dim) {
  static_assert(std::is_same_v<typename Derived::Scalar, Scalar>, "iclap: a query has the search's Scalar");
  check_dimension(query.size(), dim, "query");
  if (query.rows() != 1 && query.cols() != 1) check_dimension(query.cols(), 1, "query (columns)");
  const auto& v = query.eval();  // an expression evaluated once
  Point<Scalar, Dim> q(dim);
  for (Index k = 0; k < dim; ++k) q(k) = v.rows() == 1 ? v(0, k) : v(k, 0);
  return q;
}

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

  /// The closest point to an Eigen vector (a column or a row) of length
  /// `dim()`, ties to the smaller index. DimensionMismatch naming "query"
  /// for another length or for a matrix that is not a vector (the search
  /// over an empty cloud answers index -1 to any query).
  template <typename Derived>
  Neighbor<Scalar> nearest(const Eigen::MatrixBase<Derived>& query) const {
    if (!block_) return {};  // no point: index -1, whatever the query's length
    const Point<Scalar, Dim> q = query_point<Scalar, Dim>(query, dim());
    return static_cast<const Search&>(*this).nearest(q.data());
  }

 protected:
  std::shared_ptr<const Block> block_;
};

}  // namespace iclap::detail

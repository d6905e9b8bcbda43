// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "iclap/core/types.hpp"
#include "iclap/search/neighbor.hpp"

namespace iclap {

/// How a codebook numbers its words.
///
/// The paper (Section VI, "Discussions") notes that the word label used as
/// the 4th coordinate of an iCLAP point has no metric meaning: words 1 and 2
/// may be less alike than words 1 and 7. Ordering the words so that
/// neighbouring ids are similar centroids gives the label axis a meaning.
/// Ordering only renames the words: the clusters, their centres and every
/// bag-of-words distance stay the same.
enum class WordOrdering {
  /// The clustering's own numbering, as in the paper (the default, so the
  /// paper's plain labels stay reproducible).
  None,
  /// Sorted by the projection of the centroids on their first principal
  /// axis: a global 1-D embedding, best when the codebook is elongated.
  PrincipalAxis,
  /// A greedy nearest-neighbour chain: start at the centroid farthest from
  /// the centroids' mean (an extreme word), then repeatedly step to the
  /// nearest unvisited centroid. Consecutive ids are near each other in
  /// feature space by construction; a long jump can occur where the chain
  /// runs out of nearby words.
  NearestNeighbourChain,
};

/// Readable name ("none", "principal_axis", "nearest_neighbour_chain").
inline const char* to_string(WordOrdering o) noexcept {
  switch (o) {
    case WordOrdering::None: return "none";
    case WordOrdering::PrincipalAxis: return "principal_axis";
    case WordOrdering::NearestNeighbourChain: return "nearest_neighbour_chain";
  }
  return "unknown";
}

/// The new numbering of the words whose centroids are the columns of
/// `centres`: `order[new_id] = old_id`, a permutation of 0..k-1. Ties are
/// broken by the smaller old id, and the principal axis is oriented so its
/// largest-magnitude projection is positive (the smallest old id's, where
/// several are largest), so the order is deterministic. For PrincipalAxis,
/// projections within 1e-10 of the largest magnitude of each other (a run
/// of such steps) are ties, since the eigenvector is known only to
/// rounding.
/// O(k^2 d + k^3) for PrincipalAxis (through the k x k Gram matrix, so a
/// high feature dimension costs nothing extra), O(k^2 d) for the chain.
template <typename Scalar, int Dim>
std::vector<Index> word_order(const Cloud<Scalar, Dim>& centres, WordOrdering ordering) {
  const Index k = centres.cols();
  const Index d = centres.rows();
  std::vector<Index> order(static_cast<std::size_t>(k));
  std::iota(order.begin(), order.end(), Index(0));
  if (ordering == WordOrdering::None || k <= 1) return order;

  const Eigen::MatrixXd x = centres.template cast<double>();
  const Eigen::VectorXd mean = x.rowwise().mean();
  if (ordering == WordOrdering::PrincipalAxis) {
    const Eigen::MatrixXd centred = x.colwise() - mean;
    const Eigen::MatrixXd gram = centred.transpose() * centred;  // k x k
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(gram);
    // Projections on the first principal axis are sqrt(lambda_max) times the
    // top eigenvector of the Gram matrix; the scale does not change the order.
    Eigen::VectorXd projection = solver.eigenvectors().col(k - 1);
    // Projections within `tie` of each other count as equal: centres that
    // mirror each other across the axis project equally in exact
    // arithmetic, but the eigenvector's rounding made their order (and the
    // axis' sign) depend on the last bits.
    const double top = projection.cwiseAbs().maxCoeff();
    const double tie = 1e-10 * top;
    Index largest = 0;  // the smallest old id among the largest magnitudes
    while (std::abs(projection[largest]) < top - tie) ++largest;
    if (projection[largest] < 0.0) projection = -projection;
    std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) { return projection[a] < projection[b]; });
    // A run of projections each within `tie` of the next is one tie,
    // ordered by old id.
    const auto at = [&](std::size_t i) { return projection[order[i]]; };
    for (std::size_t begin = 0; begin < order.size();) {
      std::size_t end = begin + 1;
      while (end < order.size() && at(end) - at(end - 1) <= tie) ++end;
      std::sort(order.begin() + static_cast<std::ptrdiff_t>(begin), order.begin() + static_cast<std::ptrdiff_t>(end));
      begin = end;
    }
    return order;
  }

  // Nearest-neighbour chain.
  Index start = 0;
  double farthest = -1.0;
  for (Index j = 0; j < k; ++j) {
    const double dist = (x.col(j) - mean).squaredNorm();
    if (dist > farthest) {
      farthest = dist;
      start = j;
    }
  }
  std::vector<bool> visited(static_cast<std::size_t>(k), false);
  Index current = start;
  for (Index step = 0; step < k; ++step) {
    order[static_cast<std::size_t>(step)] = current;
    visited[static_cast<std::size_t>(current)] = true;
    Index next = -1;
    Scalar best = Scalar(0);
    for (Index j = 0; j < k; ++j) {
      if (visited[static_cast<std::size_t>(j)]) continue;
      const Scalar dist = detail::squared_distance<Dim>(centres.col(current).data(), centres.col(j).data(), d);
      if (next < 0 || dist < best) {
        best = dist;
        next = j;
      }
    }
    current = next;
  }
  return order;
}

}  // namespace iclap

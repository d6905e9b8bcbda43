// SPDX-License-Identifier: MIT
#pragma once
// The baseline of issue 2's target (b), shared by bench_registration and the
// PCL / Open3D comparison: nanoflann's own nearest-neighbour query (its L2
// adaptor and KNNResultSet, as in its examples) over the same points and
// leaf size as iclap's KdTreeSearch, hence the same tree, asked at exactly
// the positions a forced-iteration ICP run asks.

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nanoflann.hpp>

#include "../cpu_time.hpp"
#include "registration_problem.hpp"
#include "iclap/registration/registration.hpp"
#include "iclap/search/kdtree.hpp"

namespace iclap::bench {

/// nanoflann on its own over a column-major cloud (owned).
template <typename Scalar, int Dim>
struct RawNanoflann {
  struct Adaptor {
    const Cloud<Scalar, Dim>* points;
    std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(points->cols()); }
    Scalar kdtree_get_pt(std::uint32_t i, std::size_t d) const {
      return (*points)(static_cast<Index>(d), static_cast<Index>(i));
    }
    template <class BBox>
    bool kdtree_get_bbox(BBox&) const {
      return false;
    }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<Scalar, Adaptor>, Adaptor, Dim,
                                                   std::uint32_t>;

  Cloud<Scalar, Dim> points;
  Adaptor adaptor{&points};
  Tree tree;

  /// Builds the tree with `KdTreeSearch`'s default leaf size (the build
  /// depends only on the points and the leaf size, so the trees are equal).
  explicit RawNanoflann(Cloud<Scalar, Dim> p)
      : points(std::move(p)),
        tree(static_cast<int>(points.rows()), adaptor,
             nanoflann::KDTreeSingleIndexAdaptorParams(typename KdTreeSearch<Scalar, Dim>::Settings{}.leaf_max_size)) {}
  RawNanoflann(const RawNanoflann&) = delete;
  RawNanoflann& operator=(const RawNanoflann&) = delete;

  std::uint32_t nearest(const Scalar* q) const {
    std::uint32_t index = 0;
    Scalar d2 = 0;
    nanoflann::KNNResultSet<Scalar, std::uint32_t, std::size_t> set(1);
    set.init(&index, &d2);
    tree.findNeighbors(set, q, nanoflann::SearchParams());
    return index;
  }
};

/// An Icp that makes exactly `iterations` updates: the paper's tolerance
/// rules disabled (absolute < 0, relative = 0), so only the cap stops it.
template <typename Scalar, int Dim, typename Model = FullRigid>
Icp<Scalar, Dim, Model> forced_icp(int iterations) {
  Icp<Scalar, Dim, Model> icp;
  icp.termination.max_iterations = iterations;
  icp.termination.absolute_tolerance = -1;
  icp.termination.relative_tolerance = 0;
  return icp;
}

/// The query positions of a forced run of `iterations` on (reference, test):
/// round k (0..iterations) is the test under the transform after k updates,
/// in the reference's working frame (centred, unit weights assumed). An ICP
/// of n updates matches n + 1 times. Recovered by re-running with
/// max_iterations = k, so they equal the real run's queries up to rounding.
template <typename Scalar, int Dim, typename Search>
std::vector<Cloud<Scalar, Dim>> icp_query_rounds(const ReferenceCloud<Scalar, Dim, Search>& reference,
                                                 const Cloud<Scalar, Dim>& test, int iterations) {
  const Eigen::VectorXd c = reference.centroid_accurate().template cast<double>();
  const Eigen::MatrixXd x = test.template cast<double>();
  std::vector<Cloud<Scalar, Dim>> rounds;
  for (int k = 0; k <= iterations; ++k) {
    const auto r = forced_icp<Scalar, Dim>(k).align(reference, test);
    const Eigen::MatrixXd R = r.T_model_test.R.template cast<double>();
    const Eigen::VectorXd t = r.T_model_test.t.template cast<double>();
    rounds.push_back(motion(R, t - c, x).template cast<Scalar>());
  }
  return rounds;
}

/// Runs `nearest` on every query of every round; returns the sum of the
/// indices found (a checksum, which also keeps the queries from being elided).
template <typename Scalar, int Dim, typename Nearest>
std::uint64_t run_rounds(const std::vector<Cloud<Scalar, Dim>>& rounds, const Nearest& nearest) {
  std::uint64_t sum = 0;
  for (const auto& q : rounds)
    for (Index j = 0; j < q.cols(); ++j) sum += static_cast<std::uint64_t>(nearest(q.col(j).data()));
  return sum;
}

}  // namespace iclap::bench

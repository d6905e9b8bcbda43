// SPDX-License-Identifier: MIT
#pragma once
// Registration inputs shared by benchmarks/bench_registration.cpp and the
// PCL / Open3D side-by-side benchmark (benchmarks/compare/): a smooth,
// asymmetric object surface about 10 cm across (coordinates in metres, as a
// Phantom Omni reports them), optional feature coordinates that vary smoothly
// over the surface (a stand-in for word labels or tactile descriptors), and a
// test cloud of re-touched model points moved by a known motion.
// Deterministic: everything comes from iclap::Rng with fixed seeds.

#include <cmath>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "iclap/core/random.hpp"
#include "iclap/core/types.hpp"
#include "iclap/registration/models/planar.hpp"
#include "iclap/registration/models/translation.hpp"

namespace iclap::bench {

/// One registration problem: `model` (dim x m) and `test` (dim x n), with the
/// ground truth T_model_test = (R, t): model-frame point = R * test point + t.
struct RegistrationProblem {
  Eigen::MatrixXd model;
  Eigen::MatrixXd test;
  Eigen::MatrixXd R;
  Eigen::VectorXd t;
};

/// A point on the object: a direction d on the unit sphere mapped to a lumpy,
/// elongated closed surface (no symmetry, so the registration has one answer).
inline Eigen::Vector3d object_point(Eigen::Vector3d d) {
  d.normalize();
  const double r = 0.045 * (1.0 + 0.25 * d.x() * d.y() + 0.15 * std::sin(5.0 * d.z()) + 0.1 * d.x() * d.x() * d.z());
  return {1.2 * r * d.x(), 0.8 * r * d.y(), 0.6 * r * d.z()};
}

/// Feature k (k >= 0) at surface point p: a smooth wave over the object with
/// an amplitude of 1 cm, comparable to the spacing of the points, so features
/// guide the matching without dominating it.
inline double feature(Index k, const Eigen::Vector3d& p) {
  Rng rng = Rng::derive(0xFEA7, static_cast<std::uint64_t>(k));
  Eigen::Vector3d w(rng.normal(), rng.normal(), rng.normal());
  w *= 60.0 / w.norm();  // one wave per ~10 cm
  return 0.01 * std::sin(w.dot(p) + rng.uniform(0.0, 6.283185307179586));
}

/// `n` points of dimension `dim` (>= 3): surface positions in rows 0..2 and
/// features in the others, plus Gaussian noise of `noise` (m) on every
/// coordinate.
inline Eigen::MatrixXd object_cloud(Index dim, Index n, Rng rng, double noise) {
  Eigen::MatrixXd c(dim, n);
  for (Index j = 0; j < n; ++j) {
    const Eigen::Vector3d p = object_point({rng.normal(), rng.normal(), rng.normal()});
    c.col(j).head<3>() = p;
    for (Index k = 3; k < dim; ++k) c(k, j) = feature(k - 3, p);
    for (Index k = 0; k < dim; ++k) c(k, j) += noise * rng.normal();
  }
  return c;
}

/// A rotation of SO(k) near the identity: the product of a Givens rotation
/// by an angle uniform in [-magnitude, magnitude] in every coordinate plane
/// (plain loops: no dynamic-size matrix product or solver to compile).
inline Eigen::MatrixXd random_rotation(Index k, double magnitude, Rng& rng) {
  Eigen::MatrixXd R = Eigen::MatrixXd::Identity(k, k);
  for (Index i = 0; i < k; ++i)
    for (Index j = i + 1; j < k; ++j) {
      const double a = magnitude * rng.uniform(-1.0, 1.0);
      const double c = std::cos(a), s = std::sin(a);
      for (Index r = 0; r < k; ++r) {  // R <- G(i, j, a) R
        const double x = R(i, r), y = R(j, r);
        R(i, r) = c * x - s * y;
        R(j, r) = s * x + c * y;
      }
    }
  return R;
}

/// R^T (x - t) for every column x (coefficient-wise product, see above).
inline Eigen::MatrixXd inverse_motion(const Eigen::MatrixXd& R, const Eigen::VectorXd& t, const Eigen::MatrixXd& x) {
  return R.transpose().lazyProduct(x.colwise() - t);
}

/// R x + t for every column x.
inline Eigen::MatrixXd motion(const Eigen::MatrixXd& R, const Eigen::VectorXd& t, const Eigen::MatrixXd& x) {
  return R.lazyProduct(x).colwise() + t;
}

/// A model of `m` points and a test of `n` of the same surface points (a
/// random subset, or with repeats when n > m), each cloud with its own 0.3 mm
/// noise, the test moved by a motion that `Model` can represent: rotation of
/// its block by an angle of the order of `angle` radians, translation of its
/// block by up to `shift` metres per coordinate. Re-touching the model's own
/// points makes the true motion the least-squares optimum (up to the noise),
/// so the accuracy counters measure the registration, not the sampling.
template <typename Model>
RegistrationProblem make_problem(Index dim, Index m, Index n, std::uint64_t seed, double angle = 0.2,
                                 double shift = 0.01) {
  constexpr double noise = 3e-4;
  RegistrationProblem p;
  const Eigen::MatrixXd surface = object_cloud(dim, m, Rng::derive(seed, 1), 0.0);
  Rng rng = Rng::derive(seed, 2);
  p.model = surface;
  for (Index j = 0; j < m; ++j)
    for (Index k = 0; k < dim; ++k) p.model(k, j) += noise * rng.normal();
  // Partial Fisher-Yates: the first n entries become a uniform random subset.
  std::vector<Index> order(static_cast<std::size_t>(m));
  for (Index j = 0; j < m; ++j) order[static_cast<std::size_t>(j)] = j;
  Eigen::MatrixXd sampled(dim, n);
  for (Index j = 0; j < n; ++j) {
    Index pick;
    if (n <= m) {
      const auto u = static_cast<std::size_t>(j);
      const auto swap_with = u + static_cast<std::size_t>(rng.below(static_cast<std::uint64_t>(m - j)));
      std::swap(order[u], order[swap_with]);
      pick = order[u];
    } else {
      pick = static_cast<Index>(rng.below(static_cast<std::uint64_t>(m)));
    }
    for (Index k = 0; k < dim; ++k) sampled(k, j) = surface(k, pick) + noise * rng.normal();
  }
  const Index b = Model::block_size(dim);
  p.R = Eigen::MatrixXd::Identity(dim, dim);
  p.t = Eigen::VectorXd::Zero(dim);
  if constexpr (std::is_same_v<Model, Planar>) {
    const double a = angle * rng.uniform(0.5, 1.0);
    p.R.topLeftCorner(2, 2) << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  } else if constexpr (!std::is_same_v<Model, Translation>) {
    p.R.topLeftCorner(b, b) = random_rotation(b, angle / static_cast<double>(b - 1), rng);
  }
  for (Index i = 0; i < b; ++i) p.t(i) = shift * rng.uniform(-1.0, 1.0);
  // test = T^-1(sampled), so that T maps the test onto the model's object.
  p.test = inverse_motion(p.R, p.t, sampled);
  return p;
}

}  // namespace iclap::bench

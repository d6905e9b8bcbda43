// SPDX-License-Identifier: MIT
#pragma once

#include <Eigen/Core>
#include <type_traits>

namespace iclap {

/// Index type for points and coordinates (Eigen's signed index).
using Index = Eigen::Index;

/// A point cloud: one point per column, `Dim` rows (compile-time, or
/// `Eigen::Dynamic` for a dimension chosen at run time). Column-major, so a
/// point's coordinates are contiguous.
template <typename Scalar, int Dim>
using Cloud = Eigen::Matrix<Scalar, Dim, Eigen::Dynamic>;

/// One point (or any vector) of dimension `Dim`.
template <typename Scalar, int Dim>
using Point = Eigen::Matrix<Scalar, Dim, 1>;

/// A square matrix of size `Dim`.
template <typename Scalar, int Dim>
using SquareMatrix = Eigen::Matrix<Scalar, Dim, Dim>;

namespace detail {

/// a < b for integers of any two types, compared by value (C++20's
/// std::cmp_less): a negative signed value is less than every unsigned one,
/// and SIZE_MAX is not -1. For range checks of ids and labels of a user's
/// integer type.
template <typename A, typename B>
constexpr bool cmp_less(A a, B b) noexcept {
  static_assert(std::is_integral_v<A> && std::is_integral_v<B>, "iclap: cmp_less compares integers");
  if constexpr (std::is_signed_v<A> == std::is_signed_v<B>) return a < b;
  else if constexpr (std::is_signed_v<A>) return a < 0 || static_cast<std::make_unsigned_t<A>>(a) < b;
  else return b >= 0 && a < static_cast<std::make_unsigned_t<B>>(b);
}

}  // namespace detail

/// Accumulation type for sums over many points: double for float inputs
/// (so long sums keep their precision), the scalar itself otherwise.
template <typename Scalar>
using Accumulator = std::conditional_t<(sizeof(Scalar) < sizeof(double)), double, Scalar>;

namespace detail {
template <typename Scalar>
constexpr bool is_supported_scalar_v =
    std::is_same_v<Scalar, float> || std::is_same_v<Scalar, double>;
}  // namespace detail

/// Fails to compile, with a readable message, for scalars other than float
/// and double and for dimensions that are neither positive nor Dynamic.
#define ICLAP_CHECK_SCALAR_AND_DIM(Scalar, Dim)                                   \
  static_assert(::iclap::detail::is_supported_scalar_v<Scalar>,                   \
                "iclap: Scalar must be float or double");                          \
  static_assert((Dim) > 0 || (Dim) == Eigen::Dynamic,                             \
                "iclap: Dim must be a positive compile-time size or Eigen::Dynamic")

}  // namespace iclap

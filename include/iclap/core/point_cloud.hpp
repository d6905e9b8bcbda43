// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"

namespace iclap {

/// How the library reads a point container of yours. The registration works
/// on `Cloud<Scalar, Dim>` (one point per column); a cloud of another type
/// (a `std::vector` of your touch records, a PCL cloud) can be given
/// wherever a ReferenceCloud or Icp::align takes points, to the searches
/// (KdTreeSearch, BruteForceSearch, AdaptiveSearch) and to a
/// TruncatedDistanceField, or turned into a `Cloud` with `to_cloud`, once
/// `PointCloudTraits<YourCloud>` is
/// specialised with three static functions:
///
///     struct Touch { Eigen::Vector3d position; int word; };   // your record of a touch
///
///     template <> struct iclap::PointCloudTraits<std::vector<Touch>> {
///       static iclap::Index size(const std::vector<Touch>& c) { return static_cast<iclap::Index>(c.size()); }
///       static iclap::Index dimension(const std::vector<Touch>&) { return 4; }
///       static double coordinate(const std::vector<Touch>& c, iclap::Index i, iclap::Index k) {
///         const Touch& t = c[static_cast<std::size_t>(i)];
///         return k < 3 ? t.position[k] : t.word;   // iCLAP's (x, y, z, word label)
///       }
///     };
///
/// `size` is the number of points, `dimension` the coordinates of each
/// (the same for every point), `coordinate(cloud, i, k)` coordinate k of
/// point i, for 0 <= i < size and 0 <= k < dimension. A fourth, optional,
/// `static void check(const YourCloud&, const std::string& argument)` is
/// called before any of them, for what only the container can tell (the
/// built-in one for Eigen::Dynamic vectors refuses points of different
/// sizes, naming `argument`[i]). The library reads
/// each coordinate once, through the free functions traits::size,
/// traits::dimension and traits::coordinate, into its own column layout:
/// a copy of O(size x dimension) at the call, none inside the iterations.
///
/// Specialised here for `std::vector` of Eigen vectors (fixed size or
/// Eigen::Dynamic, whose points must then all have one size) and of
/// `std::array` of arithmetic values. Eigen matrices need none: they are the
/// library's own layout and are taken as they are.
template <typename C, typename Enable = void>
struct PointCloudTraits;

/// std::vector of Eigen column vectors, e.g. std::vector<Eigen::Vector3d>.
template <typename S, int D, int Options, int MaxRows, typename Allocator>
struct PointCloudTraits<std::vector<Eigen::Matrix<S, D, 1, Options, MaxRows, 1>, Allocator>> {
  using C = std::vector<Eigen::Matrix<S, D, 1, Options, MaxRows, 1>, Allocator>;
  static Index size(const C& c) { return static_cast<Index>(c.size()); }
  /// D, or for Eigen::Dynamic the size of the first point (0 for no point).
  static Index dimension(const C& c) { return D > 0 ? Index(D) : (c.empty() ? 0 : c.front().size()); }
  static double coordinate(const C& c, Index i, Index k) {
    return static_cast<double>(c[static_cast<std::size_t>(i)](k));
  }
  /// Throws DimensionMismatch naming `argument`[i] for a point of another
  /// size than the first (Eigen::Dynamic only).
  static void check(const C& c, const std::string& argument) {
    if constexpr (D == Eigen::Dynamic)
      for (std::size_t i = 1; i < c.size(); ++i)
        check_dimension(c[i].size(), c.front().size(), argument + "[" + std::to_string(i) + "]");
  }
};

/// std::vector of std::array of an arithmetic type, e.g.
/// std::vector<std::array<float, 4>>.
template <typename T, std::size_t N, typename Allocator>
struct PointCloudTraits<std::vector<std::array<T, N>, Allocator>, std::enable_if_t<std::is_arithmetic_v<T>>> {
  using C = std::vector<std::array<T, N>, Allocator>;
  static Index size(const C& c) { return static_cast<Index>(c.size()); }
  static Index dimension(const C&) { return static_cast<Index>(N); }
  static double coordinate(const C& c, Index i, Index k) {
    return static_cast<double>(c[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)]);
  }
};

namespace detail {

template <typename C, typename = void>
struct has_point_cloud_traits : std::false_type {};
template <typename C>
struct has_point_cloud_traits<
    C, std::void_t<decltype(Index(PointCloudTraits<C>::size(std::declval<const C&>()))),
                   decltype(Index(PointCloudTraits<C>::dimension(std::declval<const C&>()))),
                   decltype(double(PointCloudTraits<C>::coordinate(std::declval<const C&>(), Index(0), Index(0))))>>
    : std::true_type {};

template <typename C, typename = void>
struct has_point_cloud_check : std::false_type {};
template <typename C>
struct has_point_cloud_check<
    C, std::void_t<decltype(PointCloudTraits<C>::check(std::declval<const C&>(), std::declval<const std::string&>()))>>
    : std::true_type {};

}  // namespace detail

/// Is `C` (cv-qualifiers and references removed) an Eigen matrix or
/// expression, which the library takes as it is?
template <typename C>
inline constexpr bool is_eigen_v = std::is_base_of_v<Eigen::EigenBase<std::decay_t<C>>, std::decay_t<C>>;

/// Does `C` have a usable PointCloudTraits specialisation (size, dimension
/// and coordinate, with the signatures above)? Eigen types are not point
/// clouds in this sense: they need no traits.
template <typename C>
inline constexpr bool is_point_cloud_v = !is_eigen_v<C> && detail::has_point_cloud_traits<std::decay_t<C>>::value;

/// Fails to compile, with a readable message, for a type without a usable
/// PointCloudTraits specialisation.
#define ICLAP_CHECK_POINT_CLOUD(C)                                                                     \
  static_assert(::iclap::is_point_cloud_v<C>,                                                          \
                "iclap: this point container needs a specialisation of iclap::PointCloudTraits with " \
                "static size(cloud), dimension(cloud) and coordinate(cloud, i, k); see "              \
                "iclap/core/point_cloud.hpp")

/// The free functions through which the library reads a point cloud of
/// yours (PointCloudTraits).
namespace traits {

template <typename C>
Index size(const C& cloud) {
  ICLAP_CHECK_POINT_CLOUD(C);
  return PointCloudTraits<C>::size(cloud);
}

template <typename C>
Index dimension(const C& cloud) {
  ICLAP_CHECK_POINT_CLOUD(C);
  return PointCloudTraits<C>::dimension(cloud);
}

template <typename C>
double coordinate(const C& cloud, Index i, Index k) {
  ICLAP_CHECK_POINT_CLOUD(C);
  return static_cast<double>(PointCloudTraits<C>::coordinate(cloud, i, k));
}

}  // namespace traits

/// `cloud` read through its PointCloudTraits into the library's layout: a
/// `Cloud<Scalar, Dim>`, point i in column i. Coordinates are read as double
/// and cast once to Scalar.
///
/// Throws DimensionMismatch naming `argument` when Dim is fixed and the
/// cloud's dimension differs (or naming `argument`[i] for a point whose
/// size differs from the first, where the traits can tell), InvalidArgument
/// naming `argument` for a negative size or dimension, NonFiniteValue naming
/// `argument`, the coordinate (row) and the point (column) of the first NaN
/// or infinity, and InvalidArgument naming `argument` for a coordinate
/// beyond Scalar's range (a double of 1e39 read into float). An empty cloud
/// gives a Cloud without columns: what an empty cloud means is for the
/// callee to say (a ReferenceCloud refuses it, naming its argument).
template <typename Scalar, int Dim = Eigen::Dynamic, typename C>
Cloud<Scalar, Dim> to_cloud(const C& cloud, const std::string& argument = "cloud") {
  ICLAP_CHECK_SCALAR_AND_DIM(Scalar, Dim);
  ICLAP_CHECK_POINT_CLOUD(C);
  if constexpr (detail::has_point_cloud_check<C>::value) PointCloudTraits<C>::check(cloud, argument);
  const Index n = traits::size(cloud), d = traits::dimension(cloud);
  if (n < 0) throw InvalidArgument(argument, "has a negative size (" + std::to_string(n) + ")");
  if (d < 0) throw InvalidArgument(argument, "has a negative dimension (" + std::to_string(d) + ")");
  // A cloud of run-time-size points without a point has no dimension (0):
  // it is empty, not of another dimension.
  if (Dim > 0 && !(n == 0 && d == 0)) check_dimension(d, Dim, argument);
  Cloud<Scalar, Dim> out(Dim > 0 ? Index{Dim} : d, n);
  for (Index i = 0; i < n; ++i)
    for (Index k = 0; k < d; ++k) {
      const double v = traits::coordinate(cloud, i, k);
      if (!std::isfinite(v)) throw NonFiniteValue(argument, k, i, v);
      out(k, i) = static_cast<Scalar>(v);
      if (!std::isfinite(out(k, i)))
        throw InvalidArgument(argument, "coordinate " + std::to_string(k) + " of point " + std::to_string(i) + " is " +
                                             format_value(v) + ", beyond the range of float");
    }
  return out;
}

}  // namespace iclap

// SPDX-License-Identifier: MIT
#pragma once

/// The Descriptor concept: one tactile image in, one fixed-length feature
/// vector out. iclap ships TactileSift, RawPressures and MomentsDescriptor;
/// users plug in their own with no registration, e.g.
///
///   struct PeakDescriptor {                       // a complete descriptor
///     Eigen::Matrix<float, 2, 1> compute(const iclap::TactileImage& image) const {
///       Eigen::Index r, c;
///       image.pressures().maxCoeff(&r, &c);
///       return {float(r) / float(image.rows()), float(c) / float(image.cols())};
///     }
///   };
///
/// Requirements on a descriptor type D (checked by ICLAP_CHECK_DESCRIPTOR
/// with readable messages):
///  - `d.compute(image)` is callable on a `const D&` with a
///    `const iclap::TactileImage&` and returns `Eigen::Matrix<Scalar, N, 1>`;
///  - Scalar is float or double; N is the feature length, a positive
///    compile-time constant where known (no heap allocation per frame), or
///    Eigen::Dynamic when it depends on settings or on the grid size;
///  - every image of one dataset gives the same length, and finite values;
///  - compute() is const and thread-safe (the library may call it from
///    several threads on one object).

#include <cstddef>
#include <iterator>
#include <string>
#include <type_traits>
#include <utility>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"
#include "iclap/tactile/tactile_image.hpp"

namespace iclap {

namespace detail {

template <typename D, typename = void>
struct has_descriptor_compute : std::false_type {};
template <typename D>
struct has_descriptor_compute<
    D, std::void_t<decltype(std::declval<const D&>().compute(std::declval<const TactileImage&>()))>>
    : std::true_type {};

template <typename D, bool = has_descriptor_compute<D>::value>
struct descriptor_result {
  using type = void;
};
template <typename D>
struct descriptor_result<D, true> {
  using type = std::decay_t<decltype(std::declval<const D&>().compute(std::declval<const TactileImage&>()))>;
};

/// True for Eigen::Matrix<S, N, 1, ...> (a plain column vector object).
template <typename T, typename = void>
struct is_eigen_column_vector : std::false_type {};
template <typename T>
struct is_eigen_column_vector<T, std::void_t<typename T::Scalar, decltype(T::ColsAtCompileTime)>>
    : std::bool_constant<std::is_base_of_v<Eigen::PlainObjectBase<T>, T> && T::ColsAtCompileTime == 1> {};

template <typename T, bool = is_eigen_column_vector<T>::value>
struct column_vector_scalar_ok : std::false_type {};
template <typename T>
struct column_vector_scalar_ok<T, true> : std::bool_constant<is_supported_scalar_v<typename T::Scalar>> {};

}  // namespace detail

/// True when D models the Descriptor concept (see the top of this file).
template <typename D>
constexpr bool is_descriptor_v =
    detail::has_descriptor_compute<D>::value &&
    detail::is_eigen_column_vector<typename detail::descriptor_result<D>::type>::value &&
    detail::column_vector_scalar_ok<typename detail::descriptor_result<D>::type>::value;

/// Fails to compile, with a message naming the missing requirement, unless
/// D models the Descriptor concept.
#define ICLAP_CHECK_DESCRIPTOR(D)                                                                    \
  static_assert(::iclap::detail::has_descriptor_compute<D>::value,                                  \
                "iclap: a Descriptor needs a const member function "                                \
                "`compute(const iclap::TactileImage&) const` (see iclap/tactile/descriptor.hpp)");  \
  static_assert(!::iclap::detail::has_descriptor_compute<D>::value ||                               \
                    ::iclap::detail::is_eigen_column_vector<                                        \
                        typename ::iclap::detail::descriptor_result<D>::type>::value,               \
                "iclap: Descriptor::compute must return an Eigen column vector "                    \
                "Eigen::Matrix<Scalar, N, 1> (N may be Eigen::Dynamic)");                           \
  static_assert(!::iclap::detail::is_eigen_column_vector<                                           \
                    typename ::iclap::detail::descriptor_result<D>::type>::value ||                 \
                    ::iclap::detail::column_vector_scalar_ok<                                       \
                        typename ::iclap::detail::descriptor_result<D>::type>::value,               \
                "iclap: Descriptor features must have Scalar float or double")

/// What the library needs to know about a descriptor type D.
template <typename D>
struct DescriptorTraits {
  ICLAP_CHECK_DESCRIPTOR(D);
  /// The feature vector type D::compute returns.
  using Feature = typename detail::descriptor_result<D>::type;
  using Scalar = typename Feature::Scalar;
  /// Feature length known at compile time, or Eigen::Dynamic.
  static constexpr int length = Feature::RowsAtCompileTime;
  /// Many features, one per column (like iclap::Cloud).
  using Features = Cloud<Scalar, length>;
};

/// The feature matrix type a descriptor produces: one feature per column.
template <typename D>
using FeaturesOf = typename DescriptorTraits<D>::Features;

namespace detail {
/// `descriptor.compute(image)`, with an InvalidArgument about "image"
/// thrown again naming "images[j]" (same type and reason).
template <typename D>
typename DescriptorTraits<D>::Feature compute_naming_image(const D& descriptor, const TactileImage& image, Index j) {
  return rename_argument("image", [j] { return "images[" + std::to_string(j) + "]"; },
                         [&] { return descriptor.compute(image); });
}
}  // namespace detail

/// Runs `descriptor` on every image of `images` (any range of TactileImage:
/// vector, array, span) and returns the features, one per column, in range
/// order.
///
/// Throws EmptyInput naming "images" for an empty range, DimensionMismatch
/// when an image's feature length differs from the first one's, and
/// NonFiniteValue (argument "features", row = coordinate, column = image
/// index) when the descriptor returns a NaN or infinity, so a broken user
/// descriptor is caught here rather than inside the codebook. An
/// InvalidArgument (or derived error, which keeps its type) the descriptor
/// throws about its "image" (Tactile-SIFT's raw histograms beyond the
/// feature type) comes out naming "images[J]", the image's index in the
/// range; anything else it throws passes through unchanged. O(images x descriptor cost); one allocation for the result.
template <typename D, typename Range>
FeaturesOf<D> extract_features(const D& descriptor, const Range& images) {
  using Traits = DescriptorTraits<D>;
  using std::begin;
  using std::end;
  static_assert(std::is_convertible_v<decltype(*begin(images)), const TactileImage&>,
                "iclap: extract_features needs a range of iclap::TactileImage");
  const auto n = static_cast<Index>(std::distance(begin(images), end(images)));
  if (n == 0) throw EmptyInput("images", "holds no tactile image");
  typename Traits::Features features;
  Index j = 0;
  for (const TactileImage& image : images) {
    const typename Traits::Feature f = detail::compute_naming_image(descriptor, image, j);
    if (j == 0) {
      if (f.size() == 0) throw EmptyInput("features", "descriptor returned an empty feature for images[0]");
      features.resize(f.size(), n);
    } else {
      check_dimension(f.size(), features.rows(), "features of images[" + std::to_string(j) + "]");
    }
    features.col(j) = f;
    ++j;
  }
  check_finite(features, "features");
  return features;
}

}  // namespace iclap

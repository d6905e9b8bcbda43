// SPDX-License-Identifier: MIT
#pragma once

/// The Quantizer concept: learns a vocabulary of `size()` words from training
/// features and maps any feature to a word id in [0, size()). iclap ships
/// KMeansQuantizer (the paper's k-means codebook); users plug in their own,
/// e.g.
///
///   struct SignQuantizer {                 // 2 words: first coordinate < 0 or not
///     template <typename Features> void fit(const Features&) {}
///     template <typename Feature> Eigen::Index assign(const Feature& f) const { return f[0] < 0 ? 0 : 1; }
///     Eigen::Index size() const { return 2; }
///   };
///
/// Requirements on a quantizer type Q for a feature matrix type F (an Eigen
/// matrix with one feature per column, as `extract_features` returns),
/// checked by ICLAP_CHECK_QUANTIZER(Q, F) with readable messages:
///  - `q.fit(features)` is callable on a `Q&` with a `const F&` (its result,
///    if any, is the quantizer's own report and is not used by the library);
///  - `q.assign(features.col(j))` is callable on a `const Q&` and returns an
///    integer word id in [0, q.size()); const and thread-safe;
///  - `q.size()` is callable on a `const Q&` and returns the number of words
///    (an integer), valid after fit().
/// Optional: `q.check(features)` callable on a `const Q&` with a `const F&`,
/// throwing what `fit(features)` would throw without fitting (settings that
/// do not suit these features, say a codebook larger than their distinct
/// values). CrossValidation calls it on every codebook's training features
/// before fitting the first (is_checkable_quantizer_v; KMeansQuantizer has
/// it); a quantizer without it is found out by its fit, at its fold.
/// Word ids are plain labels unless the quantizer documents an ordering
/// (KMeansQuantizer's WordOrdering makes neighbouring ids similar words).

#include <string>
#include <type_traits>
#include <utility>

#include <Eigen/Core>

#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"

namespace iclap {

/// Word ids of many features, one per feature, in feature order.
using WordIds = Eigen::Matrix<Index, Eigen::Dynamic, 1>;

namespace detail {

/// Whether the integer `id` lies in [0, n) (n >= 0), compared in the id's
/// own type: an unsigned id beyond Index's range (SIZE_MAX, say) is out of
/// range, not read as a negative one. Callers name `id` as given
/// (std::to_string(id)).
template <typename Int>
constexpr bool id_in_range(Int id, Index n) noexcept {
  return !cmp_less(id, 0) && cmp_less(id, n);
}

template <typename Q, typename F, typename = void>
struct has_quantizer_fit : std::false_type {};
template <typename Q, typename F>
struct has_quantizer_fit<Q, F, std::void_t<decltype(std::declval<Q&>().fit(std::declval<const F&>()))>>
    : std::true_type {};

template <typename Q, typename F, typename = void>
struct has_quantizer_assign : std::false_type {};
template <typename Q, typename F>
struct has_quantizer_assign<Q, F, std::void_t<decltype(std::declval<const Q&>().assign(std::declval<const F&>().col(0)))>>
    : std::is_integral<std::decay_t<decltype(std::declval<const Q&>().assign(std::declval<const F&>().col(0)))>> {};

template <typename Q, typename = void>
struct has_quantizer_size : std::false_type {};
template <typename Q>
struct has_quantizer_size<Q, std::void_t<decltype(std::declval<const Q&>().size())>>
    : std::is_integral<std::decay_t<decltype(std::declval<const Q&>().size())>> {};

template <typename Q, typename F, typename = void>
struct has_quantizer_check : std::false_type {};
template <typename Q, typename F>
struct has_quantizer_check<Q, F, std::void_t<decltype(std::declval<const Q&>().check(std::declval<const F&>()))>>
    : std::true_type {};

template <typename F, typename = void>
struct is_feature_matrix : std::false_type {};
template <typename F>
struct is_feature_matrix<F, std::void_t<typename F::Scalar>>
    : std::bool_constant<std::is_base_of_v<Eigen::MatrixBase<F>, F> && is_supported_scalar_v<typename F::Scalar>> {};

}  // namespace detail

/// True when Q models the Quantizer concept for feature matrices of type F.
template <typename Q, typename F>
constexpr bool is_quantizer_for_v = detail::is_feature_matrix<F>::value && detail::has_quantizer_fit<Q, F>::value &&
                                    detail::has_quantizer_assign<Q, F>::value && detail::has_quantizer_size<Q>::value;

/// True when Q also has the optional `check(const F&) const` (see above).
template <typename Q, typename F>
constexpr bool is_checkable_quantizer_v = detail::has_quantizer_check<Q, F>::value;

/// Fails to compile, with a message naming the missing requirement, unless
/// Q models the Quantizer concept for feature matrices of type F.
#define ICLAP_CHECK_QUANTIZER(Q, F)                                                                          \
  static_assert(::iclap::detail::is_feature_matrix<F>::value,                                               \
                "iclap: features must be an Eigen matrix of float or double, one feature per column");      \
  static_assert(::iclap::detail::has_quantizer_fit<Q, F>::value,                                            \
                "iclap: a Quantizer needs a member `fit(const Features&)` callable on a non-const object "  \
                "(see iclap/tactile/quantizer.hpp)");                                                        \
  static_assert(::iclap::detail::has_quantizer_assign<Q, F>::value,                                         \
                "iclap: a Quantizer needs a const member `assign(feature)` accepting `features.col(j)` "    \
                "and returning an integer word id");                                                        \
  static_assert(::iclap::detail::has_quantizer_size<Q>::value,                                              \
                "iclap: a Quantizer needs a const member `size()` returning the number of words (integer)")

/// The word ids of every feature (column) of `features`, in column order.
///
/// Throws InvalidArgument naming "quantizer" when the quantizer has no words
/// or returns an id outside [0, size()) (a broken custom quantizer is caught
/// here, before the id indexes a histogram). O(features x assign cost).
template <typename Q, typename Derived>
WordIds assign_words(const Q& quantizer, const Eigen::MatrixBase<Derived>& features) {
  using F = Eigen::Matrix<typename Derived::Scalar, Derived::RowsAtCompileTime, Eigen::Dynamic>;
  ICLAP_CHECK_QUANTIZER(Q, F);
  const F& f = features.derived();  // no copy when Derived is already F
  const auto k = static_cast<Index>(quantizer.size());
  if (k <= 0) throw InvalidArgument("quantizer", "has no words (is it fitted?)");
  WordIds words(f.cols());
  for (Index j = 0; j < f.cols(); ++j) {
    const auto w = quantizer.assign(f.col(j));
    if (!detail::id_in_range(w, k))
      throw InvalidArgument("quantizer", "assigned word " + std::to_string(w) + " to features column " +
                                             std::to_string(j) + ", outside [0, " + std::to_string(k) + ")");
    words[j] = static_cast<Index>(w);
  }
  return words;
}

}  // namespace iclap

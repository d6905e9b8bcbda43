// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>
#include <type_traits>

#include <Eigen/Core>

#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"
#include "iclap/tactile/quantizer.hpp"

namespace iclap {

/// A bag-of-words histogram: element i is the fraction of an object's (or a
/// test set's) touches whose feature is word i; non-negative, sums to 1.
using WordHistogram = Eigen::VectorXd;

/// The normalised word histogram of `words` (any range of integer word ids:
/// WordIds, std::vector<Index>, std::vector<int>) over a vocabulary of `k`
/// words: h^class of an object from its training touches, or h^test of a set
/// of test touches (iCLAP paper, Section IV, "Tactile based object
/// recognition").
///
/// Throws InvalidArgument naming "k" when k < 1, EmptyInput naming "words"
/// when there is no word (a histogram of nothing has no meaning), and
/// InvalidArgument naming "words" with the position and the value of an id
/// outside [0, k). O(words + k).
template <typename Words>
WordHistogram word_histogram(const Words& words, Index k) {
  using std::begin;
  using std::end;
  static_assert(std::is_integral_v<std::decay_t<decltype(*begin(words))>>,
                "iclap: word_histogram needs a range of integer word ids");
  if (k < 1) throw InvalidArgument("k", "must be at least 1, got " + std::to_string(k));
  WordHistogram h = WordHistogram::Zero(k);
  Index count = 0;
  for (const auto w : words) {
    if (!detail::id_in_range(w, k))
      throw InvalidArgument("words", "word " + std::to_string(w) + " at position " + std::to_string(count) +
                                         " is outside [0, " + std::to_string(k) + ")");
    h[static_cast<Index>(w)] += 1.0;
    ++count;
  }
  if (count == 0) throw EmptyInput("words", "holds no word id (a histogram needs at least one touch)");
  return h / static_cast<double>(count);
}

/// One histogram per group (k x groups matrix, column g for group g), e.g.
/// one per object from all training touches: `words[i]` belongs to group
/// `groups[i]` in [0, group_count). Throws like word_histogram, plus
/// DimensionMismatch naming "groups" when the two ranges differ in length,
/// InvalidArgument naming "groups" for a group id out of range or
/// "group_count" when < 1, and EmptyInput naming "groups" for a group
/// without words. O(words + k x groups).
template <typename Words, typename Groups>
Eigen::MatrixXd word_histograms(const Words& words, const Groups& groups, Index k, Index group_count) {
  using std::begin;
  using std::end;
  static_assert(std::is_integral_v<std::decay_t<decltype(*begin(words))>>,
                "iclap: word_histograms needs a range of integer word ids");
  static_assert(std::is_integral_v<std::decay_t<decltype(*begin(groups))>>,
                "iclap: word_histograms needs a range of integer group ids");
  if (k < 1) throw InvalidArgument("k", "must be at least 1, got " + std::to_string(k));
  if (group_count < 1) throw InvalidArgument("group_count", "must be at least 1, got " + std::to_string(group_count));
  const auto n_words = static_cast<Index>(std::distance(begin(words), end(words)));
  const auto n_groups = static_cast<Index>(std::distance(begin(groups), end(groups)));
  if (n_groups != n_words) throw DimensionMismatch("groups", n_words, n_groups);
  if (n_words == 0) throw EmptyInput("words", "holds no word id (a histogram needs at least one touch)");
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(k, group_count);
  auto g_it = begin(groups);
  Index position = 0;
  for (auto w_it = begin(words); w_it != end(words); ++w_it, ++g_it, ++position) {
    if (!detail::id_in_range(*w_it, k))
      throw InvalidArgument("words", "word " + std::to_string(*w_it) + " at position " + std::to_string(position) +
                                         " is outside [0, " + std::to_string(k) + ")");
    if (!detail::id_in_range(*g_it, group_count))
      throw InvalidArgument("groups", "group " + std::to_string(*g_it) + " at position " + std::to_string(position) +
                                          " is outside [0, " + std::to_string(group_count) + ")");
    h(static_cast<Index>(*w_it), static_cast<Index>(*g_it)) += 1.0;
  }
  for (Index g = 0; g < group_count; ++g) {
    const double total = h.col(g).sum();
    if (!(total > 0.0)) throw EmptyInput("groups", "group " + std::to_string(g) + " has no word");
    h.col(g) /= total;
  }
  return h;
}

namespace detail {
template <typename Derived>
void check_histogram(const Eigen::MatrixBase<Derived>& h, const char* argument) {
  if (h.size() == 0) throw EmptyInput(argument, "is an empty histogram");
  if (h.cols() != 1 && h.rows() != 1) throw InvalidArgument(argument, "must be a vector");
  double sum = 0.0;
  for (Index i = 0; i < h.size(); ++i) {
    const auto v = static_cast<double>(h.derived().coeff(i));
    if (!std::isfinite(v) || v < 0.0)
      throw InvalidArgument(argument, "bin " + std::to_string(i) + " is " + format_value(v) +
                                          ", expected a finite non-negative value");
    sum += v;
  }
  if (!(std::abs(sum - 1.0) <= 1e-6))
    throw InvalidArgument(argument, "sums to " + format_exact(sum) + ", expected 1 (normalise it first)");
}
}  // namespace detail

/// The bag-of-words distance of the iCLAP paper (Section IV, "Tactile based
/// object recognition", Eq. (7), after Luo et al. 2015):
///   E_BoW(h_test, h_class) = 1 - sum_i min(h_test_i, h_class_i),
/// the histogram intersection distance: 0 for identical histograms, 1 for
/// histograms with no word in common, in [0, 1] always (rounding is clamped).
///
/// Both arguments must be normalised histograms of the same vocabulary:
/// non-empty vectors of equal length with finite, non-negative bins summing
/// to 1 (within 1e-6). Otherwise throws EmptyInput, DimensionMismatch or
/// InvalidArgument naming "h_test" or "h_class". O(k), computed in double.
template <typename A, typename B>
double histogram_intersection_distance(const Eigen::MatrixBase<A>& h_test, const Eigen::MatrixBase<B>& h_class) {
  detail::check_histogram(h_test, "h_test");
  detail::check_histogram(h_class, "h_class");
  if (h_class.size() != h_test.size()) throw DimensionMismatch("h_class", h_test.size(), h_class.size());
  double common = 0.0;
  for (Index i = 0; i < h_test.size(); ++i)
    common += std::min(static_cast<double>(h_test.derived().coeff(i)), static_cast<double>(h_class.derived().coeff(i)));
  return std::clamp(1.0 - common, 0.0, 1.0);
}

}  // namespace iclap

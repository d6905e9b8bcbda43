// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"

namespace iclap {

/// The distances of several classifiers from one test touch set to the same
/// N known objects, by classifier name ("icp", "bow", "iclap", ...). Usually
/// already normalised (see `normalize`).
class DistanceTable {
 public:
  /// Adds or replaces a classifier's distances; every entry must have the
  /// same length (DimensionMismatch naming the classifier otherwise) and be
  /// finite (NonFiniteValue naming the classifier and the object's row: a
  /// NaN would otherwise lose every comparison and be passed on).
  void set(const std::string& classifier, Eigen::VectorXd distances) {
    check_finite(distances, "distances of '" + classifier + "'");
    if (!entries_.empty() && distances.size() != objects())
      throw DimensionMismatch("distances of '" + classifier + "'", objects(), distances.size());
    for (auto& e : entries_)
      if (e.first == classifier) {
        e.second = std::move(distances);
        return;
      }
    entries_.emplace_back(classifier, std::move(distances));
  }
  bool has(const std::string& classifier) const {
    return std::any_of(entries_.begin(), entries_.end(), [&](const auto& e) { return e.first == classifier; });
  }
  /// Throws InvalidArgument naming "classifier" when it was not computed.
  const Eigen::VectorXd& get(const std::string& classifier) const {
    for (const auto& e : entries_)
      if (e.first == classifier) return e.second;
    throw InvalidArgument("classifier", "'" + classifier + "' has no distances in this table");
  }
  Index objects() const noexcept { return entries_.empty() ? 0 : entries_.front().second.size(); }
  void clear() noexcept { entries_.clear(); }

 private:
  std::vector<std::pair<std::string, Eigen::VectorXd>> entries_;
};

class Fusion;

/// One term of a weighted sum under construction: `0.2 * icp`.
struct WeightedTerms {
  std::vector<std::pair<double, Fusion>> terms;
};

/// A fusion policy: an expression over classifier distances that yields one
/// fused distance per object (paper, Section IV): a classifier's own
/// distances, a weighted sum of fusions (decision fusion E_+, Eq. (9), and
/// the hybrid E_+ forms, Eqs. (11)-(13)) or a product of fusions (E_x,
/// Eqs. (10) and (14)). Nestable to any depth:
///
///   const Fusion icp = Fusion::classifier("icp"), bow = Fusion::classifier("bow"),
///                iclap = Fusion::classifier("iclap");
///   const Fusion all = 0.2 * icp + 0.2 * bow + 0.6 * iclap;  // the paper's best, Eq. (18)
///   const Fusion prod = icp * bow * iclap;
///
/// Weighted sums are checked when they become a Fusion: every weight finite
/// and >= 0 and the weights summing to 1 (within 1e-9); otherwise
/// InvalidArgument naming "weights" with the expression. Immutable values;
/// const use is thread-safe.
class Fusion {
 public:
  enum class Kind { Classifier, WeightedSum, Product };

  /// A classifier's distances, by name (letters, digits, '_' and, not
  /// first, '-', as parse_method reads names).
  static Fusion classifier(std::string name) {
    if (name.empty()) throw InvalidArgument("classifier", "name is empty");
    for (char c : name)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'))
        throw InvalidArgument("classifier", "name '" + name + "' may hold only letters, digits, '_' and '-'");
    if (name.front() == '-') throw InvalidArgument("classifier", "name '" + name + "' may not start with '-'");
    Fusion f;
    f.kind_ = Kind::Classifier;
    f.name_ = std::move(name);
    return f;
  }

  /// sum_i w_i F_i. See the class comment for the checks.
  static Fusion weighted_sum(std::vector<std::pair<double, Fusion>> terms) {
    if (terms.empty()) throw InvalidArgument("weights", "a weighted sum needs at least one term");
    Fusion f;
    f.kind_ = Kind::WeightedSum;
    double sum = 0;
    for (auto& t : terms) {
      f.weights_.push_back(t.first);
      f.children_.push_back(std::move(t.second));
      sum += t.first;
    }
    const std::string expr = f.to_string();
    for (std::size_t i = 0; i < f.weights_.size(); ++i) {
      const double w = f.weights_[i];
      if (!std::isfinite(w)) throw InvalidArgument("weights", "weight " + format_value(w) + " is not finite in " + expr);
      if (w < 0)
        throw InvalidArgument("weights", "negative weight " + format_value(w) + " for " + f.children_[i].to_string() + " in " + expr);
    }
    if (std::abs(sum - 1.0) > 1e-9) {
      // Six digits unless they round to "1": then every digit it takes.
      std::string shown = format_value(sum);
      if (shown == "1") shown = format_exact(sum);
      throw InvalidArgument("weights", "the weights sum to " + shown + ", not 1, in " + expr);
    }
    return f;
  }

  /// prod_i F_i (paper: E_ICP x E_BoW, Eq. (10), and the hybrid products of
  /// Eq. (14)). Needs non-negative inputs at evaluation time. Nested
  /// products are flattened.
  static Fusion product(std::vector<Fusion> factors) {
    if (factors.empty()) throw InvalidArgument("factors", "a product needs at least one factor");
    Fusion f;
    f.kind_ = Kind::Product;
    for (auto& x : factors) {
      if (x.kind_ == Kind::Product) {
        for (auto& y : x.children_) f.children_.push_back(y);
      } else {
        f.children_.push_back(std::move(x));
      }
    }
    return f;
  }

  /// The checked weighted sum of `0.2 * a + 0.8 * b`.
  Fusion(WeightedTerms terms) : Fusion(weighted_sum(std::move(terms.terms))) {}  // NOLINT: implicit on purpose

  Kind kind() const noexcept { return kind_; }
  /// Classifier name (Kind::Classifier only).
  const std::string& name() const noexcept { return name_; }
  const std::vector<Fusion>& children() const noexcept { return children_; }
  /// Weights of a weighted sum, in term order.
  const std::vector<double>& weights() const noexcept { return weights_; }

  /// The same weighted sum with other weights (checked); for weight search.
  Fusion with_weights(const std::vector<double>& weights) const {
    if (kind_ != Kind::WeightedSum) throw InvalidArgument("weights", "only a weighted sum has weights: " + to_string());
    if (weights.size() != children_.size())
      throw DimensionMismatch("weights", static_cast<std::ptrdiff_t>(children_.size()),
                              static_cast<std::ptrdiff_t>(weights.size()));
    std::vector<std::pair<double, Fusion>> terms;
    for (std::size_t i = 0; i < weights.size(); ++i) terms.emplace_back(weights[i], children_[i]);
    return weighted_sum(std::move(terms));
  }

  /// The same expression with every use of classifier `from` replaced by
  /// classifier `to` (e.g. a variant of it with other settings); weights
  /// and structure unchanged.
  Fusion renamed(const std::string& from, const std::string& to) const {
    if (kind_ == Kind::Classifier) return name_ == from ? classifier(to) : *this;
    Fusion f = *this;
    for (auto& c : f.children_) c = c.renamed(from, to);
    return f;
  }

  /// Distinct classifier names used, in first-use order.
  std::vector<std::string> classifiers() const {
    std::vector<std::string> out;
    collect(out);
    return out;
  }

  /// The fused distance of every object. Throws InvalidArgument naming
  /// "classifier" for a missing classifier and naming "distances" when a
  /// product meets a negative distance or underflows (an object's factors
  /// all above 0 and their product below the smallest normal double, 2.2e-308,
  /// where objects would tie by rounding and be decided by their order:
  /// 1e-170 x 3e-170 and 2e-170 x 1e-170 both gave 0), and NonFiniteValue
  /// naming the product when it overflows (raw distances of 1e200 and 1e200;
  /// the normalised ones are at most 1 and cannot). O(N x nodes).
  Eigen::VectorXd evaluate(const DistanceTable& table) const {
    switch (kind_) {
      case Kind::Classifier: return table.get(name_);
      case Kind::WeightedSum: {
        Eigen::VectorXd out = weights_[0] * children_[0].evaluate(table);
        for (std::size_t i = 1; i < children_.size(); ++i) out += weights_[i] * children_[i].evaluate(table);
        return out;
      }
      case Kind::Product: {
        Eigen::VectorXd out = children_[0].evaluate(table);
        check_non_negative(out, children_[0]);
        // Objects with a factor of exactly 0: their product is exact.
        Eigen::Array<bool, Eigen::Dynamic, 1> zero = out.array() == 0.0;
        for (std::size_t i = 1; i < children_.size(); ++i) {
          const Eigen::VectorXd v = children_[i].evaluate(table);
          check_non_negative(v, children_[i]);
          out.array() *= v.array();
          zero = zero || v.array() == 0.0;
        }
        check_finite(out, "product " + to_string());
        for (Index j = 0; j < out.size(); ++j)
          if (out(j) < std::numeric_limits<double>::min() && !zero(j))
            throw InvalidArgument("distances", "the product " + to_string() + " underflows for object " +
                                                   std::to_string(j) + " (" + format_value(out(j)) +
                                                   "): its factors span too many orders of magnitude to rank "
                                                   "the objects; use a weighted sum");
        return out;
      }
    }
    return {};
  }

  /// "0.2*icp+0.2*bow+0.6*iclap", "icp*bow", "(0.5*icp+0.5*bow)*iclap".
  std::string to_string() const {
    switch (kind_) {
      case Kind::Classifier: return name_;
      case Kind::WeightedSum: {
        std::string s;
        for (std::size_t i = 0; i < children_.size(); ++i) {
          if (i) s += "+";
          s += weight_text(weights_[i]) + "*" + children_[i].to_string_as_factor();
        }
        return s;
      }
      case Kind::Product: {
        std::string s;
        for (std::size_t i = 0; i < children_.size(); ++i) {
          if (i) s += "*";
          s += i ? children_[i].to_string_as_factor() : children_[i].to_string_as_first_factor();
        }
        return s;
      }
    }
    return {};
  }

 private:
  Fusion() = default;

  /// A weight as to_string writes it: six significant digits when they read
  /// back within 1e-12 (the paper's tenths, "0.2"), else the shortest text
  /// that reads back exactly ("0.3333333333333333" for a third), so that
  /// parse_method reads any fused method's text back to the same weights.
  static std::string weight_text(double w) {
    const std::string brief = format_value(w);
    double back = 0;
    const auto read = std::from_chars(brief.data(), brief.data() + brief.size(), back);
    return read.ec == std::errc() && std::abs(back - w) <= 1e-12 ? brief : format_exact(w);
  }

  std::string to_string_as_factor() const {
    return kind_ == Kind::WeightedSum ? "(" + to_string() + ")" : to_string();
  }
  /// The first factor of a product: bracketed also when it is a classifier
  /// whose name starts with a digit, which parse_method would read as a
  /// weight ("2*icp" is 2 x icp; "(2)*icp" the product).
  std::string to_string_as_first_factor() const {
    return kind_ == Kind::Classifier && std::isdigit(static_cast<unsigned char>(name_.front()))
               ? "(" + name_ + ")"
               : to_string_as_factor();
  }
  void collect(std::vector<std::string>& out) const {
    if (kind_ == Kind::Classifier) {
      if (std::find(out.begin(), out.end(), name_) == out.end()) out.push_back(name_);
      return;
    }
    for (const auto& c : children_) c.collect(out);
  }
  static void check_non_negative(const Eigen::VectorXd& v, const Fusion& f) {
    if ((v.array() < 0).any())
      throw InvalidArgument("distances", "product fusion needs non-negative distances, but " + f.to_string() +
                                             " has " + format_value(v.minCoeff()) +
                                             " (z-score normalisation is signed: use l2 with products)");
  }

  Kind kind_ = Kind::Classifier;
  std::string name_;
  std::vector<Fusion> children_;
  std::vector<double> weights_;
};

/// `0.2 * icp`: a term of a weighted sum.
inline WeightedTerms operator*(double weight, const Fusion& f) { return WeightedTerms{{{weight, f}}}; }
/// `0.2 * icp + 0.8 * bow`: terms accumulate; the sum is checked when it
/// becomes a Fusion.
inline WeightedTerms operator+(WeightedTerms a, const WeightedTerms& b) {
  a.terms.insert(a.terms.end(), b.terms.begin(), b.terms.end());
  return a;
}
/// `icp * bow`: product fusion.
inline Fusion operator*(const Fusion& a, const Fusion& b) { return Fusion::product({a, b}); }

/// The index of the smallest fused distance: the recognised object. Ties go
/// to the smaller index, so decisions are deterministic. -1 when empty.
/// NonFiniteValue naming "fused" for a NaN or infinity (a NaN loses every
/// comparison, so it would decide by its position).
inline Index decide(const Eigen::Ref<const Eigen::VectorXd>& fused) {
  check_finite(fused, "fused");
  Index best = -1;
  for (Index j = 0; j < fused.size(); ++j)
    if (best < 0 || fused(j) < fused(best)) best = j;
  return best;
}

}  // namespace iclap

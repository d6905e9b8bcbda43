// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <chrono>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/parallel.hpp"
#include "iclap/recognition/classifier.hpp"
#include "iclap/recognition/fusion.hpp"
#include "iclap/recognition/methods.hpp"
#include "iclap/recognition/normalization.hpp"

namespace iclap {

/// Checks that every classifier a method uses is among `available`; throws
/// InvalidArgument naming "methods" with the method and the missing name.
inline void check_methods_use_known_classifiers(const std::vector<Method>& methods,
                                                const std::vector<std::string>& available) {
  for (const auto& m : methods)
    for (const auto& c : m.classifiers())
      if (std::find(available.begin(), available.end(), c) == available.end())
        throw InvalidArgument("methods", "method '" + m.name + "' needs classifier '" + c +
                                             "', which is not among the classifiers (" +
                                             detail::join(available, ", ") + ")");
}

/// How sure a decision is: the relative margin 1 - best / second best of
/// non-negative fused distances, in [0, 1] (0: a tie, 1: the best distance is
/// 0 and the next is not). 1 with a single object; 0 when every distance is
/// 0, and 0 with no object (decide's -1 is no decision). NonFiniteValue
/// naming "fused" for a NaN or infinity, InvalidArgument for a negative
/// distance, whatever the number of objects.
inline double decision_confidence(const Eigen::Ref<const Eigen::VectorXd>& fused) {
  check_finite(fused, "fused");
  if (fused.size() == 0) return 0.0;
  if (fused.minCoeff() < 0) throw InvalidArgument("fused", "confidence needs non-negative distances");
  if (fused.size() == 1) return 1.0;
  double best = fused(0), second = fused(1);
  if (second < best) std::swap(best, second);
  for (Index j = 2; j < fused.size(); ++j) {
    if (fused(j) < best) {
      second = best;
      best = fused(j);
    } else if (fused(j) < second) {
      second = fused(j);
    }
  }
  return second > 0 ? 1.0 - best / second : 0.0;
}

/// The recognition system for one training set: its classifiers (fitted
/// once), the normalisation of their distances and any fusion method over
/// them. Typical use: fit, then for each test touch set `distances` once and
/// `fuse` / `decide` with as many methods as wanted.
///
/// `distances` is const and thread-safe once fitted.
class Recognizer {
 public:
  Recognizer(std::vector<std::unique_ptr<Classifier>> classifiers, Normalization normalization = Normalization::L2)
      : classifiers_(std::move(classifiers)), normalization_(normalization) {
    if (classifiers_.empty()) throw EmptyInput("classifiers", "a recogniser needs at least one classifier");
    std::vector<std::string> seen;
    for (const auto& c : classifiers_) {
      if (!c) throw InvalidArgument("classifiers", "holds a null classifier");
      if (std::find(seen.begin(), seen.end(), c->name()) != seen.end())
        throw InvalidArgument("classifiers", "two classifiers are named '" + c->name() + "'");
      seen.push_back(c->name());
    }
  }

  /// Names of the classifiers, in order.
  std::vector<std::string> classifier_names() const {
    std::vector<std::string> out;
    for (const auto& c : classifiers_) out.push_back(c->name());
    return out;
  }

  /// Throws like check_methods_use_known_classifiers, and when a method
  /// multiplies distances under a normalisation that does not suit a
  /// product: z-score makes them signed, and min-max puts every classifier's
  /// best object at exactly 0, so that every object one factor ranks first
  /// has product 0 and the tie among them goes to the lowest index, whatever
  /// the other factors say. Products need l2 (the paper's).
  void check(const std::vector<Method>& methods) const {
    check_methods_use_known_classifiers(methods, classifier_names());
    if (normalization_ == Normalization::L2) return;
    const std::string why = normalization_ == Normalization::ZScore
                                ? "z-score normalisation makes them signed"
                                : "min-max normalisation puts every classifier's best object at 0, so the product "
                                  "is 0 for the best object of each factor and ties among them";
    for (const auto& m : methods)
      for (const auto& f : m.candidates())
        if (has_product(f))
          throw InvalidArgument("methods", "method '" + m.name + "' multiplies distances, but " + why +
                                               "; use l2 with products, or leave products out");
  }

  /// Fits every classifier on the same training touches (one set per object).
  /// When a classifier refuses them, its error passes on and the recogniser
  /// is unusable until a fit succeeds: the classifiers before it hold the
  /// new training set and those after it the old one, and `distances`
  /// would fuse the two without a word.
  void fit(const std::vector<TouchSet>& objects, Index vocabulary) {
    fit_failed_ = true;
    for (auto& c : classifiers_) c->fit(objects, vocabulary);
    fit_failed_ = false;
  }

  Index objects() const { return classifiers_.front()->objects(); }

  /// Normalised distances of every classifier (or of those named in `only`,
  /// if not empty) from `test` to every object. If `seconds` is given (one
  /// entry per classifier, in order), each classifier's time is added to it.
  /// Throws InvalidArgument naming "recognizer" before `fit` or after a
  /// failed one, naming "only" for a name that is no classifier's, and what
  /// `normalize` throws for a classifier's NaN, infinite or negative
  /// distance, naming "distances of 'NAME'" (as DistanceTable::set does).
  DistanceTable distances(const TouchSet& test, const std::vector<std::string>& only = {},
                          std::vector<double>* seconds = nullptr) const {
    return table_of(only, seconds,
                    [&](const Classifier& c, std::size_t, Eigen::Ref<Eigen::VectorXd> d) { c.distances(test, d); });
  }

  /// Every classifier's `prepare_pool(pool)`, in classifier order (null for
  /// those not named in `only`, if not empty), the classifiers spread over
  /// `threads` threads (0: all cores). If `seconds` is given, each
  /// classifier's time is added to it as in `distances`; `only` is checked
  /// as there.
  std::vector<std::shared_ptr<const PreparedPool>> prepare_pool(const TouchSet& pool,
                                                                const std::vector<std::string>& only = {},
                                                                std::vector<double>* seconds = nullptr,
                                                                unsigned threads = 1) const {
    check_fitted();
    check_only(only);
    std::vector<std::shared_ptr<const PreparedPool>> out(classifiers_.size());
    if (seconds) seconds->resize(classifiers_.size(), 0.0);
    detail::parallel_for(classifiers_.size(), threads, [&](std::size_t i, unsigned /*worker*/) {
      if (!wanted(*classifiers_[i], only)) return;
      const auto start = std::chrono::steady_clock::now();
      out[i] = classifiers_[i]->prepare_pool(pool);
      if (seconds) (*seconds)[i] += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    });
    return out;
  }

  /// The normalised distances of `distances(select_touches(pool, subset),
  /// only, seconds)`, each classifier given its entry of `prepared` (from
  /// `prepare_pool(pool)` since the last fit; see
  /// Classifier::pool_distances). Throws DimensionMismatch naming
  /// "prepared" unless it has one entry per classifier.
  DistanceTable pool_distances(const TouchSet& pool, const std::vector<std::shared_ptr<const PreparedPool>>& prepared,
                               const std::vector<Index>& subset, const std::vector<std::string>& only = {},
                               std::vector<double>* seconds = nullptr) const {
    check_dimension(static_cast<Index>(prepared.size()), static_cast<Index>(classifiers_.size()), "prepared");
    return table_of(only, seconds, [&](const Classifier& c, std::size_t i, Eigen::Ref<Eigen::VectorXd> d) {
      c.pool_distances(pool, prepared[i].get(), subset, d);
    });
  }

  /// The descriptor length a test needs for the classifiers named in `only`
  /// (all, if empty): their Classifier::descriptor_length other than 0, or
  /// 0 when none of them reads descriptors. Throws InvalidArgument naming
  /// "only" as `distances` does, and naming "recognizer" when two of them
  /// need different lengths (fitted on different references).
  Index descriptor_length(const std::vector<std::string>& only = {}) const {
    check_only(only);
    Index length = 0;
    const Classifier* by = nullptr;
    for (const auto& c : classifiers_) {
      const Index l = wanted(*c, only) ? c->descriptor_length() : 0;
      if (l == 0) continue;
      if (by && l != length)
        throw InvalidArgument("recognizer", "classifiers '" + by->name() + "' and '" + c->name() +
                                                "' need descriptors of different lengths (" + std::to_string(length) +
                                                " and " + std::to_string(l) + ")");
      length = l;
      by = c.get();
    }
    return length;
  }

  Normalization normalization() const noexcept { return normalization_; }
  const std::vector<std::unique_ptr<Classifier>>& classifiers() const noexcept { return classifiers_; }

 private:
  static bool wanted(const Classifier& c, const std::vector<std::string>& only) {
    return only.empty() || std::find(only.begin(), only.end(), c.name()) != only.end();
  }

  /// Throws InvalidArgument naming "recognizer" before `fit` (or after a
  /// fit on no object): its classifiers would measure against no object;
  /// and after a fit that failed part-way (see fit).
  void check_fitted() const {
    if (fit_failed_)
      throw InvalidArgument("recognizer", "its last fit failed part-way, so its classifiers may hold different "
                                          "training sets; fit again");
    if (objects() < 1) throw InvalidArgument("recognizer", "is not fitted (no object to recognise); call fit first");
  }

  /// Throws InvalidArgument naming "only" for a name no classifier has (it
  /// would be skipped silently, leaving its distances out of the table).
  void check_only(const std::vector<std::string>& only) const {
    for (const auto& name : only)
      if (std::none_of(classifiers_.begin(), classifiers_.end(), [&](const auto& c) { return c->name() == name; }))
        throw InvalidArgument("only", quote_text(name, 60) + " is not the name of a classifier (" +
                                          detail::join(classifier_names(), ", ") + ")");
  }

  /// The table of the wanted classifiers' distances, each computed by
  /// `compute(classifier, its index, out)`, timed and normalised.
  template <typename Compute>
  DistanceTable table_of(const std::vector<std::string>& only, std::vector<double>* seconds, Compute&& compute) const {
    check_fitted();
    check_only(only);
    DistanceTable table;
    Eigen::VectorXd d(objects());
    if (seconds) seconds->resize(classifiers_.size(), 0.0);
    for (std::size_t i = 0; i < classifiers_.size(); ++i) {
      const auto& c = *classifiers_[i];
      if (!wanted(c, only)) continue;
      const auto start = std::chrono::steady_clock::now();
      compute(c, i, d);
      if (seconds) (*seconds)[i] += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      // The name is built only if normalize refuses (this runs for every test).
      normalize(d, normalization_, [&c] { return "distances of '" + c.name() + "'"; });
      table.set(c.name(), d);
    }
    return table;
  }

  static bool has_product(const Fusion& f) {
    if (f.kind() == Fusion::Kind::Product) return true;
    for (const auto& c : f.children())
      if (has_product(c)) return true;
    return false;
  }

  std::vector<std::unique_ptr<Classifier>> classifiers_;
  Normalization normalization_;
  bool fit_failed_ = false;  ///< the last fit threw part-way (see fit)
};

}  // namespace iclap

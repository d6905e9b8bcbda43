// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/core/parallel.hpp"
#include "iclap/core/progress.hpp"
#include "iclap/core/random.hpp"
#include "iclap/recognition/classifier.hpp"
#include "iclap/recognition/fusion.hpp"
#include "iclap/recognition/methods.hpp"
#include "iclap/recognition/normalization.hpp"
#include "iclap/recognition/recognizer.hpp"
#include "iclap/recognition/touch_table.hpp"
#include "iclap/tactile/kmeans.hpp"
#include "iclap/tactile/quantizer.hpp"

namespace iclap {

/// Settings of the paper's experiment (Section VI): leave-one-exploration-out
/// cross validation, recognition rate against the number of touches.
struct CrossValidationSettings {
  /// Numbers of touches per test, each >= 1 (paper: 1 to 20).
  std::vector<int> touches = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20};
  /// Random draws of the touches per (fold, object, number of touches), at
  /// most kMaxRepeats (each draw has a random stream of its own).
  int repeats = 10;
  /// Draws per (inner fold, object, number of touches) for choosing fusion
  /// weights on the training folds; at most kMaxRepeats.
  int weight_repeats = 2;
  /// The most draws per case: the draw index has 20 bits of the random
  /// stream's id, so more draws would repeat earlier draws' streams.
  static constexpr int kMaxRepeats = 1 << 20;
  /// Weight grid resolution: weights are multiples of 1/weight_steps (0.1).
  int weight_steps = 10;
  /// Let the grid give a classifier weight 0 (beyond the paper, whose grid
  /// gives every classifier at least one step), so that a fitted fusion can
  /// drop a classifier that only hurts it; see weight_grid.
  bool zero_weights = false;
  /// Give every inner fold a codebook of its own, fitted on that inner
  /// fold's training touches only, so that the inner held-out exploration
  /// takes no part in the words its tests are given: a strictly nested
  /// cross validation, at one more codebook fit per inner fold. Off (the
  /// default): the inner folds use their outer fold's codebook, which the
  /// inner held-out exploration helped fit. The outer test is held out of
  /// every codebook either way; only the choice of weights can differ.
  bool inner_codebooks = false;
  /// Seed of every random draw (touch subsets; the codebook has its own).
  std::uint64_t seed = 1;
  Normalization normalization = Normalization::L2;
  /// Worker threads; 0: all cores. Results do not depend on it.
  int threads = 0;
  /// Also evaluate every grid weight on the test folds (the paper's
  /// rate-versus-weight figures); reporting only, never used to choose.
  bool weight_sweeps = true;

  void validate() const {
    if (touches.empty()) throw EmptyInput("touches", "no number of touches to evaluate");
    for (int t : touches)
      if (t < 1) throw InvalidArgument("touches", "every number of touches must be >= 1, got " + std::to_string(t));
    for (std::size_t i = 1; i < touches.size(); ++i)
      if (std::find(touches.begin(), touches.begin() + static_cast<std::ptrdiff_t>(i), touches[i]) !=
          touches.begin() + static_cast<std::ptrdiff_t>(i))
        throw InvalidArgument("touches", std::to_string(touches[i]) +
                                             " is listed twice (its draws would be the same test sets, counted "
                                             "twice)");
    for (const auto& [name, value] : {std::pair<const char*, int>{"repeats", repeats}, {"weight_repeats", weight_repeats}})
      if (value < 1 || value > kMaxRepeats)
        throw InvalidArgument(name, "must be >= 1 and <= " + std::to_string(kMaxRepeats) +
                                        " (each draw has a random stream of its own), got " + std::to_string(value));
    if (weight_steps < 3) throw InvalidArgument("weight_steps", "must be >= 3, got " + std::to_string(weight_steps));
    if (threads < 0) throw InvalidArgument("threads", "must be >= 0, got " + std::to_string(threads));
  }
};

/// Recognition results of one method over all folds.
struct MethodResult {
  std::string name;
  /// correct[t] / total[t]: tests recognised at touches[t], summed over folds.
  std::vector<Index> correct, total;
  /// fold_correct[f][t], fold_total[f][t]: the same per fold.
  std::vector<std::vector<Index>> fold_correct, fold_total;
  /// A matrix of test counts, of the counts' type (Index, as `total`).
  using CountMatrix = Eigen::Matrix<Index, Eigen::Dynamic, Eigen::Dynamic>;
  /// confusion[t](true object, recognised object), summed over folds.
  std::vector<CountMatrix> confusion;
  /// Weights chosen on each fold's training data (empty unless fitted), in
  /// the order of the method's weighted-sum terms.
  std::vector<std::vector<double>> fold_weights;
  /// The fusion of each fold, as text, e.g. "0.2*icp+0.2*bow+0.6*iclap".
  std::vector<std::string> fold_expressions;
  /// Index into the method's candidates() chosen on each fold's training
  /// data (always 0 for a method without alternatives).
  std::vector<std::size_t> fold_candidates;

  double rate(std::size_t t) const {
    return total[t] ? static_cast<double>(correct[t]) / static_cast<double>(total[t]) : 0.0;
  }
};

/// Rate against fusion weights on the test folds (reporting only).
struct WeightSweep {
  std::string method;
  std::vector<std::string> terms;              ///< the weighted classifiers' expressions
  std::vector<std::vector<double>> grid;       ///< grid[g]: one weight per term
  std::vector<std::vector<Index>> correct;     ///< correct[g][t]
  std::vector<Index> total;                    ///< total[t]
};

struct CrossValidationResult {
  std::vector<std::string> objects;
  std::vector<int> touches;
  int folds = 0;
  std::vector<MethodResult> methods;
  std::vector<WeightSweep> sweeps;
  /// Vocabulary size of each fold's codebook.
  std::vector<Index> vocabulary;
  /// Draws that asked for more touches than the held-out exploration had:
  /// they use all of its touches.
  std::size_t capped_draws = 0;
  /// Classifier names and the CPU time each spent on the test sets of the
  /// outer folds (all threads added up), for the time per recognition:
  /// classifier_seconds[c] / classifier_tests[c]. A classifier runs on a
  /// fold's tests only if a method chose it there (see Method::alternatives),
  /// so classifier_tests[c] can be less than `tests`, or 0.
  std::vector<std::string> classifiers;
  std::vector<double> classifier_seconds;
  std::vector<std::size_t> classifier_tests;
  std::size_t tests = 0;
};

/// Throws InvalidArgument naming `argument` unless `objects` holds at least
/// 2 objects: recognition chooses among the known objects, and among one
/// every test is "recognised", whatever was touched (100% in every row of
/// an evaluation, confidence 1 in a live session). Checked by recognition
/// experiments and live references (CrossValidation, LiveReferences), not
/// by the classifiers: distances to a single reference are legitimate.
inline void check_objects_to_choose_among(const std::vector<std::string>& objects, const std::string& argument) {
  if (objects.size() >= 2) return;
  std::string has = objects.empty() ? "no object" : "1 object (" + quote_text(objects.front(), 60) + ")";
  throw InvalidArgument(argument, has + "; recognition needs at least 2 objects to choose among");
}

/// Builds the classifiers of one training set; called once per fold and per
/// inner fold, so every fold gets fresh references.
using ClassifierFactory = std::function<std::vector<std::unique_ptr<Classifier>>()>;

/// The paper's experiment as a reusable engine. Fold f holds out the f-th
/// exploration (in id order) of every object; the number of folds is the
/// smallest number of explorations of any object (>= 2). For each fold, the
/// codebook (a copy of `quantizer` fitted on the training touches'
/// features), the references and the fusion weights come from the training
/// explorations only:
///  - weights: each training exploration in turn is held out of the
///    training set ("inner folds", with the outer fold's codebook, or with
///    one of their own under `inner_codebooks`); the grid weight vector
///    with the highest rate over those inner tests wins (ties: larger mean
///    margin between the true object's fused distance and the closest other
///    one, then grid order). The chosen weights are reported per fold. A
///    method with alternatives (Method::alternatives) has its candidate
///    chosen the same way, on the same inner tests (ties: candidate order,
///    then grid order); every classifier of every candidate is computed on
///    the inner folds, and only the chosen ones on the outer test. Such a
///    method has no weight sweep.
///  - tests: `repeats` random subsets of each number of touches from the
///    held-out exploration of every object, drawn with Rng::derive(seed,
///    draw_stream(fold, inner fold, object), touches << 20 ^ repeat), so
///    the draws do not depend on threads or order.
/// Every test set is registered once per classifier; all methods fuse those
/// same distances. Runs `threads` workers; results are identical for any
/// thread count. Keeps a reference to the touch table, which must outlive
/// it (a temporary table does not compile).
template <typename Quantizer = KMeansQuantizer<float>>
class CrossValidation {
  ICLAP_CHECK_QUANTIZER(Quantizer, Eigen::MatrixXf);

 public:
  /// Throws at construction for an empty method list, a method that needs
  /// a classifier the factory does not make, or one method given twice
  /// (under one name, or under two spellings of one method_key; all
  /// InvalidArgument naming "methods"), for invalid settings, for a table
  /// whose per-touch vectors disagree (TouchTable::validate), and (naming "table") for a table of
  /// fewer than 2 objects (check_objects_to_choose_among), an object
  /// with fewer than 2 explorations, or fewer than 3 when a method's weights
  /// or trimming are chosen on inner folds.
  CrossValidation(const TouchTable& table, ClassifierFactory factory, Quantizer quantizer, std::vector<Method> methods,
                  CrossValidationSettings settings = {})
      : table_(table),
        factory_(std::move(factory)),
        quantizer_(std::move(quantizer)),
        methods_(std::move(methods)),
        settings_(std::move(settings)) {
    settings_.validate();
    if (!factory_) throw InvalidArgument("factory", "is empty");
    if (methods_.empty()) throw EmptyInput("methods", "no method to evaluate");
    for (std::size_t i = 0; i < methods_.size(); ++i) {
      const Method& m = methods_[i];
      m.validate();
      // One method twice (by name, or under two spellings: method_key)
      // would be run twice and reported under names that cannot be told
      // apart, or as two results of one method.
      for (std::size_t j = 0; j < i; ++j) {
        const std::string items = " (method " + std::to_string(i + 1) + " and method " + std::to_string(j + 1) + ")";
        if (methods_[j].name == m.name)
          throw InvalidArgument("methods", "two methods are named '" + m.name + "'" + items);
        if (method_key(methods_[j]) == method_key(m))
          throw InvalidArgument("methods", "method '" + m.name + "' is the same method as '" + methods_[j].name +
                                               "'" + items);
      }
      // Checked here, naming the setting (run()'s weight_grid named "steps").
      if (m.fit_weights)
        for (const auto& c : m.candidates()) check_weight_steps(m.name, c, settings_.weight_steps, settings_.zero_weights);
    }
    Recognizer probe(factory_(), settings_.normalization);
    probe.check(methods_);
    if (table_.size() == 0) throw EmptyInput("table", "holds no touch");
    table_.validate("table");
    check_objects_to_choose_among(table_.objects, "table");
    // A method chosen in training holds out each of a fold's training
    // explorations in turn (inner folds); an object with 2 explorations has
    // only 1 training exploration per fold, and nothing left to fit on.
    const auto chosen = std::find_if(methods_.begin(), methods_.end(),
                                     [](const Method& m) { return m.chosen_in_training(); });
    folds_ = std::numeric_limits<int>::max();
    for (Index o = 0; o < static_cast<Index>(table_.objects.size()); ++o) {
      const auto ids = table_.explorations_of(o);
      const std::string has = "object '" + table_.objects[static_cast<std::size_t>(o)] + "' has " +
                              std::to_string(ids.size()) + (ids.size() == 1 ? " exploration" : " explorations") +
                              " with touches; ";
      if (ids.size() < 2) throw InvalidArgument("table", has + "cross validation needs at least 2");
      if (ids.size() < 3 && chosen != methods_.end())
        throw InvalidArgument("table", has + "method '" + chosen->name +
                                           "' is chosen on inner folds of each fold's training explorations "
                                           "(weights or trimming), which needs at least 3 explorations of every "
                                           "object (give fixed weights and trimming, which need only 2)");
      folds_ = std::min(folds_, static_cast<int>(ids.size()));
      explorations_.push_back(ids);
    }
    if (folds_ > kMaxFolds)
      throw InvalidArgument("table", "every object has at least " + std::to_string(folds_) +
                                         " explorations, which makes more folds than the " +
                                         std::to_string(kMaxFolds) + " whose test draws have random streams of their own");
    // Classifiers the weight and candidate search needs (the only ones
    // computed on inner folds).
    std::vector<Fusion> searched;
    for (const auto& m : methods_)
      if (m.chosen_in_training())
        for (const auto& f : m.candidates()) searched.push_back(f);
    fitted_classifiers_ = classifiers_of(searched);
  }

  /// The table is kept by reference: a temporary would dangle.
  CrossValidation(const TouchTable&& table, ClassifierFactory factory, Quantizer quantizer,
                  std::vector<Method> methods, CrossValidationSettings settings = {}) = delete;

  int folds() const noexcept { return folds_; }

  /// The most touches of any exploration that a fold or inner fold holds
  /// out (of every object, the explorations of rank below folds()): a draw
  /// of this many touches or more uses all the touches of every held-out
  /// exploration.
  std::size_t largest_held_out() const {
    std::size_t most = 0;
    for (Index o = 0; o < static_cast<Index>(table_.objects.size()); ++o)
      for (int rank = 0; rank < folds_; ++rank) most = std::max(most, touches_of(o, rank).size());
    return most;
  }

  /// The touches (indices into the table, ascending) that each codebook of
  /// run() is fitted on: every fold's training touches, in fold order, then,
  /// under inner_codebooks (when a method is chosen on inner folds), those
  /// of each fold's inner folds. For checking the quantizer's settings
  /// against the data before run(), which finds a codebook too large for
  /// its touches only when it reaches that fold.
  std::vector<std::vector<Index>> codebook_trainings() const {
    std::vector<std::vector<Index>> out;
    for (int f = 0; f < folds_; ++f) out.push_back(training_of(f));
    if (!settings_.inner_codebooks || fitted_classifiers_.empty()) return out;
    for (int f = 0; f < folds_; ++f)
      for (int g = 0; g < folds_; ++g)
        if (g != f) out.push_back(inner_training_of(out[static_cast<std::size_t>(f)], g));
    return out;
  }

  /// Throws what fitting a codebook of run() would throw, naming the
  /// quantizer's setting, for a quantizer with the optional `check` (see
  /// tactile/quantizer.hpp), e.g. KMeansQuantizer's settings.k above a
  /// fold's (distinct) training features; does nothing for a quantizer
  /// without it. run() calls it before fitting anything, so such a setting
  /// is refused at once rather than at the fold whose codebook it does not
  /// suit; call it yourself to refuse it before printing anything.
  void check_codebooks() const {
    if constexpr (is_checkable_quantizer_v<Quantizer, Eigen::MatrixXf>)
      for (const auto& train : codebook_trainings())
        quantizer_.check(Eigen::MatrixXf(table_.touches.features(Eigen::all, train)));
  }

  /// The most folds: the random stream of a draw has 16 bits for the fold.
  static constexpr int kMaxFolds = (1 << 16) - 1;

  /// The random stream id of the test draws of `object` in fold `fold`
  /// (from 0) and inner fold `inner` (-1 for the outer test), distinct for
  /// every (fold, inner, object) with folds up to kMaxFolds and objects
  /// below 2^31: fold << 40 ^ (inner + 1) << 32 ^ object while inner + 1
  /// fits in 8 bits, else the top bit set and 16 bits each for the fold and
  /// inner + 1 above the object's 31.
  static std::uint64_t draw_stream(int fold, int inner, Index object) {
    const auto f = static_cast<std::uint64_t>(fold), i = static_cast<std::uint64_t>(inner + 1),
               o = static_cast<std::uint64_t>(object);
    if (i < 256) return (f << 40) ^ (i << 32) ^ o;
    return (std::uint64_t{1} << 63) | (f << 47) | (i << 31) | o;
  }

  /// Runs every fold. `progress` gets (test sets done, test sets in all).
  /// Throws what check_codebooks() throws before fitting anything.
  CrossValidationResult run(const ProgressCallback& progress = {}) {
    check_codebooks();
    const Index n_objects = static_cast<Index>(table_.objects.size());
    const std::size_t nt = settings_.touches.size();
    CrossValidationResult result;
    result.objects = table_.objects;
    result.touches = settings_.touches;
    result.folds = folds_;
    for (const auto& m : methods_) {
      MethodResult r;
      r.name = m.name;
      r.correct.assign(nt, 0);
      r.total.assign(nt, 0);
      r.confusion.assign(nt, MethodResult::CountMatrix::Zero(n_objects, n_objects));
      result.methods.push_back(std::move(r));
      if (has_sweep(m)) {
        WeightSweep s;
        s.method = m.name;
        for (const auto& c : m.fusion.children()) s.terms.push_back(c.to_string());
        s.grid = weight_grid(static_cast<int>(m.fusion.children().size()), settings_.weight_steps,
                             settings_.zero_weights);
        s.correct.assign(s.grid.size(), std::vector<Index>(nt, 0));
        s.total.assign(nt, 0);
        result.sweeps.push_back(std::move(s));
      }
    }
    // Each method's weight sweep, if it has one (index into result.sweeps).
    std::vector<std::size_t> sweep_of(methods_.size(), result.sweeps.size());
    for (std::size_t mi = 0, k = 0; mi < methods_.size(); ++mi)
      if (has_sweep(methods_[mi])) sweep_of[mi] = k++;
    const bool any_fit =
        std::any_of(methods_.begin(), methods_.end(), [](const Method& m) { return m.chosen_in_training(); });

    // Total work, for progress.
    std::size_t total_sets = 0;
    for (int f = 0; f < folds_; ++f) {
      total_sets += draws_count(f, settings_.repeats);
      if (any_fit)
        for (int g = 0; g < folds_; ++g)
          if (g != f) total_sets += draws_count(g, settings_.weight_repeats);
    }
    ProgressCounter counter(progress, total_sets);

    // The table with each fold's words, and with each inner fold's own
    // words under inner_codebooks: copied once per run, and the words
    // overwritten by every fold (the folds run one after another).
    TouchSet all = table_.touches;
    TouchSet inner_words;
    if (settings_.inner_codebooks) inner_words = table_.touches;

    for (int f = 0; f < folds_; ++f) {
      // Codebook from the training touches only.
      const std::vector<Index> train = training_of(f);
      const Index k = fit_words(train, all.words);
      result.vocabulary.push_back(k);

      // Fusion weights (and candidates) from inner folds of the training
      // explorations.
      std::vector<Method> chosen = methods_;
      std::vector<std::size_t> candidate(methods_.size(), 0);
      if (any_fit) {
        std::vector<std::vector<Draw>> inner_draws;
        std::vector<std::vector<DistanceTable>> inner_tables;
        for (int g = 0; g < folds_; ++g) {
          if (g == f) continue;
          const std::vector<Index> inner_train = inner_training_of(train, g);
          // The inner fold's own codebook (inner_codebooks), or the outer one.
          const Index inner_k = settings_.inner_codebooks ? fit_words(inner_train, inner_words.words) : k;
          const TouchSet& inner_all = settings_.inner_codebooks ? inner_words : all;
          Recognizer rec = fitted_recognizer(inner_all, inner_train, inner_k);
          auto draws = make_draws(f, g, settings_.weight_repeats, result);
          inner_tables.push_back(compute(rec, inner_all, draws, fitted_classifiers_, counter));
          inner_draws.push_back(std::move(draws));
        }
        parallel_for(chosen.size(), [&](std::size_t mi, unsigned) {
          if (chosen[mi].chosen_in_training())
            chosen[mi].fusion = choose(chosen[mi], inner_draws, inner_tables, candidate[mi]);
        });
      }

      // Outer test on the held-out exploration, with the chosen classifiers.
      Recognizer rec = fitted_recognizer(all, train, k);
      const auto draws = make_draws(f, -1, settings_.repeats, result);
      std::vector<Fusion> fused;
      for (const auto& m : chosen) fused.push_back(m.fusion);
      const std::vector<std::string> used = classifiers_of(fused);
      std::vector<double> seconds;
      const auto tables = compute(rec, all, draws, used, counter, &seconds);
      result.classifiers = rec.classifier_names();
      result.classifier_seconds.resize(seconds.size(), 0.0);
      result.classifier_tests.resize(seconds.size(), 0);
      for (std::size_t c = 0; c < seconds.size(); ++c) {
        result.classifier_seconds[c] += seconds[c];
        if (std::find(used.begin(), used.end(), result.classifiers[c]) != used.end())
          result.classifier_tests[c] += draws.size();
      }
      result.tests += draws.size();
      // Every method writes only its own MethodResult and sweep.
      parallel_for(chosen.size(), [&](std::size_t mi, unsigned) {
        MethodResult& r = result.methods[mi];
        r.fold_correct.emplace_back(nt, 0);
        r.fold_total.emplace_back(nt, 0);
        r.fold_expressions.push_back(chosen[mi].fusion.to_string());
        r.fold_weights.push_back(chosen[mi].fit_weights ? chosen[mi].fusion.weights() : std::vector<double>{});
        r.fold_candidates.push_back(candidate[mi]);
        for (std::size_t d = 0; d < draws.size(); ++d) {
          const Index guess = decide(chosen[mi].fusion.evaluate(tables[d]));
          const Draw& dr = draws[d];
          const bool ok = guess == dr.object;
          r.correct[dr.touch_index] += ok;
          r.total[dr.touch_index] += 1;
          r.fold_correct.back()[dr.touch_index] += ok;
          r.fold_total.back()[dr.touch_index] += 1;
          r.confusion[dr.touch_index](dr.object, guess) += 1;
        }
        if (sweep_of[mi] < result.sweeps.size()) {
          WeightSweep& s = result.sweeps[sweep_of[mi]];
          for (const auto& dr : draws) s.total[dr.touch_index] += 1;
          for (std::size_t g = 0; g < s.grid.size(); ++g) {
            const Fusion fg = methods_[mi].fusion.with_weights(s.grid[g]);
            for (std::size_t d = 0; d < draws.size(); ++d)
              s.correct[g][draws[d].touch_index] += decide(fg.evaluate(tables[d])) == draws[d].object;
          }
        }
      });
    }
    return result;
  }

 private:
  /// One test set: `touches` (indices into the table) of `object`, for
  /// settings.touches[touch_index].
  struct Draw {
    Index object = 0;
    std::size_t touch_index = 0;
    std::vector<Index> touches;
  };

  /// Rank (fold number) of touch i's exploration among its object's.
  int exploration_rank(Index i) const {
    const auto& ids = explorations_[static_cast<std::size_t>(table_.object[static_cast<std::size_t>(i)])];
    const auto it = std::lower_bound(ids.begin(), ids.end(), table_.exploration[static_cast<std::size_t>(i)]);
    return static_cast<int>(it - ids.begin());
  }

  /// The touches fold `fold` trains on (its codebook, references and inner
  /// folds): those of every exploration but the one of rank `fold`, in table
  /// order.
  std::vector<Index> training_of(int fold) const {
    std::vector<Index> train;
    for (Index i = 0; i < table_.size(); ++i)
      if (exploration_rank(i) != fold) train.push_back(i);
    return train;
  }

  /// Of a fold's training touches `train`, those its inner fold `inner`
  /// trains on: without the explorations of rank `inner`.
  std::vector<Index> inner_training_of(const std::vector<Index>& train, int inner) const {
    std::vector<Index> out;
    for (Index i : train)
      if (exploration_rank(i) != inner) out.push_back(i);
    return out;
  }

  std::size_t draws_count(int held_rank, int repeats) const {
    std::size_t n = 0;
    for (Index o = 0; o < static_cast<Index>(table_.objects.size()); ++o)
      if (!touches_of(o, held_rank).empty()) n += settings_.touches.size() * static_cast<std::size_t>(repeats);
    return n;
  }

  std::vector<Index> touches_of(Index object, int rank) const {
    std::vector<Index> out;
    if (rank >= static_cast<int>(explorations_[static_cast<std::size_t>(object)].size())) return out;
    const std::int64_t id = explorations_[static_cast<std::size_t>(object)][static_cast<std::size_t>(rank)];
    for (Index i = 0; i < table_.size(); ++i)
      if (table_.object[static_cast<std::size_t>(i)] == object && table_.exploration[static_cast<std::size_t>(i)] == id)
        out.push_back(i);
    return out;
  }

  /// Test sets drawn from exploration rank `inner` (or, for inner < 0, the
  /// fold's held-out rank `fold`) of every object.
  std::vector<Draw> make_draws(int fold, int inner, int repeats, CrossValidationResult& result) const {
    const int rank = inner < 0 ? fold : inner;
    std::vector<Draw> draws;
    for (Index o = 0; o < static_cast<Index>(table_.objects.size()); ++o) {
      const auto pool = touches_of(o, rank);
      // Every rank below folds() is an exploration with touches of every
      // object (folds() is the fewest explorations_of(), which lists only
      // explorations with touches), so a pool is never empty here.
      if (pool.empty()) continue;
      for (std::size_t t = 0; t < settings_.touches.size(); ++t) {
        for (int r = 0; r < repeats; ++r) {
          const std::uint64_t stream = draw_stream(fold, inner, o);
          const std::uint64_t sub = (static_cast<std::uint64_t>(settings_.touches[t]) << 20) ^ static_cast<std::uint64_t>(r);
          Rng rng = Rng::derive(settings_.seed, stream, sub);
          std::vector<Index> p = pool;
          const auto want = static_cast<std::size_t>(settings_.touches[t]);
          const std::size_t n = std::min(want, p.size());
          if (n < want && inner < 0) ++result.capped_draws;
          for (std::size_t i = 0; i < n; ++i) {  // partial Fisher-Yates
            const std::size_t j = i + static_cast<std::size_t>(rng.below(p.size() - i));
            std::swap(p[i], p[j]);
          }
          p.resize(n);
          draws.push_back(Draw{o, t, std::move(p)});
        }
      }
    }
    return draws;
  }

  /// Fits a copy of the quantizer on the features of the touches `train`
  /// and sets `words` to the word of every touch of the table; returns the
  /// codebook size.
  Index fit_words(const std::vector<Index>& train, WordIds& words) const {
    const Eigen::MatrixXf features = table_.touches.features(Eigen::all, train);
    Quantizer q = quantizer_;
    q.fit(features);
    words = assign_words(q, table_.touches.features);
    return static_cast<Index>(q.size());
  }

  Recognizer fitted_recognizer(const TouchSet& all, const std::vector<Index>& train, Index k) const {
    Recognizer rec(factory_(), settings_.normalization);
    const Index n_objects = static_cast<Index>(table_.objects.size());
    std::vector<std::vector<Index>> per_object(static_cast<std::size_t>(n_objects));
    for (Index i : train) per_object[static_cast<std::size_t>(table_.object[static_cast<std::size_t>(i)])].push_back(i);
    std::vector<TouchSet> objects;
    for (Index o = 0; o < n_objects; ++o) {
      if (per_object[static_cast<std::size_t>(o)].empty())
        throw InvalidArgument("table", "object '" + table_.objects[static_cast<std::size_t>(o)] +
                                           "' has no training touch in a fold");
      objects.push_back(select_touches(all, per_object[static_cast<std::size_t>(o)]));
    }
    rec.fit(objects, k);
    return rec;
  }

  /// Normalised distances of every draw, in parallel; identical for any
  /// thread count (each draw is computed independently). The draws are
  /// subsets of one pool, the union of their touches, which the classifiers
  /// prepare once (Classifier::prepare_pool: the registrations' first
  /// matches); the distances are those of each draw's own touch set. The
  /// preparation's time counts in `seconds`.
  std::vector<DistanceTable> compute(const Recognizer& rec, const TouchSet& all, const std::vector<Draw>& draws,
                                     const std::vector<std::string>& only, ProgressCounter& progress,
                                     std::vector<double>* seconds = nullptr) const {
    std::vector<Index> members;  // sorted union of the draws' touches (rows of `all`)
    for (const auto& d : draws) members.insert(members.end(), d.touches.begin(), d.touches.end());
    std::sort(members.begin(), members.end());
    members.erase(std::unique(members.begin(), members.end()), members.end());
    const TouchSet pool = select_touches(all, members);
    std::vector<double> prepare_seconds;
    const auto prepared =
        rec.prepare_pool(pool, only, seconds ? &prepare_seconds : nullptr, static_cast<unsigned>(settings_.threads));
    std::vector<DistanceTable> tables(draws.size());
    std::vector<std::vector<double>> worker_seconds(worker_count(draws.size()));
    parallel_for(draws.size(), [&](std::size_t d, unsigned worker) {
      std::vector<Index> subset;
      subset.reserve(draws[d].touches.size());
      for (Index t : draws[d].touches)
        subset.push_back(static_cast<Index>(std::lower_bound(members.begin(), members.end(), t) - members.begin()));
      tables[d] = rec.pool_distances(pool, prepared, subset, only, seconds ? &worker_seconds[worker] : nullptr);
      progress.tick();
    });
    if (seconds) {
      seconds->assign(rec.classifiers().size(), 0.0);
      for (std::size_t c = 0; c < prepare_seconds.size(); ++c) (*seconds)[c] += prepare_seconds[c];
      for (const auto& mine : worker_seconds)
        for (std::size_t c = 0; c < mine.size(); ++c) (*seconds)[c] += mine[c];
    }
    return tables;
  }

  /// Threads of this run for `count` items (see detail::worker_count).
  unsigned worker_count(std::size_t count) const {
    return detail::worker_count(static_cast<unsigned>(settings_.threads), count);
  }

  /// detail::parallel_for on this run's threads.
  template <typename Body>
  void parallel_for(std::size_t count, Body&& body) const {
    detail::parallel_for(count, static_cast<unsigned>(settings_.threads), std::forward<Body>(body));
  }

  bool has_sweep(const Method& m) const {
    return m.fit_weights && m.alternatives.empty() && settings_.weight_sweeps;
  }

  /// The candidate and grid weights with the highest inner-fold rate (ties:
  /// larger mean margin, then candidate order, then grid order); the index of
  /// the candidate goes to `index`.
  Fusion choose(const Method& m, const std::vector<std::vector<Draw>>& draws,
                const std::vector<std::vector<DistanceTable>>& tables, std::size_t& index) const {
    const auto candidates = m.candidates();
    std::optional<Fusion> best;
    Index best_correct = -1;
    double best_margin = -std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      const auto consider = [&](const Fusion& f) {
        Index correct = 0;
        double margin = 0;
        std::size_t count = 0;
        for (std::size_t s = 0; s < draws.size(); ++s)
          for (std::size_t d = 0; d < draws[s].size(); ++d) {
            const Eigen::VectorXd fused = f.evaluate(tables[s][d]);
            const Index truth = draws[s][d].object;
            correct += decide(fused) == truth;
            double other = std::numeric_limits<double>::infinity();
            for (Index j = 0; j < fused.size(); ++j)
              if (j != truth) other = std::min(other, fused(j));
            if (std::isfinite(other)) margin += other - fused(truth);
            ++count;
          }
        margin /= static_cast<double>(std::max<std::size_t>(count, 1));
        if (correct > best_correct || (correct == best_correct && margin > best_margin)) {
          best = f;
          index = c;
          best_correct = correct;
          best_margin = margin;
        }
      };
      if (m.fit_weights) {
        for (const auto& w : weight_grid(static_cast<int>(candidates[c].children().size()), settings_.weight_steps,
                                         settings_.zero_weights))
          consider(candidates[c].with_weights(w));
      } else {
        consider(candidates[c]);
      }
    }
    return *best;
  }

  const TouchTable& table_;
  ClassifierFactory factory_;
  Quantizer quantizer_;
  std::vector<Method> methods_;
  CrossValidationSettings settings_;
  int folds_ = 0;
  std::vector<std::vector<std::int64_t>> explorations_;
  std::vector<std::string> fitted_classifiers_;
};

}  // namespace iclap

// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/progress.hpp"
#include "iclap/core/random.hpp"
#include "iclap/core/types.hpp"
#include "iclap/search/brute_force.hpp"
#include "iclap/search/neighbor.hpp"
#include "iclap/tactile/quantizer.hpp"
#include "iclap/tactile/word_ordering.hpp"

namespace iclap {

/// What k-means does with a cluster that no feature is nearest to.
enum class EmptyClusterPolicy {
  /// Move the feature farthest from its own centre (among clusters that keep
  /// at least one member) into the empty cluster and put the centre on it:
  /// the worst-represented feature gets a word of its own. The default.
  ReseedFarthest,
  /// Leave the centre where it is; the word may stay unused. Reported in
  /// KMeansResult::empty_clusters.
  KeepCentre,
};

/// Why a k-means fit stopped. Stopping at the iteration limit is a normal
/// outcome, not an error: the codebook is usable, just not converged.
enum class KMeansStop {
  AssignmentsStable,  ///< no feature changed word: a fixed point of Lloyd's iteration
  RelativeChange,     ///< the inertia fell by at most relative_tolerance of itself
  MaxIterations,      ///< settings.max_iterations centre updates were made
};

inline const char* to_string(KMeansStop s) noexcept {
  switch (s) {
    case KMeansStop::AssignmentsStable: return "assignments_stable";
    case KMeansStop::RelativeChange: return "relative_change";
    case KMeansStop::MaxIterations: return "max_iterations";
  }
  return "unknown";
}

/// The outcome of KMeansQuantizer::fit.
struct KMeansResult {
  bool converged = false;  ///< stop != MaxIterations
  KMeansStop stop = KMeansStop::MaxIterations;
  int iterations = 0;      ///< centre updates made (Lloyd iterations)
  /// Sum over training features of the squared distance to their word's
  /// centre, at the final centres (feature units squared).
  double inertia = 0.0;
  /// Number of times a cluster was re-seeded (EmptyClusterPolicy::ReseedFarthest).
  Index reseeded = 0;
  /// Words with no training feature at the end (only possible with
  /// KeepCentre, or when re-seeding found no candidate).
  Index empty_clusters = 0;
  /// Feature-to-centre distances evaluated by the assignment steps. Plain
  /// Lloyd (no pruning) counts n * k per step, what brute force evaluates;
  /// with pruning, the fraction of that actually computed is the speed-up.
  std::int64_t distance_evaluations = 0;
  /// Assignment steps made (iterations + 1, or + 2 after a late re-seed).
  int assignment_steps = 0;
  /// Word of every training feature (in feature order, after any word
  /// ordering); equal to `assign(features.col(j))` for every j.
  WordIds labels;
  /// Training features per word.
  WordIds cluster_sizes;
};

namespace detail {
template <typename S, typename Scalar, int Dim, typename = void>
struct is_search_policy : std::false_type {};
template <typename S, typename Scalar, int Dim>
struct is_search_policy<
    S, Scalar, Dim,
    std::void_t<typename S::Settings,
                decltype(S(std::declval<Cloud<Scalar, Dim>>(), std::declval<const typename S::Settings&>())),
                decltype(std::declval<const S&>().nearest(std::declval<const Scalar*>()))>>
    : std::is_same<std::decay_t<decltype(std::declval<const S&>().nearest(std::declval<const Scalar*>()))>,
                   Neighbor<Scalar>> {};
}  // namespace detail

/// The paper's codebook (Section III): k-means clustering of the training
/// tactile features into k words; a feature's word is its nearest centre in
/// Euclidean distance. Models the Quantizer concept (quantizer.hpp).
///
/// Fit: k-means++ seeding (Arthur and Vassilvitskii 2007) drawn from
/// `iclap::Rng(settings.seed)`, then Lloyd iterations until no feature
/// changes word, or the inertia falls by at most `relative_tolerance` of
/// itself, or `max_iterations` centre updates. Single-threaded and
/// deterministic: the same features, settings and build give the same
/// codebook bit for bit on every run (sums in double, in feature order).
///
/// Assignment: `assign()` queries the `Search` policy built on the centres
/// (BruteForceSearch or KdTreeSearch from iclap/search; identical answers,
/// ties to the smaller word id). Brute force is the default: at the paper's
/// scale (k = 50 words, 72-D Tactile-SIFT) a kd-tree cannot prune in 72
/// dimensions and only adds traversal cost (benchmarks/bench_tactile.cpp).
///
/// Fit: with `pruning` off, each Lloyd step queries the policy for every
/// feature (plain Lloyd, O(n k d) per step). With `pruning` on (default), the
/// step is Elkan's algorithm ("Using the triangle inequality to accelerate
/// k-means", ICML 2003): per-feature lower bounds on the distance to every
/// centre, carried across iterations and lowered by each centre's movement,
/// skip most distance evaluations. It evaluates the policies' own distance
/// kernel with their tie rule, and every skip holds with a rounding margin,
/// so the labels, centres and iterations are bit-identical to plain Lloyd
/// with either policy (the test suite checks it); only faster. It keeps k
/// bounds per feature: O(n k) doubles of memory (3.4 MB at the paper's
/// scale); switch pruning off for very large n x k.
///
/// After fit(), assign() is const and thread-safe; copies are independent
/// (they share the search policy's immutable points or tree, which no fit
/// changes: a fit builds a new one).
template <typename Scalar = float, int Dim = Eigen::Dynamic, typename Search = BruteForceSearch<Scalar, Dim>>
class KMeansQuantizer {
  ICLAP_CHECK_SCALAR_AND_DIM(Scalar, Dim);
  static_assert(detail::is_search_policy<Search, Scalar, Dim>::value,
                "iclap: KMeansQuantizer's Search must be a search policy over Cloud<Scalar, Dim> such as "
                "iclap::BruteForceSearch<Scalar, Dim> or iclap::KdTreeSearch<Scalar, Dim> "
                "(Search(Cloud, Settings), nearest(const Scalar*) -> Neighbor<Scalar>)");

 public:
  /// Training features, one per column; also the centres (one per word).
  using Features = Cloud<Scalar, Dim>;
  using Feature = Point<Scalar, Dim>;
  using SearchPolicy = Search;

  struct Settings {
    /// Number of words (the paper uses 50), >= 1 and at most the number of
    /// distinct training features.
    Index k = 50;
    /// Seed of the k-means++ draw.
    std::uint64_t seed = 0;
    /// Maximum number of centre updates, >= 0.
    int max_iterations = 100;
    /// Stop when (previous - current inertia) <= relative_tolerance *
    /// previous inertia; >= 0 (0: only stable assignments or the limit stop).
    double relative_tolerance = 1e-6;
    EmptyClusterPolicy empty_clusters = EmptyClusterPolicy::ReseedFarthest;
    WordOrdering ordering = WordOrdering::None;
    /// Elkan's exact triangle-inequality pruning (see the class comment);
    /// false = plain Lloyd through the Search policy.
    bool pruning = true;
    typename Search::Settings search{};
  };

  /// Public, as in the rest of iclap: `q.settings.k = 50;` before fit().
  Settings settings;

  KMeansQuantizer() = default;
  explicit KMeansQuantizer(const Settings& s) : settings(s) {}

  /// A quantizer whose words are the given centres (one per column), e.g. a
  /// codebook read back from a file; settings.k becomes centres.cols() and
  /// settings.ordering is not applied. Throws EmptyInput / NonFiniteValue
  /// naming "centres", and what the Search throws for settings.search
  /// (naming "settings.search.X").
  static KMeansQuantizer from_centres(Features centres, const Settings& s = {}) {
    check_not_empty(centres, "centres");
    check_finite(centres, "centres");
    check_coordinate_range<Scalar>(centres, "centres");
    KMeansQuantizer q(s);
    q.settings.k = centres.cols();
    q.install(std::move(centres));
    return q;
  }

  /// Learns the codebook from `features` (one per column) with k-means++
  /// seeding. Throws, leaving the quantizer unchanged: EmptyInput naming
  /// "features"; NonFiniteValue naming "features" with the row (coordinate)
  /// and column (feature index) of the first NaN or infinity;
  /// InvalidArgument naming "features" for values whose squared distances
  /// the scalar type cannot hold (beyond largest_coordinate, or a spread
  /// below smallest_spread: see check.hpp); InvalidArgument naming "settings.k" when k < 1 or k exceeds the number
  /// of features or of distinct features (the message gives both numbers),
  /// or naming another setting out of range. `progress` gets (iteration,
  /// max_iterations). Cost O(iterations x n x k x d) without pruning; with
  /// it, late iterations cost little more than O(n x d).
  KMeansResult fit(const Features& features, const ProgressCallback& progress = {}) {
    check_before_seeding(features);
    Features centres = seed_plus_plus(features);
    return run(features, std::move(centres), progress);
  }

  /// Throws exactly what fit(features) would throw for these features and
  /// the current settings, without fitting (the quantizer is unchanged),
  /// so that a caller with many codebooks to fit (CrossValidation, one per
  /// fold) can refuse settings before the first: k beyond the distinct
  /// features, which fit() finds only while seeding, is found here by
  /// counting them. Cost O(n log n x d) for n features of dimension d.
  void check(const Features& features) const {
    check_before_seeding(features);
    const Index distinct = count_distinct(features);
    if (settings.k > distinct) throw too_many_words(distinct);
  }

  /// Same as fit() from user-chosen initial centres (one per column, exactly
  /// settings.k of them, same dimension as the features) instead of
  /// k-means++: a warm start from an older codebook, or a reproduction of
  /// another implementation's initialisation.
  /// Additionally throws DimensionMismatch / InvalidArgument naming
  /// "initial_centres", and InvalidArgument naming "settings.k" when k
  /// exceeds the number of distinct features.
  template <typename D1, typename D2>
  KMeansResult fit_from(const Eigen::MatrixBase<D1>& features, const Eigen::MatrixBase<D2>& initial_centres,
                        const ProgressCallback& progress = {}) {
    // Other Eigen types are copied into Features, rows checked, as fit()'s
    // overload below does.
    if constexpr (std::is_same_v<D1, Features> && std::is_same_v<D2, Features>)
      return fit_from_features(features.derived(), initial_centres.derived(), progress);
    else
      return fit_from_features(as_features(features, "features"), as_features(initial_centres, "initial_centres"),
                               progress);
  }

  /// fit(), check() and from_centres() for features or centres
  /// given as another Eigen type (a MatrixXf, a block, a map): with a fixed
  /// Dim their row count is checked first, DimensionMismatch naming the
  /// argument, since Eigen's conversion to Features does not check it in a
  /// release build (a 4-row matrix was read as 3 rows, a silent wrong
  /// codebook). The features are copied into Features.
  template <typename Derived, typename = std::enable_if_t<!std::is_same_v<Derived, Features>>>
  KMeansResult fit(const Eigen::MatrixBase<Derived>& features, const ProgressCallback& progress = {}) {
    return fit(as_features(features, "features"), progress);
  }
  template <typename Derived, typename = std::enable_if_t<!std::is_same_v<Derived, Features>>>
  void check(const Eigen::MatrixBase<Derived>& features) const {
    check(as_features(features, "features"));
  }
  template <typename Derived, typename = std::enable_if_t<!std::is_same_v<Derived, Features>>>
  static KMeansQuantizer from_centres(const Eigen::MatrixBase<Derived>& centres, const Settings& s = {}) {
    return from_centres(as_features(centres, "centres"), s);
  }

  /// Number of words (0 before fit).
  Index size() const noexcept { return centres_.cols(); }
  /// Feature dimension (0 before fit).
  Index dim() const noexcept { return centres_.rows(); }
  bool fitted() const noexcept { return centres_.cols() > 0; }
  /// The centre of each word, one per column, in word-id order.
  const Features& centres() const noexcept { return centres_; }
  /// The search structure over the centres (for batch or custom queries).
  const Search& search() const noexcept { return search_; }

  /// Word id in [0, size()) of the feature at `feature` (dim() values):
  /// the nearest centre, ties to the smaller id. The fast path: the feature
  /// is not checked. Throws InvalidArgument naming "quantizer" before fit.
  Index assign(const Scalar* feature) const { return nearest(feature).index; }

  /// Same for an Eigen vector; throws DimensionMismatch naming "feature" for
  /// a wrong length, NonFiniteValue for NaN or infinity and InvalidArgument
  /// for a value beyond largest_coordinate<Scalar>().
  template <typename Derived>
  Index assign(const Eigen::MatrixBase<Derived>& feature) const {
    return nearest(feature).index;
  }

  /// The nearest word and its squared distance (e.g. to reject features far
  /// from every word). Same contract as assign().
  Neighbor<Scalar> nearest(const Scalar* feature) const {
    if (!fitted()) throw InvalidArgument("quantizer", "is not fitted: call fit() first");
    return search_.nearest(feature);
  }

  template <typename Derived>
  Neighbor<Scalar> nearest(const Eigen::MatrixBase<Derived>& feature) const {
    static_assert(Derived::ColsAtCompileTime == 1 || Derived::ColsAtCompileTime == Eigen::Dynamic,
                  "iclap: assign() takes one feature (a column vector)");
    if (!fitted()) throw InvalidArgument("quantizer", "is not fitted: call fit() first");
    if (feature.cols() != 1) throw DimensionMismatch("feature.cols", 1, feature.cols());
    check_dimension(feature.rows(), dim(), "feature");
    // Checked as given, before the cast: a finite double beyond float's
    // range is out of range, not the inf its cast would be.
    check_finite(feature, "feature");
    check_coordinate_range<Scalar>(feature, "feature");
    const Feature f = feature.template cast<Scalar>();
    return search_.nearest(f.data());
  }

 private:
  /// Relative safety margin of the pruning tests: several times the worst
  /// relative rounding error of the d-term squared-distance kernel, so a
  /// skipped centre is strictly farther even in floating point.
  static double pruning_margin(Index d) noexcept {
    return 4.0 * static_cast<double>(d + 4) * static_cast<double>(std::numeric_limits<Scalar>::epsilon());
  }

  static double dist2(const Scalar* a, const Scalar* b, Index d) noexcept {
    return static_cast<double>(detail::squared_distance<Dim>(a, b, d));
  }

  void validate_settings() const {
    if (settings.k < 1) throw InvalidArgument("settings.k", "must be at least 1, got " + std::to_string(settings.k));
    if (settings.max_iterations < 0)
      throw InvalidArgument("settings.max_iterations",
                            "must be >= 0, got " + std::to_string(settings.max_iterations));
    if (!(settings.relative_tolerance >= 0.0) || !std::isfinite(settings.relative_tolerance))
      throw InvalidArgument("settings.relative_tolerance",
                            "must be finite and >= 0, got " + format_exact(settings.relative_tolerance));
  }

  /// Also refuses features the kernel's squared distances cannot hold in
  /// Scalar: a value beyond largest_coordinate (they overflow; a feature at
  /// infinite distance from every centre had no word, and its index -1 was
  /// used), or a spread below smallest_spread (they underflow: distinct
  /// features looked identical and the pruning's margins did not hold).
  KMeansResult fit_from_features(const Features& features, const Features& initial_centres,
                                 const ProgressCallback& progress) {
    validate_settings();
    check_features(features);
    check_not_empty(initial_centres, "initial_centres");
    check_dimension(initial_centres.rows(), features.rows(), "initial_centres");
    check_finite(initial_centres, "initial_centres");
    check_coordinate_range<Scalar>(initial_centres, "initial_centres");
    if (initial_centres.cols() != settings.k)
      throw InvalidArgument("initial_centres", "has " + std::to_string(initial_centres.cols()) +
                                                   " columns but settings.k is " + std::to_string(settings.k));
    check_search_settings(features);
    const Index distinct = count_distinct(features);
    if (settings.k > distinct) throw too_many_words(distinct);
    return run(features, initial_centres, progress);
  }

  /// `m` as Features, its row count checked against a fixed Dim first.
  template <typename Derived>
  static Features as_features(const Eigen::MatrixBase<Derived>& m, const char* argument) {
    static_assert(std::is_same_v<typename Derived::Scalar, Scalar>,
                  "iclap: KMeansQuantizer takes features of its own Scalar (cast them first)");
    return detail::checked_rows<Features>(m, argument);
  }

  static void check_features(const Features& features) {
    check_not_empty(features, "features");
    check_finite(features, "features");
    check_coordinate_range<Scalar>(features, "features");
    const auto spread = static_cast<double>((features.colwise() - features.col(0)).cwiseAbs().maxCoeff());
    if (spread > 0.0 && spread < smallest_spread<Scalar>())
      throw InvalidArgument("features", "largest coordinate difference is " + format_value(spread) + ", below " +
                                            format_value(smallest_spread<Scalar>()) +
                                            ": squared distances at this scale underflow the scalar type; rescale "
                                            "the features");
  }

  /// fit()'s checks before the k-means++ draw, which finds k beyond the
  /// distinct features itself.
  void check_before_seeding(const Features& features) const {
    validate_settings();
    check_features(features);
    const Index n = features.cols();
    if (settings.k > n)
      throw InvalidArgument("settings.k", "k = " + std::to_string(settings.k) +
                                              " exceeds the number of features (" + std::to_string(n) + ")");
    check_search_settings(features);
  }

  /// Refuses settings.search as building the Search of the centres would
  /// (make_search), before any k-means work: on one feature (checked), so
  /// that check() finds what fit() would, and fit() does not find it only
  /// after the whole run (with pruning, the search is built at the end).
  void check_search_settings(const Features& features) const { (void)make_search(features.leftCols(1)); }

  /// The Search of `centres` with settings.search. Its InvalidArgument
  /// naming "settings.X" (a setting of the search's own Settings) is thrown
  /// again naming "settings.search.X", the member the caller set.
  Search make_search(const Features& centres) const {
    return rename_argument_prefix("settings.", "settings.search.", [&] { return Search(centres, settings.search); });
  }

  InvalidArgument too_many_words(Index distinct) const {
    return InvalidArgument("settings.k", "k = " + std::to_string(settings.k) +
                                             " exceeds the number of distinct features (" +
                                             std::to_string(distinct) + ")");
  }

  /// Number of distinct columns of `features` (exact comparison).
  static Index count_distinct(const Features& features) {
    const Index n = features.cols();
    const Index d = features.rows();
    std::vector<Index> idx(static_cast<std::size_t>(n));
    for (Index j = 0; j < n; ++j) idx[static_cast<std::size_t>(j)] = j;
    const auto less = [&](Index a, Index b) {
      for (Index i = 0; i < d; ++i) {
        if (features(i, a) < features(i, b)) return true;
        if (features(i, b) < features(i, a)) return false;
      }
      return false;
    };
    std::sort(idx.begin(), idx.end(), less);
    Index distinct = n > 0 ? 1 : 0;
    for (std::size_t j = 1; j < idx.size(); ++j)
      if (less(idx[j - 1], idx[j])) ++distinct;
    return distinct;
  }

  /// k-means++: the first centre uniformly, each next one with probability
  /// proportional to the squared distance to the nearest chosen centre.
  /// Chosen centres are distinct features; when every feature already
  /// coincides with one before k are chosen, k exceeds the number of
  /// distinct features, which is exactly the number chosen so far.
  Features seed_plus_plus(const Features& features) const {
    const Index n = features.cols();
    const Index d = features.rows();
    const Index k = settings.k;
    Rng rng(settings.seed);
    Features centres(d, k);
    std::vector<double> d2(static_cast<std::size_t>(n));
    Index chosen = static_cast<Index>(rng.below(static_cast<std::uint64_t>(n)));
    centres.col(0) = features.col(chosen);
    for (Index i = 0; i < n; ++i)
      d2[static_cast<std::size_t>(i)] = dist2(features.col(i).data(), centres.col(0).data(), d);
    for (Index c = 1; c < k; ++c) {
      double total = 0.0;
      for (const double v : d2) total += v;
      if (!(total > 0.0)) {
        // Every feature is at squared distance 0 from a chosen centre: k
        // exceeds the distinct features (c of them), or distinct features
        // differ by less than squared distances in Scalar resolve (below
        // about 1e-162 in double). Then the next distinct one in order is
        // taken, so that fit accepts what check() (an exact count) does.
        chosen = first_unchosen(features, centres, c);
        if (chosen < 0) throw too_many_words(c);
        centres.col(c) = features.col(chosen);
        continue;
      }
      const double target = rng.uniform() * total;
      double cumulative = 0.0;
      chosen = -1;
      for (Index i = 0; i < n; ++i) {
        const double v = d2[static_cast<std::size_t>(i)];
        if (v <= 0.0) continue;
        chosen = i;  // the last candidate, should rounding leave target unreached
        cumulative += v;
        if (cumulative > target) break;
      }
      centres.col(c) = features.col(chosen);
      for (Index i = 0; i < n; ++i) {
        double& v = d2[static_cast<std::size_t>(i)];
        v = std::min(v, dist2(features.col(i).data(), centres.col(c).data(), d));
      }
    }
    return centres;
  }

  /// The first feature equal to none of the first `c` centres, or -1.
  static Index first_unchosen(const Features& features, const Features& centres, Index c) {
    for (Index i = 0; i < features.cols(); ++i) {
      bool unchosen = true;
      for (Index j = 0; j < c && unchosen; ++j) unchosen = features.col(i) != centres.col(j);
      if (unchosen) return i;
    }
    return -1;
  }

  /// Lloyd's iteration from `centres`; installs the result on success.
  KMeansResult run(const Features& features, Features centres, const ProgressCallback& progress) {
    const Index n = features.cols();
    const Index d = features.rows();
    const Index k = settings.k;

    KMeansResult result;
    WordIds labels = WordIds::Constant(n, -1);
    WordIds sizes = WordIds::Zero(k);
    std::vector<double> d2(static_cast<std::size_t>(n), 0.0);
    Eigen::Matrix<double, Dim, Eigen::Dynamic> sums(d, k);

    // Elkan's bounds (pruning only). All distances below are Euclidean (not
    // squared) and in double; `lower(j, i)` never exceeds the true distance
    // from feature i to centre j, and every test that skips a distance
    // evaluation holds with a relative margin m (several times the rounding
    // error of the distance kernel) plus an absolute slack eta (rounding of
    // the bound updates), so a skipped centre is strictly farther than the
    // current best in the kernel's own floating-point distances too. Hence
    // the labels are exactly those of a brute-force search.
    const double m = pruning_margin(d);
    double radius = 0.0;
    for (Index i = 0; i < n; ++i) radius = std::max(radius, features.col(i).template cast<double>().norm());
    for (Index j = 0; j < k; ++j) radius = std::max(radius, centres.col(j).template cast<double>().norm());
    const double eta = 16.0 * std::numeric_limits<double>::epsilon() * (settings.max_iterations + 2.0) * 2.0 * radius;
    Eigen::MatrixXd lower;           // k x n, built on the first step
    Features bound_centres;          // the centres the bounds refer to
    Eigen::MatrixXd half_gap(k, k);  // lower bounds on half the centre-centre distances
    std::vector<double> nearest_half(static_cast<std::size_t>(k));
    const auto lower_from = [m](Scalar squared) { return std::sqrt(static_cast<double>(squared)) * (1.0 - m); };
    const auto upper_from = [m, eta](Scalar squared) { return std::sqrt(static_cast<double>(squared)) * (1.0 + m) + eta; };
    const auto kernel = [d](const Scalar* a, const Scalar* b) { return detail::squared_distance<Dim>(a, b, d); };

    // Records feature i's new word; returns 1 when it changed.
    const auto set_label = [&](Index i, Index word, Scalar squared) -> Index {
      const Index changed = word != labels[i] ? 1 : 0;
      labels[i] = word;
      d2[static_cast<std::size_t>(i)] = static_cast<double>(squared);
      return changed;
    };
    const auto count_sizes = [&]() {
      sizes.setZero();
      for (Index i = 0; i < n; ++i) ++sizes[labels[i]];
    };

    // Plain Lloyd step: every feature is a query to the Search policy.
    const auto assign_with_policy = [&]() {
      const Search search = make_search(centres);
      Index changed = 0;
      for (Index i = 0; i < n; ++i) {
        const Neighbor<Scalar> nb = search.nearest(features.col(i).data());
        changed += set_label(i, nb.index, nb.squared_distance);
      }
      result.distance_evaluations += static_cast<std::int64_t>(n) * k;
      count_sizes();
      return changed;
    };

    // First bounded step: every distance, which also initialises the bounds.
    // Same kernel, same order and same tie rule as BruteForceSearch.
    const auto assign_all_distances = [&]() {
      lower.resize(k, n);
      Index changed = 0;
      for (Index i = 0; i < n; ++i) {
        const Scalar* x = features.col(i).data();
        Index best = -1;
        Scalar best_d2 = std::numeric_limits<Scalar>::infinity();
        for (Index j = 0; j < k; ++j) {
          const Scalar dj = kernel(x, centres.col(j).data());
          lower(j, i) = lower_from(dj);
          if (detail::closer(dj, j, best_d2, best)) {
            best = j;
            best_d2 = dj;
          }
        }
        changed += set_label(i, best, best_d2);
      }
      result.distance_evaluations += static_cast<std::int64_t>(n) * k;
      bound_centres = centres;
      count_sizes();
      return changed;
    };

    // Later bounded steps (Elkan 2003).
    const auto assign_with_bounds = [&]() {
      // Centres moved since the bounds were made (updates and re-seeds):
      // every lower bound to centre j drops by j's movement.
      for (Index j = 0; j < k; ++j) {
        const Scalar moved = kernel(bound_centres.col(j).data(), centres.col(j).data());
        if (moved > Scalar(0)) lower.row(j).array() = (lower.row(j).array() - upper_from(moved)).max(0.0);
      }
      bound_centres = centres;
      for (Index j = 0; j < k; ++j) {
        half_gap(j, j) = 0.0;
        for (Index o = j + 1; o < k; ++o)
          half_gap(j, o) = half_gap(o, j) = 0.5 * lower_from(kernel(centres.col(j).data(), centres.col(o).data()));
      }
      for (Index j = 0; j < k; ++j) {
        double nearest = std::numeric_limits<double>::infinity();
        for (Index o = 0; o < k; ++o)
          if (o != j) nearest = std::min(nearest, half_gap(j, o));
        nearest_half[static_cast<std::size_t>(j)] = nearest;
      }
      Index changed = 0;
      std::int64_t evaluations = 0;
      for (Index i = 0; i < n; ++i) {
        const Scalar* x = features.col(i).data();
        Index best = labels[i];
        Scalar best_d2 = kernel(x, centres.col(best).data());  // exact: needed for the inertia anyway
        ++evaluations;
        lower(best, i) = lower_from(best_d2);
        double upper = upper_from(best_d2);
        // Elkan's lemma 1: nearer to its own centre than half the gap to
        // any other centre, so that centre is the strictly nearest.
        if (upper < nearest_half[static_cast<std::size_t>(best)] - eta) {
          d2[static_cast<std::size_t>(i)] = static_cast<double>(best_d2);
          continue;
        }
        const Index own = best;
        for (Index j = 0; j < k; ++j) {
          if (j == own) continue;
          // Lemma 2 (bound) and lemma 1 against the current best.
          if (lower(j, i) - eta > upper || half_gap(best, j) - eta > upper) continue;
          const Scalar dj = kernel(x, centres.col(j).data());
          ++evaluations;
          lower(j, i) = lower_from(dj);
          if (detail::closer(dj, j, best_d2, best)) {
            best = j;
            best_d2 = dj;
            upper = upper_from(dj);
          }
        }
        changed += set_label(i, best, best_d2);
      }
      result.distance_evaluations += evaluations;
      count_sizes();
      return changed;
    };

    bool bounds_ready = false;
    const auto assign_step = [&]() -> Index {
      ++result.assignment_steps;
      if (!settings.pruning) return assign_with_policy();
      if (!bounds_ready) {
        bounds_ready = true;
        return assign_all_distances();
      }
      return assign_with_bounds();
    };

    // Empty clusters after an assignment step; returns how many were re-seeded.
    const auto fix_empty = [&]() {
      Index reseeded = 0;
      if (settings.empty_clusters != EmptyClusterPolicy::ReseedFarthest) return reseeded;
      for (Index j = 0; j < k; ++j) {
        if (sizes[j] > 0) continue;
        Index farthest = -1;
        for (Index i = 0; i < n; ++i) {
          if (sizes[labels[i]] < 2) continue;
          if (farthest < 0 || d2[static_cast<std::size_t>(i)] > d2[static_cast<std::size_t>(farthest)]) farthest = i;
        }
        if (farthest < 0 || !(d2[static_cast<std::size_t>(farthest)] > 0.0)) continue;  // nothing to give
        --sizes[labels[farthest]];
        labels[farthest] = j;
        sizes[j] = 1;
        d2[static_cast<std::size_t>(farthest)] = 0.0;
        centres.col(j) = features.col(farthest);
        ++reseeded;
      }
      return reseeded;
    };

    const auto update_centres = [&]() {
      sums.setZero();
      for (Index i = 0; i < n; ++i) sums.col(labels[i]) += features.col(i).template cast<double>();
      for (Index j = 0; j < k; ++j)
        if (sizes[j] > 0) centres.col(j) = (sums.col(j) / static_cast<double>(sizes[j])).template cast<Scalar>();
    };

    const auto inertia = [&]() {
      double sum = 0.0;
      for (const double v : d2) sum += v;
      return sum;
    };

    const auto max_iterations = static_cast<std::size_t>(settings.max_iterations);
    assign_step();
    Index reseeded_now = fix_empty();
    result.reseeded += reseeded_now;
    double previous = inertia();
    if (progress) progress(0, max_iterations);
    bool stopped = false;
    for (int it = 1; it <= settings.max_iterations; ++it) {
      update_centres();
      const Index changed = assign_step();
      reseeded_now = fix_empty();
      result.reseeded += reseeded_now;
      result.iterations = it;
      const double current = inertia();
      if (progress) progress(static_cast<std::size_t>(it), max_iterations);
      if (reseeded_now == 0) {
        if (changed == 0) {
          result.stop = KMeansStop::AssignmentsStable;
          stopped = true;
        } else if (previous - current <= settings.relative_tolerance * previous) {
          result.stop = KMeansStop::RelativeChange;
          stopped = true;
        }
      }
      previous = current;
      if (stopped) break;
    }
    if (!stopped) {
      result.stop = KMeansStop::MaxIterations;
      // A re-seed in the last step moved a centre after the features were
      // assigned: assign once more so labels match assign() exactly.
      if (reseeded_now > 0) assign_step();
    }
    if (progress && result.iterations < settings.max_iterations) progress(max_iterations, max_iterations);
    result.converged = result.stop != KMeansStop::MaxIterations;
    result.inertia = inertia();
    result.empty_clusters = static_cast<Index>((sizes.array() == 0).count());

    // Optional renumbering of the words (word_ordering.hpp).
    const std::vector<Index> order = word_order(centres, settings.ordering);
    bool renumbered = false;
    Features ordered(d, k);
    for (Index j = 0; j < k; ++j) {
      const Index old = order[static_cast<std::size_t>(j)];
      renumbered = renumbered || old != j;
      ordered.col(j) = centres.col(old);
    }
    install(std::move(ordered));
    if (!renumbered) {
      result.labels = std::move(labels);
      result.cluster_sizes = std::move(sizes);
    } else {
      // A feature equally close to two words went to the smaller old id;
      // assign() gives it the smaller new one. The labels are taken from the
      // installed search so that they equal assign() (ties are the only
      // features whose word is not the renumbered old one; the inertia is
      // the same).
      result.labels.resize(n);
      result.cluster_sizes = WordIds::Zero(k);
      for (Index i = 0; i < n; ++i) {
        result.labels[i] = search_.nearest(features.col(i).data()).index;
        ++result.cluster_sizes[result.labels[i]];
      }
    }
    return result;
  }

  void install(Features centres) {
    Search search = make_search(centres);
    centres_ = std::move(centres);
    search_ = std::move(search);
  }

  Features centres_;
  Search search_;
};

}  // namespace iclap

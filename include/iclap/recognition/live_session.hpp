// SPDX-License-Identifier: MIT
#pragma once

/// Live recognition (the paper's Discussion, "Haptic exploration"): the
/// ranking of the known objects is updated after every touch, and the
/// exploration stops as soon as the decision is confident enough instead of
/// after a fixed number of touches.
///
///  - LiveReferences: what a live run recognises against, built once from a
///    training touch table (codebook, one reference touch set per object,
///    fitted recogniser, the fusion to apply).
///  - LiveSession: the touches of one exploration so far and the ranking
///    they give; add_touch() recomputes it.
///  - LiveTouch: one touch as a session receives it (position, descriptor,
///    word and, when the pad orientation is known, the pad normal and the
///    contact points that the height and patch classifiers need).
///  - LiveStopRule: when to stop (confidence threshold, touch limits).
///  - choose_live_weights(): fusion weights for a method whose weights are
///    fitted, by leave-one-exploration-out grid search on the references
///    (reuses CrossValidation).
///  - evaluate_live_stopping(): replays held-out explorations touch by touch
///    in time order and measures the stop rule against fixed touch counts.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numeric>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/parallel.hpp"
#include "iclap/core/progress.hpp"
#include "iclap/recognition/cross_validation.hpp"
#include "iclap/recognition/fusion.hpp"
#include "iclap/recognition/methods.hpp"
#include "iclap/recognition/normalization.hpp"
#include "iclap/recognition/recognizer.hpp"
#include "iclap/recognition/touch_set.hpp"
#include "iclap/recognition/touch_table.hpp"
#include "iclap/tactile/kmeans.hpp"
#include "iclap/tactile/quantizer.hpp"

namespace iclap {

/// One touch as a live session receives it. `position`: pad centre
/// (metres, the references' frame); `feature`: its descriptor (of the
/// references' length when a classifier of the fusion reads descriptors,
/// Classifier::descriptor_length; else it may be empty); `word`: its codebook
/// word. When the pad orientation is known (a dataset with qw..qz, the
/// Phantom Omni's gimbal), `normal` is the pad's z axis in the world (unit;
/// the height classifier needs it) and `contact_points` the world positions
/// of the pressed taxels (`append_contact_points`; the patch classifiers
/// need them, and a touch without any stands for one at its position) and
/// `free_points` those of the other taxels (`append_free_points`; the
/// occupancy classifier needs them). Without a normal the orientation is
/// unknown and both are ignored. Build one with `live_touch_of`.
struct LiveTouch {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::VectorXf feature;
  Index word = 0;
  std::optional<Eigen::Vector3d> normal;
  Eigen::Matrix3Xd contact_points;
  Eigen::Matrix3Xd free_points;
};

/// The touch of a contact frame: its position and, when the frame has an
/// orientation, the pad normal, the taxels above `contact_threshold` and the
/// others placed with `pitch` (as `make_touch_table` does); `feature` and
/// `word` are the caller's. Throws InvalidArgument naming
/// "contact_threshold" unless it is finite and >= 0, "pitch" unless it is
/// in (0, kLargestTaxelPitch] metres, and "frame.orientation" for an
/// orientation that is not a unit quaternion.
inline LiveTouch live_touch_of(const Frame& frame, double contact_threshold, double pitch, Eigen::VectorXf feature,
                               Index word) {
  detail::check_taxel_placement(frame, contact_threshold, "contact_threshold", pitch);
  LiveTouch t;
  t.position = frame.position;
  t.feature = std::move(feature);
  t.word = word;
  if (frame.orientation) {
    t.normal = frame.orientation->normalized() * Eigen::Vector3d::UnitZ();
    auto as_matrix = [](const std::vector<Eigen::Vector3d>& points) {
      Eigen::Matrix3Xd m(3, static_cast<Index>(points.size()));
      for (std::size_t k = 0; k < points.size(); ++k) m.col(static_cast<Index>(k)) = points[k];
      return m;
    };
    std::vector<Eigen::Vector3d> points;
    detail::place_taxels(frame, contact_threshold, pitch, true, points);
    t.contact_points = as_matrix(points);
    points.clear();
    detail::place_taxels(frame, contact_threshold, pitch, false, points);
    t.free_points = as_matrix(points);
  }
  return t;
}

/// Touch `i` of `touches` (position, descriptor, and the normal, contact
/// and free points when the set has normals) with codebook word `word`.
inline LiveTouch live_touch_of(const TouchSet& touches, Index i, Index word) {
  if (i < 0 || i >= touches.size())
    throw InvalidArgument("i", "touch " + std::to_string(i) + " is outside [0, " + std::to_string(touches.size()) + ")");
  LiveTouch t;
  t.position = touches.positions.col(i);
  if (touches.features.size() > 0) t.feature = touches.features.col(i);
  t.word = word;
  if (touches.has_normals()) t.normal = touches.normals.col(i).eval();
  if (touches.has_normals() && touches.has_contacts()) {
    const Index begin = touches.contact_offsets[static_cast<std::size_t>(i)];
    const Index end = touches.contact_offsets[static_cast<std::size_t>(i) + 1];
    t.contact_points = touches.contact_points.middleCols(begin, end - begin);
  }
  if (touches.has_normals() && touches.has_free())
    t.free_points = touches.free_points.middleCols(touches.free_offsets[static_cast<std::size_t>(i)], touches.free_of(i));
  return t;
}

/// When a live exploration stops: as soon as the decision's confidence
/// (decision_confidence of the fused distances) reaches `confidence` after
/// at least `min_touches` touches, or after `max_touches` touches (0: no
/// limit; the source running out also ends a run, which the caller sees).
struct LiveStopRule {
  double confidence = 0.5;  ///< in [0, 1]; 0 stops at min_touches, above 1 never (not allowed)
  Index min_touches = 1;    ///< >= 1
  Index max_touches = 0;    ///< 0: no limit; otherwise >= min_touches

  /// Throws InvalidArgument naming the member and the value.
  void validate() const {
    if (!(confidence >= 0 && confidence <= 1))
      throw InvalidArgument("confidence", "must be in [0, 1], got " + format_exact(confidence));
    if (min_touches < 1) throw InvalidArgument("min_touches", "must be >= 1, got " + std::to_string(min_touches));
    if (max_touches < 0 || (max_touches > 0 && max_touches < min_touches))
      throw InvalidArgument("max_touches", "must be 0 (no limit) or >= min_touches (" + std::to_string(min_touches) +
                                               "), got " + std::to_string(max_touches));
  }
};

/// Why a live session asks to stop.
enum class LiveStop {
  kContinue,   ///< not yet: take another touch
  kConfident,  ///< the confidence reached the threshold (after min_touches)
  kTouchLimit  ///< max_touches touches taken without a confident decision
};

inline const char* to_string(LiveStop s) noexcept {
  switch (s) {
    case LiveStop::kContinue: return "continue";
    case LiveStop::kConfident: return "confident";
    case LiveStop::kTouchLimit: return "touch limit";
  }
  return "unknown";
}

/// The object order of `fused` distances, best (smallest) first; ties keep
/// the smaller index first, like decide(). O(N log N).
inline std::vector<Index> rank_objects(const Eigen::Ref<const Eigen::VectorXd>& fused) {
  std::vector<Index> order(static_cast<std::size_t>(fused.size()));
  std::iota(order.begin(), order.end(), Index{0});
  std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) { return fused(a) < fused(b); });
  return order;
}

namespace detail {
/// Throws InvalidArgument naming `argument` unless `n` is L2, the only
/// normalisation live recognition takes.
inline void check_live_normalization(Normalization n, const std::string& argument) {
  if (n != Normalization::L2)
    throw InvalidArgument(argument, std::string("live recognition needs l2 normalisation (got ") + iclap::to_string(n) +
                                        "): its confidence 1 - d1/d2 needs distances whose 0 is a perfect match");
}
}  // namespace detail

/// The incremental recognition state of one live exploration: the touches
/// so far (positions, descriptors, words, and normals and contact points when
/// the pad orientation is known) and, after each add_touch(), the
/// normalised distances of every classifier the fusion uses, the fused
/// distances, the ranking, the best guess and its confidence.
///
/// Every update recognises all touches so far from scratch with the
/// recogniser (normalisation is over the objects, so it cannot be updated
/// per touch; registration restarts from the identity), so the state after n
/// touches equals `recognizer.distances()` of the same n touches: O(cost of
/// one recognition of n touches) per update. The recogniser must be fitted,
/// must outlive the session and must not be refitted while it is in use.
/// Not thread-safe (sessions on the same recogniser in different threads
/// are: the recogniser's distances are const).
class LiveSession {
 public:
  /// `vocabulary`: the codebook size the recogniser was fitted with, to
  /// check words (0: unchecked). Throws InvalidArgument for an unfitted
  /// recogniser, one that does not normalise by the L2 norm (naming
  /// "normalization": the confidence 1 - d1/d2 needs distances whose 0 is a
  /// perfect match; min-max puts every classifier's best object at 0, so
  /// its confidence would always be 1, and z-scores are signed), a fusion
  /// that needs a classifier the recogniser lacks, or an invalid stop rule.
  LiveSession(const Recognizer& recognizer, Fusion fusion, LiveStopRule rule = {}, Index vocabulary = 0)
      : recognizer_(&recognizer),
        fusion_(std::move(fusion)),
        rule_(rule),
        vocabulary_(vocabulary),
        only_(fusion_.classifiers()) {
    rule_.validate();
    if (vocabulary_ < 0) throw InvalidArgument("vocabulary", "must be >= 0, got " + std::to_string(vocabulary_));
    if (recognizer.objects() < 1) throw InvalidArgument("recognizer", "is not fitted (no object to recognise)");
    detail::check_live_normalization(recognizer.normalization(), "normalization");
    recognizer.check({Method{fusion_.to_string(), fusion_, false, {}}});
    descriptor_length_ = recognizer.descriptor_length(only_);
    touches_.positions.resize(3, 0);
  }

  /// Adds one touch and updates the ranking. Every touch of a session
  /// carries the same information: descriptors of one length (the
  /// references', Recognizer::descriptor_length, when a classifier of the
  /// fusion reads them: checked from the first touch on), and the pad
  /// orientation (a normal, with the contact points) on every touch or on
  /// none (the first touch decides). Throws NonFiniteValue /
  /// DimensionMismatch / InvalidArgument naming the field ("position",
  /// "feature", "word", "normal", "contact_points", "free_points"), and whatever the
  /// classifiers throw for a touch they cannot use (e.g. height without a
  /// normal); the session is unchanged then.
  LiveStop add_touch(const LiveTouch& touch) {
    check_finite(touch.position, "position");
    check_finite(touch.feature, "feature");
    if (touch.word < 0 || (vocabulary_ > 0 && touch.word >= vocabulary_))
      throw InvalidArgument("word", std::to_string(touch.word) + " is outside [0, " +
                                        (vocabulary_ > 0 ? std::to_string(vocabulary_) : std::string("inf")) + ")");
    const Index n = touches_.size();
    if (descriptor_length_ > 0) check_dimension(touch.feature.size(), descriptor_length_, "feature");
    if (n > 0) check_dimension(touch.feature.size(), touches_.features.rows(), "feature");
    if (touch.normal) {
      check_finite(*touch.normal, "normal");
      if (std::abs(touch.normal->norm() - 1.0) > 1e-6)
        throw InvalidArgument("normal", "is not a unit vector (norm " + format_exact(touch.normal->norm()) + ")");
    }
    if (touch.normal) {
      check_finite(touch.contact_points, "contact_points");
      check_finite(touch.free_points, "free_points");
    }
    if (n > 0 && touch.normal.has_value() != touches_.has_normals())
      throw InvalidArgument("normal", std::string("touch ") + std::to_string(n + 1) +
                                          (touch.normal ? " has a pad normal but the earlier touches have none"
                                                        : " has no pad normal but the earlier touches have one"));
    TouchSet next = touches_;
    next.positions.conservativeResize(3, n + 1);
    next.positions.col(n) = touch.position;
    if (touch.feature.size() > 0) {
      next.features.conservativeResize(touch.feature.size(), n + 1);
      next.features.col(n) = touch.feature;
    }
    next.words.conservativeResize(n + 1);
    next.words(n) = touch.word;
    if (touch.normal) {
      next.normals.conservativeResize(3, n + 1);
      next.normals.col(n) = *touch.normal;
    }
    if (touch.normal) {
      auto append = [n](Eigen::Matrix3Xd& points, std::vector<Index>& offsets, const Eigen::Matrix3Xd& more) {
        const Index m = more.cols(), c = points.cols();
        if (n == 0) offsets.assign(1, 0);
        points.conservativeResize(3, c + m);
        points.rightCols(m) = more;
        offsets.push_back(c + m);
      };
      append(next.contact_points, next.contact_offsets, touch.contact_points);
      append(next.free_points, next.free_offsets, touch.free_points);
    }
    DistanceTable table = recognizer_->distances(next, only_);  // throws before anything changes
    Eigen::VectorXd fused = fusion_.evaluate(table);
    touches_ = std::move(next);
    table_ = std::move(table);
    fused_ = std::move(fused);
    ranking_ = rank_objects(fused_);
    confidence_ = decision_confidence(fused_);
    history_.push_back(Step{ranking_.front(), confidence_});
    return stop();
  }

  /// A touch without pad orientation: `add_touch(LiveTouch{position,
  /// feature, word})`.
  LiveStop add_touch(const Eigen::Vector3d& position, const Eigen::Ref<const Eigen::VectorXf>& feature, Index word) {
    LiveTouch t;
    t.position = position;
    t.feature = feature;
    t.word = word;
    return add_touch(t);
  }

  /// The session keeps a pointer to the recogniser: a temporary one would
  /// dangle, so it does not compile.
  LiveSession(const Recognizer&& recognizer, Fusion fusion, LiveStopRule rule = {}, Index vocabulary = 0) = delete;

  /// Forgets every touch (a new exploration with the same references).
  void reset() {
    touches_ = TouchSet{};
    touches_.positions.resize(3, 0);
    table_.clear();
    fused_.resize(0);
    ranking_.clear();
    confidence_ = 0;
    history_.clear();
  }

  /// Whether to stop now (kContinue before the first touch).
  LiveStop stop() const {
    const Index n = touches();
    if (n == 0) return LiveStop::kContinue;
    if (n >= rule_.min_touches && confidence_ >= rule_.confidence) return LiveStop::kConfident;
    if (rule_.max_touches > 0 && n >= rule_.max_touches) return LiveStop::kTouchLimit;
    return LiveStop::kContinue;
  }

  Index touches() const noexcept { return touches_.size(); }
  Index objects() const { return recognizer_->objects(); }
  /// The recognised object (index into the references' objects), -1 before
  /// the first touch.
  Index best() const noexcept { return ranking_.empty() ? -1 : ranking_.front(); }
  /// decision_confidence() of the fused distances: the relative margin
  /// 1 - best / second best, in [0, 1]; 0 before the first touch.
  double confidence() const noexcept { return confidence_; }
  /// Objects, best first (empty before the first touch).
  const std::vector<Index>& ranking() const noexcept { return ranking_; }
  /// Fused distance of every object (empty before the first touch).
  const Eigen::VectorXd& fused() const noexcept { return fused_; }
  /// Normalised distances of each classifier the fusion uses.
  const DistanceTable& distances() const noexcept { return table_; }
  /// The touches so far, in the order added.
  const TouchSet& touch_set() const noexcept { return touches_; }
  const Fusion& fusion() const noexcept { return fusion_; }
  const LiveStopRule& rule() const noexcept { return rule_; }

  /// Best object and confidence after each touch so far (element n - 1:
  /// after n touches).
  struct Step {
    Index best = -1;
    double confidence = 0;
  };
  const std::vector<Step>& history() const noexcept { return history_; }

 private:
  const Recognizer* recognizer_;
  Fusion fusion_;
  LiveStopRule rule_;
  Index vocabulary_ = 0;
  std::vector<std::string> only_;
  Index descriptor_length_ = 0;  // the fusion's classifiers' (0: none reads descriptors)
  TouchSet touches_;
  DistanceTable table_;
  Eigen::VectorXd fused_;
  std::vector<Index> ranking_;
  double confidence_ = 0;
  std::vector<Step> history_;
};

/// What a live run recognises against: the objects of a training touch
/// table, the codebook fitted on its training touches, one reference touch
/// set per object, the recogniser fitted on them, and the fusion to apply
/// (fixed weights: choose fitted ones first, see choose_live_weights).
///
/// Immutable after construction; word() and the recogniser's distances are
/// const and thread-safe, so sessions in several threads may share it.
template <typename Quantizer = KMeansQuantizer<float>>
class LiveReferences {
  ICLAP_CHECK_QUANTIZER(Quantizer, Eigen::MatrixXf);

 public:
  /// Builds the references from the touches `train` of `table` (indices;
  /// empty: every touch): fits a copy of `quantizer` on their descriptors,
  /// gives every touch its word, fits the classifiers `factory` makes on one
  /// touch set per object. Throws InvalidArgument naming "table" for a table
  /// of fewer than 2 objects (check_objects_to_choose_among: a session among
  /// one object would be confident of it after any touch) and when an
  /// object has no training touch, "train" for an index outside the table or
  /// listed twice, "factory" when it is empty, and what the recogniser
  /// throws for a fusion it cannot evaluate.
  LiveReferences(const TouchTable& table, const std::vector<Index>& train, const ClassifierFactory& factory,
                 Quantizer quantizer, Fusion fusion, Normalization normalization = Normalization::L2)
      : objects_(table.objects),
        quantizer_(std::move(quantizer)),
        recognizer_(make(factory), normalization),
        fusion_(std::move(fusion)),
        feature_length_(table.touches.features.rows()) {
    if (table.size() == 0) throw EmptyInput("table", "holds no touch");
    table.validate("table");
    check_objects_to_choose_among(table.objects, "table");
    recognizer_.check({Method{fusion_.to_string(), fusion_, false, {}}});
    std::vector<Index> all;
    const std::vector<Index>* use = &train;
    if (train.empty()) {
      all.resize(static_cast<std::size_t>(table.size()));
      std::iota(all.begin(), all.end(), Index{0});
      use = &all;
    }
    std::vector<bool> taken(static_cast<std::size_t>(table.size()), false);
    for (const Index i : *use) {
      if (i < 0 || i >= table.size())
        throw InvalidArgument("train", "touch " + std::to_string(i) + " is outside [0, " + std::to_string(table.size()) + ")");
      // A touch listed twice would count twice in the codebook's fit and in
      // its object's reference, weighting it silently.
      if (taken[static_cast<std::size_t>(i)])
        throw InvalidArgument("train", "touch " + std::to_string(i) + " is listed twice");
      taken[static_cast<std::size_t>(i)] = true;
    }
    TouchSet train_set = select_touches(table.touches, *use);
    quantizer_.fit(train_set.features);
    train_set.words = assign_words(quantizer_, train_set.features);
    std::vector<std::vector<Index>> per_object(objects_.size());
    for (std::size_t j = 0; j < use->size(); ++j)
      per_object[static_cast<std::size_t>(table.object[static_cast<std::size_t>((*use)[j])])].push_back(static_cast<Index>(j));
    std::vector<TouchSet> references;
    for (std::size_t o = 0; o < objects_.size(); ++o) {
      if (per_object[o].empty())
        throw InvalidArgument("table", "object '" + objects_[o] + "' has no training touch");
      references.push_back(select_touches(train_set, per_object[o]));
      touches_per_object_.push_back(static_cast<Index>(per_object[o].size()));
    }
    recognizer_.fit(references, static_cast<Index>(quantizer_.size()));
  }

  /// The codebook word of one descriptor (same length as the table's).
  /// Throws DimensionMismatch / NonFiniteValue naming "feature".
  Index word(const Eigen::Ref<const Eigen::VectorXf>& feature) const {
    check_dimension(feature.size(), feature_length(), "feature");
    check_finite(feature, "feature");
    const Eigen::MatrixXf f = feature;
    return assign_words(quantizer_, f)(0);
  }

  /// A new session on these references.
  LiveSession session(LiveStopRule rule = {}) const { return LiveSession(recognizer_, fusion_, rule, vocabulary()); }

  const std::vector<std::string>& objects() const noexcept { return objects_; }
  /// Training touches of each object.
  const std::vector<Index>& touches_per_object() const noexcept { return touches_per_object_; }
  const Quantizer& quantizer() const noexcept { return quantizer_; }
  Index vocabulary() const { return static_cast<Index>(quantizer_.size()); }
  Index feature_length() const { return feature_length_; }
  const Recognizer& recognizer() const noexcept { return recognizer_; }
  const Fusion& fusion() const noexcept { return fusion_; }

 private:
  static std::vector<std::unique_ptr<Classifier>> make(const ClassifierFactory& factory) {
    if (!factory) throw InvalidArgument("factory", "is empty");
    return factory();
  }

  std::vector<std::string> objects_;
  Quantizer quantizer_;
  Recognizer recognizer_;
  Fusion fusion_;
  std::vector<Index> touches_per_object_;
  Index feature_length_ = 0;
};

/// Fusion weights chosen for live recognition on the references alone.
struct LiveWeights {
  Fusion fusion;                ///< the method's fusion with the chosen weights
  std::vector<double> weights;  ///< the chosen grid vector (empty: the method's weights are fixed)
  Index correct = 0;            ///< held-out test sets recognised with them, summed over folds and touch counts
  Index total = 0;              ///< held-out test sets in all
  int folds = 0;                ///< explorations held out in turn (0: nothing searched)
};

/// Chooses the weights of a method whose top-level weighted sum is fitted
/// (`a+b` without numbers; Method::fit_weights) for live recognition against
/// references built from all of `table`: the paper's brute-force grid
/// (settings.weight_steps, settings.zero_weights), scored by
/// leave-one-exploration-out recognition on `table` itself (each
/// exploration rank held out of every object in
/// turn, codebook and references from the rest, `settings.weight_repeats`
/// random draws of each of `settings.touches` touches). That is
/// CrossValidation's inner search with the whole table as the training set;
/// it runs CrossValidation once with every grid vector as a fixed-weight
/// method (each draw is registered once, all vectors fuse the same
/// distances), so it needs only 2 explorations per object. Highest number of
/// correct tests wins; ties go to the earlier grid vector (CrossValidation's
/// own search breaks them by the mean margin, which its results do not
/// report). A method with fixed weights is returned as it is.
///
/// Throws what CrossValidation throws (e.g. InvalidArgument naming "table"
/// when an object has fewer than 2 explorations with touches). `progress`
/// is CrossValidation's. Deterministic for a given seed, any thread count.
template <typename Quantizer>
LiveWeights choose_live_weights(const TouchTable& table, const ClassifierFactory& factory, const Quantizer& quantizer,
                                const Method& method, CrossValidationSettings settings,
                                const ProgressCallback& progress = {}) {
  if (!method.alternatives.empty())
    throw InvalidArgument("method", "'" + method.name + "' has alternatives; choose_live_weights chooses weights only "
                                    "(evaluate_live_stopping chooses among alternatives in each fold)");
  LiveWeights out{method.fusion, {}, 0, 0, 0};
  if (!method.fit_weights) return out;
  settings.validate();
  check_weight_steps(method.name, method.fusion, settings.weight_steps, settings.zero_weights);
  const auto grid =
      weight_grid(static_cast<int>(method.fusion.children().size()), settings.weight_steps, settings.zero_weights);
  std::vector<Method> candidates;
  for (std::size_t g = 0; g < grid.size(); ++g)
    candidates.push_back(Method{"w" + std::to_string(g), method.fusion.with_weights(grid[g]), false, {}});
  settings.weight_sweeps = false;
  settings.repeats = settings.weight_repeats;
  CrossValidation<Quantizer> cv(table, factory, quantizer, candidates, settings);
  const CrossValidationResult r = cv.run(progress);
  std::size_t best = 0;
  for (std::size_t g = 0; g < grid.size(); ++g) {
    Index correct = 0, total = 0;
    for (std::size_t t = 0; t < r.touches.size(); ++t) {
      correct += r.methods[g].correct[t];
      total += r.methods[g].total[t];
    }
    if (g == 0 || correct > out.correct) {
      best = g;
      out.correct = correct;
      out.total = total;
    }
  }
  out.weights = grid[best];
  out.fusion = method.fusion.with_weights(out.weights);
  out.folds = r.folds;
  return out;
}

/// Settings of evaluate_live_stopping.
struct LiveEvaluationSettings {
  /// Touches replayed per held-out exploration at most (>= 1): the stop
  /// rules evaluated may not exceed it.
  Index max_touches = 20;
  /// The CrossValidation run that chooses each fold's fusion weights (for a
  /// fitted method, on inner folds of that fold's training explorations, as
  /// `iclap evaluate` does) and gives the method's rate on random draws of
  /// `touches` touches, for comparison. Its normalisation and thread count
  /// also apply to the replays. Default: 1..20 touches, 10 draws, no sweeps.
  CrossValidationSettings cross_validation = [] {
    CrossValidationSettings s;
    s.weight_sweeps = false;
    return s;
  }();

  /// Also refuses a normalisation other than L2 (naming
  /// "cross_validation.normalization"), before any run: the replays are live
  /// sessions.
  void validate() const {
    if (max_touches < 1) throw InvalidArgument("max_touches", "must be >= 1, got " + std::to_string(max_touches));
    cross_validation.validate();
    detail::check_live_normalization(cross_validation.normalization, "cross_validation.normalization");
  }
};

/// One held-out exploration replayed touch by touch in time order (frame
/// index): element n - 1 of each vector is the state after n touches.
struct LiveTrace {
  int fold = 0;
  Index object = 0;               ///< the true object
  std::int64_t exploration = 0;   ///< its exploration id
  Index available = 0;            ///< touches the exploration has (may exceed the replayed ones)
  std::vector<Index> best;        ///< recognised object
  std::vector<double> confidence; ///< decision_confidence of the fused distances
  std::vector<Eigen::VectorXd> fused;  ///< fused distances (for studying other confidence measures)

  Index replayed() const noexcept { return static_cast<Index>(best.size()); }
};

/// Outcome of a stop rule over every replayed exploration.
struct LiveStopOutcome {
  LiveStopRule rule;
  Index tests = 0;        ///< explorations replayed
  Index correct = 0;      ///< recognised correctly when the rule stopped
  Index confident = 0;    ///< stopped by the confidence (not by running out or the limit)
  double mean_touches = 0;
  double median_touches = 0;
  std::vector<Index> touches;  ///< touches used by each test, in trace order

  double accuracy() const { return tests ? static_cast<double>(correct) / static_cast<double>(tests) : 0.0; }
};

/// Rate of a fixed number of touches taken in time order.
struct LiveFixedOutcome {
  Index touches = 0;
  Index tests = 0;
  Index correct = 0;
  Index short_tests = 0;  ///< explorations with fewer touches: they use all of theirs

  double accuracy() const { return tests ? static_cast<double>(correct) / static_cast<double>(tests) : 0.0; }
};

/// Result of evaluate_live_stopping.
struct LiveEvaluationResult {
  std::vector<std::string> objects;
  int folds = 0;
  Index max_touches = 0;
  /// The fusion of each fold (weights chosen on its training explorations).
  std::vector<std::string> fold_expressions;
  /// Fold-major, objects in order within a fold; explorations without a
  /// touch are left out.
  std::vector<LiveTrace> traces;
  /// The CrossValidation run: the method's rate on random touch draws.
  CrossValidationResult random_draws;

  /// Where `rule` stops on every trace: the first n in [min_touches, limit]
  /// whose confidence reaches rule.confidence, else (not confident; also
  /// where the limit is below min_touches) the limit, which is
  /// rule.max_touches (0: this result's max_touches) or the touches the
  /// exploration has, whichever is smaller. Throws InvalidArgument naming
  /// "rule" when its max_touches exceeds what was replayed.
  LiveStopOutcome stop(const LiveStopRule& rule) const {
    rule.validate();
    if (rule.max_touches > max_touches)
      throw InvalidArgument("rule", "max_touches " + std::to_string(rule.max_touches) + " exceeds the " +
                                        std::to_string(max_touches) + " touches replayed");
    const Index cap = rule.max_touches > 0 ? rule.max_touches : max_touches;
    LiveStopOutcome out;
    out.rule = rule;
    for (const auto& t : traces) {
      const Index limit = std::min(cap, t.replayed());
      Index n = limit;
      bool confident = false;
      // A trace shorter than min_touches stops at its end, not confident
      // (as a LiveSession, which is confident only from min_touches on).
      for (Index k = rule.min_touches; k <= limit; ++k)
        if (t.confidence[static_cast<std::size_t>(k - 1)] >= rule.confidence) {
          n = k;
          confident = true;
          break;
        }
      ++out.tests;
      out.correct += t.best[static_cast<std::size_t>(n - 1)] == t.object;
      out.confident += confident;
      out.touches.push_back(n);
    }
    if (!out.touches.empty()) {
      double sum = 0;
      for (Index n : out.touches) sum += static_cast<double>(n);
      out.mean_touches = sum / static_cast<double>(out.touches.size());
      std::vector<Index> sorted = out.touches;
      std::sort(sorted.begin(), sorted.end());
      const std::size_t m = sorted.size() / 2;
      out.median_touches = sorted.size() % 2 ? static_cast<double>(sorted[m])
                                             : 0.5 * static_cast<double>(sorted[m - 1] + sorted[m]);
    }
    return out;
  }

  /// Rate of the first `touches` touches of every trace (all of them when an
  /// exploration has fewer). Throws InvalidArgument naming "touches" outside
  /// [1, max_touches].
  LiveFixedOutcome fixed(Index touches) const {
    if (touches < 1 || touches > max_touches)
      throw InvalidArgument("touches", std::to_string(touches) + " is outside [1, " + std::to_string(max_touches) + "]");
    LiveFixedOutcome out;
    out.touches = touches;
    for (const auto& t : traces) {
      const Index n = std::min(touches, t.replayed());
      ++out.tests;
      out.short_tests += n < touches;
      out.correct += t.best[static_cast<std::size_t>(n - 1)] == t.object;
    }
    return out;
  }
};

/// The confidence-based stop (the paper's Discussion, "Haptic exploration")
/// measured by cross validation: fold f holds out the f-th exploration of
/// every object, as in CrossValidation (same folds, same training touches,
/// same codebook, the weights CrossValidation chose for the fold); the
/// references come from the other explorations; each held-out exploration
/// is replayed in time order (frame index), one touch at a time (with its
/// pad normal and contact points when the table has them), up to
/// settings.max_touches, and the session's state after every touch is
/// recorded. Any stop rule and fixed count are then read off the traces
/// (LiveEvaluationResult::stop / fixed).
///
/// Deterministic: the replays have no randomness and the CrossValidation run
/// is seeded; results do not depend on the thread count. `progress` gets
/// (replayed explorations, explorations) after CrossValidation's own run.
/// Throws what CrossValidation throws: InvalidArgument naming "table" for an
/// object with fewer than 2 explorations with touches, or fewer than 3 when
/// the method's weights or trimming are chosen in training (inner folds),
/// and for a method that needs a classifier the factory lacks.
template <typename Quantizer>
LiveEvaluationResult evaluate_live_stopping(const TouchTable& table, const ClassifierFactory& factory,
                                            const Quantizer& quantizer, const Method& method,
                                            const LiveEvaluationSettings& settings,
                                            const ProgressCallback& cv_progress = {},
                                            const ProgressCallback& progress = {}) {
  settings.validate();
  const CrossValidationSettings& cvs = settings.cross_validation;
  CrossValidation<Quantizer> cv(table, factory, quantizer, {method}, cvs);
  LiveEvaluationResult out;
  out.random_draws = cv.run(cv_progress);
  out.objects = table.objects;
  out.folds = cv.folds();
  out.max_touches = settings.max_touches;
  const MethodResult& mr = out.random_draws.methods.at(0);

  const auto n_objects = static_cast<Index>(table.objects.size());
  std::vector<std::vector<std::int64_t>> ids;
  for (Index o = 0; o < n_objects; ++o) ids.push_back(table.explorations_of(o));
  auto rank_of = [&](Index i) {
    const auto& v = ids[static_cast<std::size_t>(table.object[static_cast<std::size_t>(i)])];
    return static_cast<int>(std::lower_bound(v.begin(), v.end(), table.exploration[static_cast<std::size_t>(i)]) -
                            v.begin());
  };
  std::size_t total = 0;
  for (int f = 0; f < out.folds; ++f)
    for (Index o = 0; o < n_objects; ++o) total += static_cast<std::size_t>(f) < ids[static_cast<std::size_t>(o)].size();
  ProgressCounter counter(progress, total);

  for (int f = 0; f < out.folds; ++f) {
    const Fusion candidate = method.candidates().at(mr.fold_candidates.at(static_cast<std::size_t>(f)));
    const Fusion fusion =
        method.fit_weights ? candidate.with_weights(mr.fold_weights.at(static_cast<std::size_t>(f))) : candidate;
    out.fold_expressions.push_back(fusion.to_string());
    std::vector<Index> train;
    std::vector<std::vector<Index>> held(static_cast<std::size_t>(n_objects));
    for (Index i = 0; i < table.size(); ++i) {
      if (rank_of(i) != f) train.push_back(i);
      else held[static_cast<std::size_t>(table.object[static_cast<std::size_t>(i)])].push_back(i);
    }
    const LiveReferences<Quantizer> refs(table, train, factory, quantizer, fusion, cvs.normalization);
    std::vector<LiveTrace> traces(static_cast<std::size_t>(n_objects));
    LiveStopRule rule;
    rule.confidence = 1.0;
    detail::parallel_for(static_cast<std::size_t>(n_objects), static_cast<unsigned>(cvs.threads),
                         [&](std::size_t oi, unsigned) {
      const auto o = static_cast<Index>(oi);
      auto& idx = held[oi];
      if (idx.empty()) return;
      std::stable_sort(idx.begin(), idx.end(), [&](Index a, Index b) {
        return table.frame[static_cast<std::size_t>(a)] < table.frame[static_cast<std::size_t>(b)];
      });
      LiveTrace& t = traces[oi];
      t.fold = f;
      t.object = o;
      t.exploration = table.exploration[static_cast<std::size_t>(idx.front())];
      t.available = static_cast<Index>(idx.size());
      LiveSession s = refs.session(rule);
      const Index n = std::min(settings.max_touches, t.available);
      for (Index k = 0; k < n; ++k) {
        const Index i = idx[static_cast<std::size_t>(k)];
        s.add_touch(live_touch_of(table.touches, i, refs.word(table.touches.features.col(i))));
        t.best.push_back(s.best());
        t.confidence.push_back(s.confidence());
        t.fused.push_back(s.fused());
      }
      counter.tick();
    });
    for (auto& t : traces)
      if (!t.best.empty()) out.traces.push_back(std::move(t));
  }
  return out;
}

}  // namespace iclap

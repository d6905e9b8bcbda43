// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <type_traits>
#include <utility>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/recognition/classifier.hpp"
#include "iclap/registration/registration.hpp"
#include "iclap/search/adaptive.hpp"

namespace iclap {

namespace detail {
/// `scale` (an embedding's weight of an axis, in double) as the Scalar
/// weight the ICP uses. InvalidArgument naming `name` when that is 0,
/// subnormal or infinite: the ICP divides by its weights, and a float label
/// scale of 1e-50 became a weight of 0, refused deep in fit as "weights".
template <typename Scalar>
Scalar axis_weight(double scale, const char* name) {
  const auto w = static_cast<Scalar>(scale);
  if (!(w >= std::numeric_limits<Scalar>::min() && w <= std::numeric_limits<Scalar>::max()))
    throw InvalidArgument(name, format_value(scale) + " is outside the range of a " +
                                    (std::is_same_v<Scalar, float> ? "float" : "double") + " weight [" +
                                    format_value(static_cast<double>(std::numeric_limits<Scalar>::min())) + ", " +
                                    format_value(static_cast<double>(std::numeric_limits<Scalar>::max())) +
                                    "]; use a scale within it" +
                                    (std::is_same_v<Scalar, float> ? ", or double arithmetic" : ""));
  return w;
}
}  // namespace detail

/// How the kinesthetic ICP sees a touch: its position (x, y, z). Paper,
/// Section IV, "Kinesthetics based object recognition".
struct PositionEmbedding {
  static constexpr int dimension = 3;
  static constexpr const char* default_name = "icp";
  /// A set's points are its touches' points in order, each touch's from that
  /// touch alone (see RegistrationClassifier::prepare_pool).
  static constexpr bool per_touch = true;
  Index dim(const TouchSet& /*touches*/) const noexcept { return 3; }
  void validate() const {}
  template <typename Scalar, int Dim>
  void weights(Point<Scalar, Dim>& w, Index d) const {
    w = Point<Scalar, Dim>::Ones(d);
  }
  template <typename Scalar, int Dim>
  void embed(const TouchSet& s, Cloud<Scalar, Dim>& out) const {
    out = s.positions.cast<Scalar>();
  }
};

/// How iCLAP sees a touch: the 4-D labeled point (x, y, z, word) of paper
/// Section III. `label_scale` is the weight of the label axis in metres per
/// word step: the paper's rig reported millimetres and integer labels, so
/// one label step weighed one millimetre; with positions in metres that is
/// 0.001, the default.
struct LabeledEmbedding {
  static constexpr int dimension = 4;
  static constexpr const char* default_name = "iclap";
  /// A set's points are its touches' points in order, each touch's from that
  /// touch alone (see RegistrationClassifier::prepare_pool).
  static constexpr bool per_touch = true;
  double label_scale = 0.001;
  Index dim(const TouchSet& /*touches*/) const noexcept { return 4; }
  void validate() const {
    check_positive(label_scale, "label_scale");
  }
  template <typename Scalar, int Dim>
  void weights(Point<Scalar, Dim>& w, Index d) const {
    w = Point<Scalar, Dim>::Ones(d);
    w(3) = detail::axis_weight<Scalar>(label_scale, "label_scale");
  }
  template <typename Scalar, int Dim>
  void embed(const TouchSet& s, Cloud<Scalar, Dim>& out) const {
    if (s.words.size() != s.size()) throw DimensionMismatch("touches.words", s.size(), s.words.size());
    out.resize(4, s.size());
    out.template topRows<3>() = s.positions.cast<Scalar>();
    out.row(3) = s.words.transpose().cast<Scalar>();
  }
};

/// How iCLAP-N sees a touch (the paper's Discussion, beyond the paper): the
/// position followed by the whole descriptor, a (3 + D)-D point, so that no
/// information is lost to quantisation. `descriptor_scale` weighs the
/// descriptor axes in metres per descriptor unit (a unit-norm Tactile-SIFT
/// difference of 1 counts as 1 cm by default).
struct DescriptorEmbedding {
  static constexpr int dimension = Eigen::Dynamic;
  static constexpr const char* default_name = "iclapn";
  /// A set's points are its touches' points in order, each touch's from that
  /// touch alone (see RegistrationClassifier::prepare_pool).
  static constexpr bool per_touch = true;
  /// Tests need descriptors of the references' length
  /// (RegistrationClassifier::descriptor_length).
  static constexpr bool reads_descriptors = true;
  double descriptor_scale = 0.01;
  Index dim(const TouchSet& touches) const noexcept { return 3 + touches.features.rows(); }
  void validate() const {
    check_positive(descriptor_scale, "descriptor_scale");
  }
  template <typename Scalar, int Dim>
  void weights(Point<Scalar, Dim>& w, Index d) const {
    w = Point<Scalar, Dim>::Constant(d, detail::axis_weight<Scalar>(descriptor_scale, "descriptor_scale"));
    w.template head<3>().setOnes();
  }
  template <typename Scalar, int Dim>
  void embed(const TouchSet& s, Cloud<Scalar, Dim>& out) const {
    if (s.features.cols() != s.size()) throw DimensionMismatch("touches.features", s.size(), s.features.cols());
    out.resize(3 + s.features.rows(), s.size());
    out.template topRows<3>() = s.positions.cast<Scalar>();
    out.bottomRows(s.features.rows()) = s.features.cast<Scalar>();
  }
};

/// How the patch classifiers see a touch (beyond the paper): the points where
/// the pad met the object, i.e. the world positions of its pressed taxels
/// (`TouchSet::contact_points`), so that a touch tells of a 51 x 24 mm patch
/// of surface instead of one pad-centre point, and sparse explorations
/// overlap more. `Labeled` adds the touch's word as a 4th axis, as iCLAP
/// does. A test uses at most `test_points_per_touch` contact points per
/// touch (evenly spread over its pressed taxels); a reference keeps all of
/// them, averaged per `reference_voxel` cube (and per word).
template <bool Labeled>
struct ContactEmbedding {
  static constexpr int dimension = Labeled ? 4 : 3;
  static constexpr const char* default_name = Labeled ? "iclap_patch" : "patch";
  /// A set's points are its touches' points in order, each touch's from that
  /// touch alone (see RegistrationClassifier::prepare_pool).
  static constexpr bool per_touch = true;
  double label_scale = 0.001;
  Index test_points_per_touch = 8;
  double reference_voxel = 0.002;

  /// The most voxels from the origin a reference point may lie: cell
  /// indices are long long (a cast beyond its range is undefined).
  static constexpr double kMaxCells = 0x1p62;

  /// The index of the `voxel` cell holding `coordinate` along one axis (0
  /// when voxel is 0: no averaging). Throws InvalidArgument naming
  /// "reference_voxel" when it is kMaxCells or more from the origin.
  static long long cell_of(double coordinate, double voxel) {
    const double cell = voxel > 0 ? std::floor(coordinate / voxel) : 0.0;
    if (!(std::abs(cell) < kMaxCells))
      throw InvalidArgument("reference_voxel", "coordinate " + format_value(coordinate) + " is " + format_value(cell) +
                                                   " voxels of " + format_value(voxel) +
                                                   " from the origin, beyond the cell index range; use a larger "
                                                   "voxel, or 0 for none");
    return static_cast<long long>(cell);
  }

  Index dim(const TouchSet& /*touches*/) const noexcept { return dimension; }
  void validate() const {
    if (Labeled) check_positive(label_scale, "label_scale");
    if (test_points_per_touch < 1)
      throw InvalidArgument("test_points_per_touch", "must be >= 1, got " + std::to_string(test_points_per_touch));
    check_non_negative(reference_voxel, "reference_voxel");
  }
  template <typename Scalar, int Dim>
  void weights(Point<Scalar, Dim>& w, Index d) const {
    w = Point<Scalar, Dim>::Ones(d);
    if (Labeled) w(3) = detail::axis_weight<Scalar>(label_scale, "label_scale");
  }
  template <typename Scalar, int Dim>
  void embed(const TouchSet& s, Cloud<Scalar, Dim>& out) const {
    check(s);
    Index total = 0;
    for (Index i = 0; i < s.size(); ++i) total += std::max<Index>(1, std::min(s.contacts_of(i), test_points_per_touch));
    out.resize(dimension, total);
    Index k = 0;
    for (Index i = 0; i < s.size(); ++i) {
      const Index m = s.contacts_of(i);
      const Index take = std::min(m, test_points_per_touch);
      if (take == 0) put(out, k++, s.positions.col(i), s, i);
      for (Index j = 0; j < take; ++j)
        put(out, k++, s.contact_points.col(s.contact_offsets[static_cast<std::size_t>(i)] + j * m / take), s, i);
    }
  }
  template <typename Scalar, int Dim>
  void embed_reference(const TouchSet& s, Cloud<Scalar, Dim>& out) const {
    check(s);
    using Key = std::array<long long, 4>;
    std::map<Key, std::pair<Eigen::Vector3d, Index>> cells;
    auto add = [&](const Eigen::Vector3d& p, Index word) {
      Key key{0, 0, 0, Labeled ? static_cast<long long>(word) : 0};
      for (int a = 0; a < 3; ++a) key[static_cast<std::size_t>(a)] = cell_of(p(a), reference_voxel);
      auto it = cells.find(key);
      if (it == cells.end()) it = cells.emplace(key, std::make_pair(Eigen::Vector3d::Zero().eval(), Index(0))).first;
      it->second.first += p;
      ++it->second.second;
    };
    std::vector<std::pair<Eigen::Vector3d, Index>> raw;  // without a voxel: every point
    for (Index i = 0; i < s.size(); ++i) {
      const Index word = Labeled ? s.words(i) : 0;
      const Index m = s.contacts_of(i);
      for (Index j = 0; j < std::max<Index>(m, 1); ++j) {
        const Eigen::Vector3d p =
            m == 0 ? Eigen::Vector3d(s.positions.col(i))
                   : Eigen::Vector3d(s.contact_points.col(s.contact_offsets[static_cast<std::size_t>(i)] + j));
        if (reference_voxel > 0) add(p, word);
        else raw.emplace_back(p, word);
      }
    }
    if (reference_voxel > 0)
      for (const auto& c : cells) raw.emplace_back(c.second.first / static_cast<double>(c.second.second), c.first[3]);
    out.resize(dimension, static_cast<Index>(raw.size()));
    for (std::size_t k = 0; k < raw.size(); ++k) {
      out.col(static_cast<Index>(k)).template head<3>() = raw[k].first.template cast<Scalar>();
      if (Labeled) out(3, static_cast<Index>(k)) = static_cast<Scalar>(raw[k].second);
    }
  }

 private:
  static void check(const TouchSet& s) {
    if (!s.has_contacts())
      throw InvalidArgument("touches.contact_points",
                            "the patch classifiers need contact points (a dataset with the pad orientation qw,qx,qy,qz)");
    if (Labeled && s.words.size() != s.size()) throw DimensionMismatch("touches.words", s.size(), s.words.size());
  }
  template <typename Scalar, int Dim, typename P>
  static void put(Cloud<Scalar, Dim>& out, Index k, const P& p, const TouchSet& s, Index touch) {
    out.col(k).template head<3>() = p.template cast<Scalar>();
    if (Labeled) out(3, k) = static_cast<Scalar>(s.words(touch));
  }
};

namespace detail {
/// Does embedding E promise per-touch points (`static constexpr bool
/// per_touch = true`)? Without the member: no.
template <typename E, typename = void>
struct embeds_per_touch : std::false_type {};
template <typename E>
struct embeds_per_touch<E, std::void_t<decltype(E::per_touch)>> : std::bool_constant<E::per_touch> {};

/// Does embedding E put the touches' descriptors into its points (`static
/// constexpr bool reads_descriptors = true`)? Without the member: no.
template <typename E, typename = void>
struct embeds_descriptors : std::false_type {};
template <typename E>
struct embeds_descriptors<E, std::void_t<decltype(E::reads_descriptors)>> : std::bool_constant<E::reads_descriptors> {};

template <typename E, typename Scalar, int Dim, typename = void>
struct has_embed_reference : std::false_type {};
template <typename E, typename Scalar, int Dim>
struct has_embed_reference<E, Scalar, Dim,
                           std::void_t<decltype(std::declval<const E&>().template embed_reference<Scalar, Dim>(
                               std::declval<const TouchSet&>(), std::declval<Cloud<Scalar, Dim>&>()))>>
    : std::true_type {};

template <typename Settings, typename = void>
struct has_leaf_size : std::false_type {};
template <typename Settings>
struct has_leaf_size<Settings, std::void_t<decltype(std::declval<Settings&>().leaf_max_size)>> : std::true_type {};

/// Search settings for recognition references: a tree's leaves hold 24
/// points. ICP's queries are warm-started from each point's previous match,
/// and on the few-hundred-point references a larger leaf answers them with
/// fewer node visits; the answers do not depend on the leaf size.
template <typename Search>
typename Search::Settings reference_search_settings() {
  typename Search::Settings s{};
  if constexpr (has_leaf_size<typename Search::Settings>::value) s.leaf_max_size = 24;
  return s;
}
}  // namespace detail

/// How `RegistrationClassifier::decide` avoids registering the test against
/// every object to the end.
struct PruningSettings {
  enum class Schedule {
    /// Every registration runs to its end (the reference decision).
    None,
    /// Exact: objects are registered in order of a lower bound on their
    /// final error, and skipped once the bound exceeds the best final error
    /// found so far; the decision is provably the same as with None
    /// (see `decide`).
    Bound,
    /// Approximate: successive halving. Every surviving object gets
    /// `round_iterations` more iterations, then only the best `keep_fraction`
    /// (by current error) go on, until `finalists` remain, which run to the
    /// end. Objects whose lower bound exceeds an error already reached are
    /// dropped at any time (that part is exact).
    Halving,
  };
  Schedule schedule = Schedule::Bound;
  int round_iterations = 2;
  double keep_fraction = 0.5;
  Index finalists = 2;
  /// Approximate, with Bound or Halving: register only the `shortlist`
  /// objects with the smallest lower bounds (0: every object). The cost of a
  /// decision then grows with the number of objects only through the bounds
  /// (one small kd-tree query per test point and object), but the winner
  /// can lie outside the shortlist; `scaling_study` reports how often the
  /// decisions differ from the exact ones. Needs the lower bound (a model
  /// that leaves coordinates unmoved, no `max_distance`); ignored by None.
  Index shortlist = 0;

  void validate() const {
    if (shortlist < 0) throw InvalidArgument("pruning.shortlist", "must be >= 0 (0: every object)");
    if (round_iterations < 1) throw InvalidArgument("pruning.round_iterations", "must be >= 1");
    if (!(keep_fraction > 0 && keep_fraction < 1)) throw InvalidArgument("pruning.keep_fraction", "must be in (0, 1)");
    if (finalists < 1) throw InvalidArgument("pruning.finalists", "must be >= 1");
  }
};

/// The outcome of `RegistrationClassifier::decide`.
struct PrunedDecision {
  Index object = -1;          ///< recognised object (smallest final error), -1 if none
  double error = 0;           ///< its final error E
  Index completed = 0;        ///< registrations run to their end (one per object and start)
  Index pruned = 0;           ///< registrations dropped by the lower bound (exact)
  Index eliminated = 0;       ///< registrations dropped by an approximate rule (halving, shortlist)
  long long iterations = 0;   ///< ICP iterations over all objects and starts
};

/// A classifier whose distance is the ICP error E between the test touches
/// and each object's reference cloud (paper: E_ICP, Eq. (8); E_iCLAP,
/// Section III): the test is registered against every object and E = sum
/// of squared distances of the matched pairs after convergence. `Embedding`
/// turns touches into points (PositionEmbedding: 3-D ICP; LabeledEmbedding:
/// 4-D iCLAP; DescriptorEmbedding: (3+D)-D iCLAP-N), `Model` is the motion
/// allowed
/// between a test and a reference (default Planar: the objects lie on a
/// table and are re-placed between explorations; FullRigid is the paper's).
///
/// Configure through the public members (`icp.termination.max_iterations`,
/// `embedding.label_scale`, ...) before `fit`. `icp.rejection.trim_fraction`
/// < 1 makes every registration a trimmed ICP: E then sums the closest
/// fraction of the pairs, the same number for every object, so the
/// distances stay comparable. `icp.rejection.max_distance` does not keep
/// them comparable (E sums the pairs kept, and an object that kept fewer
/// looks closer); use it only when that is what you want. It also turns the
/// pruning bound off, which trimming keeps (see `lower_bounds`). The references (kd-trees
/// included) are built once in `fit` and shared by every `distances` call;
/// `distances` is const and thread-safe (per-thread buffers).
template <typename Embedding, typename Scalar = float, int Dim = Embedding::dimension, typename Model = Planar,
          typename Search = AdaptiveSearch<Scalar, Dim>>
class RegistrationClassifier final : public Classifier {
 public:
  using Reference = ReferenceCloud<Scalar, Dim, Search>;
  using IcpType = Icp<Scalar, Dim, Model>;

  IcpType icp;
  Embedding embedding;
  /// The name in fusion expressions and results (default: the embedding's).
  std::string label = Embedding::default_name;
  /// Initial yaw guesses, degrees, about the vertical axis through the test
  /// centroid: each object's distance is the smallest final error over them.
  /// {0} (one start from the identity) is the paper's; more starts widen the
  /// convergence basin at proportional cost.
  std::vector<double> yaw_starts_deg = {0.0};
  /// Keep at most this many points per reference (evenly spaced in touch
  /// order, which is time order along the sweeps); 0 keeps all.
  Index max_reference_points = 0;
  /// Settings of each reference's search structure. Speed only: every
  /// setting gives the same distances. The default `AdaptiveSearch` scans
  /// references of up to 2048 coordinates (512 4-D points) by brute force,
  /// about half the time of the kd-tree on the built-in objects' references
  /// (`bench_recognition --benchmark_filter=Search`), and builds kd-trees
  /// for larger ones with 24 points per leaf (`KdTreeSearch` alone defaults
  /// to 10): 9-14% less time per recognition on the built-in references
  /// than 10 (`bench_recognition --benchmark_filter=LeafSize`).
  typename Search::Settings search_settings = detail::reference_search_settings<Search>();

  std::string name() const override { return label; }

  /// Throws EmptyInput naming "objects" / "objects[j]" for no object or an
  /// object without touches, plus whatever the embedding rejects.
  void fit(const std::vector<TouchSet>& objects, Index /*vocabulary*/) override {
    embedding.validate();
    if (objects.empty()) throw EmptyInput("objects", "no object to recognise");
    std::vector<Reference> refs;
    refs.reserve(objects.size());
    Cloud<Scalar, Dim> points;
    Point<Scalar, Dim> w;
    for (std::size_t j = 0; j < objects.size(); ++j) {
      const std::string arg = "objects[" + std::to_string(j) + "]";
      objects[j].validate(arg);
      // Against objects[0], not the references of an earlier fit, which
      // this one replaces (it may embed descriptors of another length).
      check_embedded_dimension(objects[j], arg, j == 0 ? Index{-1} : embedding.dim(objects.front()), ", as objects[0]'s");
      check_touch_range(objects[j], arg);  // before the embedding, which may bin the coordinates
      if constexpr (detail::has_embed_reference<Embedding, Scalar, Dim>::value)
        embedding.template embed_reference<Scalar, Dim>(objects[j], points);
      else
        embedding.template embed<Scalar, Dim>(objects[j], points);
      check_range(objects[j], points, arg);
      if (max_reference_points > 0 && points.cols() > max_reference_points) {
        Cloud<Scalar, Dim> kept(points.rows(), max_reference_points);
        for (Index k = 0; k < max_reference_points; ++k)
          kept.col(k) = points.col(k * points.cols() / max_reference_points);
        points = std::move(kept);
      }
      embedding.template weights<Scalar, Dim>(w, points.rows());
      refs.emplace_back(points, w, search_settings);
    }
    // Lower-bound structures: the coordinates the transform model never
    // moves, weighted, searched per reference (brute force for the usual
    // few hundred points, a kd-tree for large references).
    std::vector<AdaptiveSearch<Scalar, Eigen::Dynamic>> fixed;
    const Index d = refs.front().dim(), b = Model::block_size(d);
    if (d > b) {
      for (const auto& r : refs) {
        const Cloud<Scalar, Eigen::Dynamic> q =
            (r.working_points().bottomRows(d - b).colwise() +
             r.weights().tail(d - b).cwiseProduct(r.centroid().tail(d - b)))
                .template cast<Scalar>();
        fixed.emplace_back(q);
      }
    }
    references_ = std::move(refs);
    fixed_ = std::move(fixed);
    descriptor_length_ = detail::embeds_descriptors<Embedding>::value ? objects.front().features.rows() : 0;
    fit_id_ = detail::next_fit_id();
  }

  /// The references' descriptor length for an embedding that reads
  /// descriptors (`reads_descriptors`: iclapn), else 0; 0 before `fit`.
  Index descriptor_length() const override { return descriptor_length_; }

  void distances(const TouchSet& test, Eigen::Ref<Eigen::VectorXd> out) const override {
    compute_distances(test, nullptr, nullptr, out);
  }

  /// For an embedding with per-touch points (`per_touch`: the library's
  /// four), the first matching of every pool touch's points in every
  /// reference under the identity start (Icp::first_matches), so that each
  /// registration of `pool_distances` from that start skips its first round
  /// of nearest-neighbour queries, with the same distances (the saving:
  /// `bench_recognition --benchmark_filter='PoolDistances|leaf:24'`).
  /// Costs one query per pool point and object. Null when there is nothing to
  /// reuse: another embedding, `icp.centroid_alignment`, or no zero yaw
  /// start. Throws InvalidArgument naming "prepare_pool" before `fit`, and
  /// like `distances` for a bad pool (named "pool").
  std::shared_ptr<const PreparedPool> prepare_pool(const TouchSet& pool) const override {
    if constexpr (!detail::embeds_per_touch<Embedding>::value) {
      (void)pool;
      return nullptr;
    } else {
      if (references_.empty()) throw InvalidArgument("prepare_pool", "called before fit");
      if (icp.centroid_alignment ||
          std::find(yaw_starts_deg.begin(), yaw_starts_deg.end(), 0.0) == yaw_starts_deg.end())
        return nullptr;
      pool.validate("pool");
      check_embedded_dimension(pool, "pool");
      auto prepared = std::make_shared<FirstMatches>(fit_id_, pool);
      // The pool's points touch by touch, as a test made of them has them.
      std::vector<Cloud<Scalar, Dim>> parts(static_cast<std::size_t>(pool.size()));
      prepared->offsets.assign(1, 0);
      for (Index i = 0; i < pool.size(); ++i) {
        embedding.template embed<Scalar, Dim>(select_touches(pool, std::array<Index, 1>{i}),
                                              parts[static_cast<std::size_t>(i)]);
        prepared->offsets.push_back(prepared->offsets.back() + parts[static_cast<std::size_t>(i)].cols());
      }
      Cloud<Scalar, Dim> points(embedding.dim(pool), prepared->offsets.back());
      for (Index i = 0; i < pool.size(); ++i)
        points.middleCols(prepared->offsets[static_cast<std::size_t>(i)], parts[static_cast<std::size_t>(i)].cols()) =
            parts[static_cast<std::size_t>(i)];
      check_range(pool, points, "pool");
      IcpWorkspace<Scalar, Dim> ws;
      prepared->matches.resize(references_.size());
      for (std::size_t j = 0; j < references_.size(); ++j)
        icp.first_matches(references_[j], points, nullptr, ws, prepared->matches[j]);
      return prepared;
    }
  }

  /// The distances of `distances(select_touches(pool, subset), out)`, with
  /// the first matchings of the zero yaw start taken from `prepared` (from
  /// `prepare_pool(pool)` since the last fit; null: searched as usual).
  /// Throws InvalidArgument naming "prepared" for a preparation of another
  /// classifier, pool or fit, and "subset" for an index outside the pool.
  void pool_distances(const TouchSet& pool, const PreparedPool* prepared, const std::vector<Index>& subset,
                      Eigen::Ref<Eigen::VectorXd> out) const override {
    const FirstMatches* first = checked_preparation<FirstMatches>(prepared, fit_id_, pool, subset);
    const TouchSet test = select_touches(pool, subset);
    compute_distances(test, first, &subset, out);
  }

  /// The lower bound on every object's final error used by pruning: the
  /// sum over test points of the squared (weighted) distance to the closest
  /// reference point in the coordinates the transform model never moves (z
  /// and the label for Planar, the label or descriptor for SpatialRigid and
  /// Translation; none for FullRigid, where every bound is 0). Valid for any
  /// motion of the model, because the error of a pair is at least its error
  /// in those coordinates. With trimming (`icp.rejection.trim_fraction` < 1)
  /// the bound sums the smallest of these per-point bounds, as many as the
  /// trimming keeps pairs: the k-th smallest pair error is at least the k-th
  /// smallest per-point bound. With a `max_distance` (a dropped pair adds
  /// nothing) every bound is 0, and `decide` registers every object.
  Eigen::VectorXd lower_bounds(const TouchSet& test) const {
    test.validate("test");
    check_embedded_dimension(test, "test");
    Cloud<Scalar, Dim> points;
    embed_checked(test, points, "test");
    return bound_is_valid() ? lower_bounds_of(points) : Eigen::VectorXd::Zero(objects());
  }

  /// Which object fits `test` best (smallest final error, ties to the
  /// smaller index), with as little registration work as `pruning` allows.
  ///
  /// With Schedule::Bound the decision equals the one of `distances`
  /// (argmin of every final error): objects are registered in increasing
  /// order of `lower_bounds`, and an object is skipped only when its bound
  /// exceeds a final error already reached, which its own final error could
  /// then not beat. Plain and trimmed ICP have the bound; with a
  /// `max_distance` it is not used (see `lower_bounds`). Single-threaded;
  /// const and thread-safe.
  PrunedDecision decide(const TouchSet& test, const PruningSettings& pruning = {}) const {
    pruning.validate();
    test.validate("test");
    check_embedded_dimension(test, "test");
    Cloud<Scalar, Dim> points;
    embed_checked(test, points, "test");
    const Index n = objects();
    const bool bounded = bound_is_valid();
    const Eigen::VectorXd lb = bounded ? lower_bounds_of(points) : Eigen::VectorXd::Zero(n);
    std::vector<Index> order(static_cast<std::size_t>(n));
    for (Index j = 0; j < n; ++j) order[static_cast<std::size_t>(j)] = j;
    std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) { return lb(a) < lb(b); });
    const auto starts = initial_guesses(points);
    PrunedDecision out;
    if (pruning.shortlist > 0 && pruning.schedule != PruningSettings::Schedule::None) {
      if (!bounded)
        throw InvalidArgument("pruning.shortlist",
                              "needs the lower bound, which a max_distance or a transform model moving every coordinate "
                              "leaves unavailable");
      if (pruning.shortlist < n) {
        out.eliminated = (n - pruning.shortlist) * static_cast<Index>(starts.size());
        order.resize(static_cast<std::size_t>(pruning.shortlist));
      }
    }
    // A bound beats an error only by a margin above rounding: relative, plus
    // the squared rounding of the coordinates themselves.
    const double scale = static_cast<double>(
        (points.cwiseAbs().rowwise().maxCoeff().cwiseProduct(references_.front().weights().cwiseAbs())).maxCoeff());
    const double slack = static_cast<double>(points.cols()) * 256.0 *
                         static_cast<double>(std::numeric_limits<Scalar>::epsilon()) * (scale * scale + 1e-300);
    auto beaten = [slack](double bound, double error) { return bound > error * (1 + 1e-4) + slack; };
    auto consider = [&](Index j, double e) {
      if (out.object < 0 || e < out.error || (e == out.error && j < out.object)) {
        out.object = j;
        out.error = e;
      }
    };
    if (pruning.schedule != PruningSettings::Schedule::Halving) {
      IcpWorkspace<Scalar, Dim> ws;
      for (std::size_t k = 0; k < order.size(); ++k) {
        const Index j = order[k];
        if (pruning.schedule == PruningSettings::Schedule::Bound && out.object >= 0 && beaten(lb(j), out.error)) {
          out.pruned = static_cast<Index>(order.size() - k) * static_cast<Index>(starts.size());
          break;
        }
        double best = std::numeric_limits<double>::infinity();
        for (const auto& T0 : starts) {
          const auto r = icp.align(references_[static_cast<std::size_t>(j)], points, T0 ? &*T0 : nullptr, ws);
          best = std::min(best, static_cast<double>(r.error));
          out.iterations += r.iterations;
        }
        out.completed += static_cast<Index>(starts.size());
        consider(j, best);
      }
      return out;
    }
    // Successive halving over (object, start) registrations.
    struct Live {
      Index object;
      std::unique_ptr<IcpWorkspace<Scalar, Dim>> ws;  // stable address for the registration
      typename IcpType::template Registration<Search> run;
      Live(Index o, std::unique_ptr<IcpWorkspace<Scalar, Dim>> w, const IcpType& icp_, const Reference& ref,
           const Cloud<Scalar, Dim>& pts, const RigidTransform<Scalar, Dim>* T0)
          : object(o), ws(std::move(w)), run(icp_.start(ref, pts, T0, *ws)) {}
    };
    std::vector<Live> live;
    live.reserve(order.size() * starts.size());
    for (Index j : order)
      for (const auto& T0 : starts)
        live.emplace_back(j, std::make_unique<IcpWorkspace<Scalar, Dim>>(), icp,
                          references_[static_cast<std::size_t>(j)], points, T0 ? &*T0 : nullptr);
    auto upper = [&] {  // the smallest error reached: an upper bound of the winner's final error
      double u = std::numeric_limits<double>::infinity();
      for (const auto& l : live) u = std::min(u, static_cast<double>(l.run.error()));
      return u;
    };
    auto drop_bounded = [&] {
      const double u = upper();
      const auto before = live.size();
      const auto cut = std::stable_partition(live.begin(), live.end(),
                                             [&](const Live& l) { return !beaten(lb(l.object), u); });
      for (auto it = cut; it != live.end(); ++it) out.iterations += it->run.iterations();
      live.erase(cut, live.end());
      out.pruned += static_cast<Index>(before - live.size());
    };
    auto objects_alive = [&] {
      std::vector<Index> ids;
      for (const auto& l : live) ids.push_back(l.object);
      std::sort(ids.begin(), ids.end());
      return static_cast<Index>(std::unique(ids.begin(), ids.end()) - ids.begin());
    };
    if (bounded) drop_bounded();
    while (objects_alive() > pruning.finalists) {
      bool progressed = false;
      for (auto& l : live)
        for (int i = 0; i < pruning.round_iterations && l.run.step(); ++i) progressed = true;
      if (bounded) drop_bounded();
      std::stable_sort(live.begin(), live.end(),
                       [](const Live& a, const Live& b) { return a.run.error() < b.run.error(); });
      const auto keep = std::max<std::size_t>(
          static_cast<std::size_t>(pruning.finalists) * starts.size(),
          static_cast<std::size_t>(std::ceil(pruning.keep_fraction * static_cast<double>(live.size()))));
      if (keep < live.size()) {
        out.eliminated += static_cast<Index>(live.size() - keep);
        for (std::size_t i = keep; i < live.size(); ++i) out.iterations += live[i].run.iterations();
        live.erase(live.begin() + static_cast<std::ptrdiff_t>(keep), live.end());
      } else if (!progressed) {
        break;  // everything left has finished
      }
    }
    for (auto& l : live) {
      l.run.run();
      out.iterations += l.run.iterations();
      ++out.completed;
      consider(l.object, static_cast<double>(l.run.error()));
    }
    return out;
  }

  /// One registration, for inspection (e.g. the transform that matched).
  typename IcpType::Result register_against(const TouchSet& test, Index object) const {
    if (object < 0 || object >= objects())
      throw InvalidArgument("object", std::to_string(object) + " is outside [0, " + std::to_string(objects()) + ")");
    test.validate("test");
    check_embedded_dimension(test, "test");
    Cloud<Scalar, Dim> points;
    embed_checked(test, points, "test");
    return icp.align(references_[static_cast<std::size_t>(object)], points);
  }

  Index objects() const override { return static_cast<Index>(references_.size()); }
  const std::vector<Reference>& references() const noexcept { return references_; }

 private:
  bool bound_is_valid() const {
    return !fixed_.empty() && !(icp.rejection.max_distance < std::numeric_limits<Scalar>::infinity());
  }

  Eigen::VectorXd lower_bounds_of(const Cloud<Scalar, Dim>& points) const {
    Eigen::VectorXd lb = Eigen::VectorXd::Zero(objects());
    if (fixed_.empty()) return lb;
    const Index d = points.rows(), b = Model::block_size(d);
    const auto& w = references_.front().weights();
    Point<Scalar, Eigen::Dynamic> q(d - b);
    const Index n = points.cols(), keep = icp.rejection.trimmed_count(n);
    std::vector<double> per_point(static_cast<std::size_t>(n));
    for (std::size_t j = 0; j < fixed_.size(); ++j) {
      for (Index i = 0; i < n; ++i) {
        q = points.col(i).tail(d - b).cwiseProduct(w.tail(d - b));
        per_point[static_cast<std::size_t>(i)] = static_cast<double>(fixed_[j].nearest(q.data()).squared_distance);
      }
      if (keep < n) std::nth_element(per_point.begin(), per_point.begin() + (keep - 1), per_point.end());
      double sum = 0;  // the `keep` smallest, in test order when keep == n
      for (Index i = 0; i < keep; ++i) sum += per_point[static_cast<std::size_t>(i)];
      lb(static_cast<Index>(j)) = sum;
    }
    return lb;
  }

  /// One initial transform per yaw start (nullopt for a zero yaw).
  std::vector<std::optional<RigidTransform<Scalar, Dim>>> initial_guesses(const Cloud<Scalar, Dim>& points) const {
    std::vector<std::optional<RigidTransform<Scalar, Dim>>> out;
    if (yaw_starts_deg.empty()) throw InvalidArgument("yaw_starts_deg", "needs at least one start");
    const Index d = points.rows();
    const Eigen::Vector2d c = points.template topRows<2>().template cast<double>().rowwise().mean();
    for (double deg : yaw_starts_deg) {
      if (!std::isfinite(deg)) throw InvalidArgument("yaw_starts_deg", "holds a non-finite angle");
      if (deg == 0.0) {
        out.emplace_back(std::nullopt);
        continue;
      }
      const double a = deg * 3.14159265358979323846 / 180.0;
      Eigen::Matrix2d R2;
      R2 << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
      RigidTransform<Scalar, Dim> T = RigidTransform<Scalar, Dim>::identity(d);
      T.R.template topLeftCorner<2, 2>() = R2.cast<Scalar>();
      T.t.template head<2>() = (c - R2 * c).cast<Scalar>();
      out.emplace_back(T);
    }
    return out;
  }

  /// What `prepare_pool` computes.
  struct FirstMatches final : PreparedPool {
    FirstMatches(std::uint64_t fit_id, const TouchSet& pool) : PreparedPool(fit_id, pool) {}
    /// Pool touch i's points are columns offsets[i] .. offsets[i + 1] - 1.
    std::vector<Index> offsets;
    /// matches[object][point]: the point's first match in that reference.
    std::vector<std::vector<Neighbor<Scalar>>> matches;
  };

  /// Every object's distance from `test`; with `first`, `test` is the pool
  /// touches `*subset` and the zero yaw start takes its first matching from
  /// `first`.
  void compute_distances(const TouchSet& test, const FirstMatches* first, const std::vector<Index>* subset,
                         Eigen::Ref<Eigen::VectorXd> out) const {
    check_dimension(out.size(), objects(), "out");
    test.validate("test");
    check_embedded_dimension(test, "test");
    thread_local Cloud<Scalar, Dim> points;
    thread_local IcpWorkspace<Scalar, Dim> workspace;
    thread_local std::vector<Neighbor<Scalar>> given;
    embed_checked(test, points, "test");
    const auto starts = initial_guesses(points);
    for (std::size_t j = 0; j < references_.size(); ++j) {
      double best = std::numeric_limits<double>::infinity();
      for (const auto& T0 : starts) {
        Scalar e;
        if (first && !T0) {
          given.clear();
          const auto& matches = first->matches[j];
          for (Index i : *subset) {
            const auto u = static_cast<std::size_t>(i);
            for (Index k = first->offsets[u]; k < first->offsets[u + 1]; ++k)
              given.push_back(matches[static_cast<std::size_t>(k)]);
          }
          e = icp.align(references_[j], points, nullptr, workspace, given).error;
        } else {
          e = icp.align(references_[j], points, T0 ? &*T0 : nullptr, workspace).error;
        }
        best = std::min(best, static_cast<double>(e));
      }
      out(static_cast<Index>(j)) = best;
    }
  }

  void embed_checked(const TouchSet& s, Cloud<Scalar, Dim>& points, const std::string& arg) const {
    embedding.template embed<Scalar, Dim>(s, points);
    check_range(s, points, arg);
  }

  /// Throws InvalidArgument when a coordinate of the embedded `points` of
  /// touches `s` is beyond largest_coordinate<Scalar>() (inf after a cast to
  /// float included): it names `arg`.positions or `arg`.contact_points and
  /// the touch when one of those is the cause (1e300 m, a unit error, became
  /// inf in a float cloud and failed inside the registration as "non-finite
  /// value inf at row 0, column 5"), otherwise the embedded value
  /// (check_coordinate_range). One pass over the points when they are in
  /// range.
  static void check_range(const TouchSet& s, const Cloud<Scalar, Dim>& points, const std::string& arg) {
    if ((points.array().abs().template cast<double>() <= largest_coordinate<Scalar>()).all()) return;
    check_touch_range(s, arg);
    check_coordinate_range<Scalar>(points, arg);
  }

  /// Throws InvalidArgument naming `arg`.positions or `arg`.contact_points
  /// and the touch for a coordinate beyond largest_coordinate<Scalar>().
  static void check_touch_range(const TouchSet& s, const std::string& arg) {
    const double limit = largest_coordinate<Scalar>();
    const auto beyond = [limit](double v) { return !(std::abs(v) <= limit); };
    const std::string range = std::string(" is beyond the ") + (std::is_same_v<Scalar, float> ? "float" : "double") +
                              " registration's range (|v| <= " + format_value(limit) +
                              "); check the unit of the positions";
    for (Index i = 0; i < s.size(); ++i)
      for (Index r = 0; r < 3; ++r)
        if (beyond(s.positions(r, i)))
          throw InvalidArgument(arg + ".positions",
                                "touch " + std::to_string(i) + ": coordinate " + format_value(s.positions(r, i)) + range);
    if (s.has_contacts())
      for (Index c = 0; c < s.contact_points.cols(); ++c)
        for (Index r = 0; r < 3; ++r)
          if (beyond(s.contact_points(r, c))) {
            const auto touch = std::upper_bound(s.contact_offsets.begin(), s.contact_offsets.end(), c) -
                               s.contact_offsets.begin() - 1;
            throw InvalidArgument(arg + ".contact_points", "touch " + std::to_string(touch) + ": coordinate " +
                                                               format_value(s.contact_points(r, c)) + range);
          }
  }

  /// Throws DimensionMismatch naming `arg` unless `s` embeds to Dim points
  /// or, for a run-time Dim, to `expected` (not checked when negative;
  /// `whose` says whose dimension that is).
  void check_embedded_dimension(const TouchSet& s, const std::string& arg, Index expected,
                                const char* whose = "") const {
    if (Dim > 0) check_dimension(embedding.dim(s), Dim, arg + " (embedded point dimension)");
    else if (expected >= 0)
      check_dimension(embedding.dim(s), expected, arg + " (embedded point dimension" + whose + ")");
  }

  /// As above, against the references of the last fit (a test or a pool).
  void check_embedded_dimension(const TouchSet& s, const std::string& arg) const {
    check_embedded_dimension(s, arg, references_.empty() ? Index{-1} : references_.front().dim());
  }

  std::vector<Reference> references_;
  std::vector<AdaptiveSearch<Scalar, Eigen::Dynamic>> fixed_;
  Index descriptor_length_ = 0;  // see descriptor_length()
  std::uint64_t fit_id_ = 0;  // detail::next_fit_id() of the last fit, 0 before
};

/// 3-D ICP on positions (the paper's kinesthetic pipeline, "icp").
template <typename Scalar = float, typename Model = Planar, typename Search = AdaptiveSearch<Scalar, 3>>
using IcpClassifier = RegistrationClassifier<PositionEmbedding, Scalar, 3, Model, Search>;

/// 4-D iCLAP on (x, y, z, word) ("iclap").
template <typename Scalar = float, typename Model = Planar, typename Search = AdaptiveSearch<Scalar, 4>>
using IclapClassifier = RegistrationClassifier<LabeledEmbedding, Scalar, 4, Model, Search>;

/// 3-D ICP on contact patches ("patch", beyond the paper).
template <typename Scalar = float, typename Model = Planar, typename Search = AdaptiveSearch<Scalar, 3>>
using PatchClassifier = RegistrationClassifier<ContactEmbedding<false>, Scalar, 3, Model, Search>;

/// 4-D iCLAP on contact patches labeled with their touch's word ("iclap_patch").
template <typename Scalar = float, typename Model = Planar, typename Search = AdaptiveSearch<Scalar, 4>>
using IclapPatchClassifier = RegistrationClassifier<ContactEmbedding<true>, Scalar, 4, Model, Search>;

/// (3 + Length)-D iCLAP on (x, y, z, descriptor) ("iclapn"); Length is the
/// descriptor length (72 for Tactile-SIFT 3x3x8) or Eigen::Dynamic.
template <int Length = Eigen::Dynamic, typename Scalar = float, typename Model = Planar,
          typename Search = AdaptiveSearch<Scalar, (Length == Eigen::Dynamic ? Eigen::Dynamic : 3 + Length)>>
using IclapNClassifier =
    RegistrationClassifier<DescriptorEmbedding, Scalar, (Length == Eigen::Dynamic ? Eigen::Dynamic : 3 + Length),
                           Model, Search>;

}  // namespace iclap

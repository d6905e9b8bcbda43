// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/types.hpp"
#include "iclap/registration/correspondence.hpp"
#include "iclap/registration/models/full_rigid.hpp"
#include "iclap/registration/reference_cloud.hpp"
#include "iclap/registration/rejector.hpp"
#include "iclap/registration/result.hpp"
#include "iclap/registration/termination.hpp"
#include "iclap/registration/transform.hpp"
#include "iclap/search/neighbor.hpp"

namespace iclap {

namespace detail {
/// Whether a termination policy takes the rounding floor (see PaperTermination).
template <typename T, typename Scalar, typename = void>
struct has_floor_check : std::false_type {};
template <typename T, typename Scalar>
struct has_floor_check<
    T, Scalar, std::void_t<decltype(std::declval<const T&>().check(0, Scalar(), Scalar(), Scalar()))>>
    : std::true_type {};
}  // namespace detail

/// Reusable buffers of `Icp::align`. Passing the same workspace to many
/// registrations (one per thread) removes their per-call allocations; with a
/// fixed `Dim` the iterations never allocate either way.
template <typename Scalar, int Dim>
struct IcpWorkspace {
  Cloud<Scalar, Dim> test_points;
  std::vector<Correspondence<Scalar>> pairs;
  /// Each test point's previous match, the warm start of its next query.
  std::vector<Index> hints;
  /// The pairs the current transform was estimated from (the kept ones
  /// first); swapped with `pairs` at every iteration, never copied.
  std::vector<Correspondence<Scalar>> previous_pairs;
  /// Counts the registrations started on this workspace. It serves one
  /// live registration at a time: one started later takes its buffers
  /// over, and the earlier one's step() and result() then throw
  /// InvalidArgument naming "workspace" instead of reading them.
  std::uint64_t registrations = 0;
};

/// Iterative Closest (Labeled) Point in `Dim` dimensions (paper, Section III;
/// equation numbers count the paper's numbered equations in order).
///
/// Each iteration matches every test point to its closest reference point
/// under the current transform (through the reference's search structure,
/// built once), rejects pairs with `rejection`, then re-estimates the motion
/// from the kept pairs in closed form: centroids c_p, c_q and
/// t = c_q - R c_p (Eqs. (1)-(2)), cross-covariance H = sum p'_i q'_i^T
/// (Eq. (3)), R = V U^T from H = U S V^T (Eqs. (4)-(6)) with det R = +1.
/// `Model` restricts which coordinates move (FullRigid: all, the paper's
/// iCLAP; SpatialRigid: x, y, z; Planar: rotation about z and x, y
/// translation; Translation: x, y, z shift).
///
/// Precision: both clouds are expressed relative to the reference centroid
/// and sums are accumulated in double (also for float clouds), so a large
/// coordinate offset costs no more than the rounding of the inputs.
///
/// Thread safety: `align` is const and re-entrant; one `Icp` and one
/// `ReferenceCloud` can serve many threads (give each its own workspace).
///
/// Complexity per iteration: n nearest-neighbour queries (O(n log m) with the
/// kd-tree), O(n B^2) for the covariance and one B x B SVD (closed forms for
/// B = 2 and, when well conditioned, B = 3), B the number of
/// moved coordinates.
template <typename Scalar, int Dim, typename Model = FullRigid,
          typename Rejector = DistanceRejector<Scalar>, typename Termination = PaperTermination<Scalar>>
class Icp {
  ICLAP_CHECK_SCALAR_AND_DIM(Scalar, Dim);
  static constexpr int B = Model::template block<Dim>;
  static_assert(Dim == Eigen::Dynamic || (B != Eigen::Dynamic && B <= Dim),
                "iclap::Icp: the transform model moves more coordinates than the points have "
                "(SpatialRigid needs Dim >= 3, Planar needs Dim >= 2)");

 public:
  using Transform = RigidTransform<Scalar, Dim>;
  using Result = RegistrationResult<Scalar, Dim>;
  using Workspace = IcpWorkspace<Scalar, Dim>;
  using ModelType = Model;

  /// When to stop (paper's three rules by default).
  Termination termination;
  /// Which pairs to keep (all by default).
  Rejector rejection;
  /// Start by translating the test centroid onto the reference centroid
  /// (along the coordinates the model translates), after `initial`.
  bool centroid_alignment = false;

  template <typename Search>
  class Registration;

  /// Registers `test` (one point per column, any floating scalar) against
  /// `reference`, starting from the identity.
  template <typename Search, typename Derived>
  Result align(const ReferenceCloud<Scalar, Dim, Search>& reference, const Eigen::MatrixBase<Derived>& test) const {
    Workspace ws;
    return align(reference, test, nullptr, ws);
  }

  /// Same, starting from `initial` (a guess of T_model_test; the model's
  /// motion is estimated on top of it, so any rigid guess is allowed). A
  /// guess whose R is no rotation (see RigidTransform::check_rotation; a
  /// result for the same reference is one) is refused naming "initial.R".
  template <typename Search, typename Derived>
  Result align(const ReferenceCloud<Scalar, Dim, Search>& reference, const Eigen::MatrixBase<Derived>& test,
               const Transform& initial) const {
    Workspace ws;
    return align(reference, test, &initial, ws);
  }

  /// Registers a cloud of your own type (a PointCloudTraits specialisation,
  /// see iclap/core/point_cloud.hpp), read once as `to_cloud` reads it, in
  /// double: the result is the one for a matrix of the same values. Throws
  /// what to_cloud throws, naming `test`, then as above. (For the other
  /// entry points, pass `to_cloud<double, Dim>(cloud)`.)
  template <typename Search, typename C, typename = std::enable_if_t<is_point_cloud_v<C>>>
  Result align(const ReferenceCloud<Scalar, Dim, Search>& reference, const C& test) const {
    return align(reference, to_cloud<double, Dim>(test, "test"));
  }

  /// Same, starting from `initial`.
  template <typename Search, typename C, typename = std::enable_if_t<is_point_cloud_v<C>>>
  Result align(const ReferenceCloud<Scalar, Dim, Search>& reference, const C& test, const Transform& initial) const {
    return align(reference, to_cloud<double, Dim>(test, "test"), initial);
  }

  /// Same, with caller-owned buffers (`initial` may be null: identity).
  template <typename Search, typename Derived>
  Result align(const ReferenceCloud<Scalar, Dim, Search>& reference, const Eigen::MatrixBase<Derived>& test,
               const Transform* initial, Workspace& workspace) const {
    auto r = start(reference, test, initial, workspace);
    r.run();
    return r.result();
  }

  /// Same, with the first matching given: `first[i]` is test point i's
  /// closest reference point under `initial`, as `first_matches` computes it
  /// (for these points or for a pool they were taken from). The result is
  /// the one of `align` without it; the first round of queries is skipped.
  /// Throws InvalidArgument naming "first_matches" when the size differs
  /// from the number of test points, when an index is out of range, when a
  /// distance is not the one between the point and its match (matches of
  /// another reference, point or initial transform), or when
  /// `centroid_alignment` is on (the first matching then depends on the whole
  /// test set).
  template <typename Search, typename Derived>
  Result align(const ReferenceCloud<Scalar, Dim, Search>& reference, const Eigen::MatrixBase<Derived>& test,
               const Transform* initial, Workspace& workspace, const std::vector<Neighbor<Scalar>>& first) const {
    auto r = start(reference, test, initial, workspace, first);
    r.run();
    return r.result();
  }

  /// Each test point's closest reference point under `initial` (null: the
  /// identity), before any update: a registration's first matching. Without
  /// `centroid_alignment` it depends on each point alone, not on the other
  /// test points, so when many registrations take their test points from one
  /// pool (cross validation draws subsets of a held-out exploration), the
  /// pool's first matches can be computed once and each registration given
  /// its points' entries (`align` / `start` with `first`), which skips its
  /// first round of nearest-neighbour queries and changes nothing else.
  /// Throws like `align`, and InvalidArgument naming "centroid_alignment"
  /// when it is on.
  template <typename Search, typename Derived>
  void first_matches(const ReferenceCloud<Scalar, Dim, Search>& reference, const Eigen::MatrixBase<Derived>& test,
                     const Transform* initial, Workspace& workspace, std::vector<Neighbor<Scalar>>& out) const {
    reject_centroid_alignment();
    const Index b = working_test_points(reference, test, initial, workspace);
    const Index n = test.cols();
    workspace.pairs.resize(static_cast<std::size_t>(n));
    workspace.hints.assign(static_cast<std::size_t>(n), Index(-1));
    // The first matching of a registration: the identity block motion.
    const BlockMatrix R = AccBlockMatrix::Identity(b, b).template cast<Scalar>();
    const BlockVector t = AccBlockVector::Zero(b).template cast<Scalar>();
    Point<Scalar, Dim> y(reference.dim());
    match(workspace.test_points, R, t, reference, y, workspace.pairs, workspace.hints, b, nullptr);
    out.resize(static_cast<std::size_t>(n));
    for (const auto& c : workspace.pairs) out[static_cast<std::size_t>(c.test)] = {c.model, c.squared_distance};
  }

  /// Starts a registration without running it: the first matching is done
  /// and checked against the stopping rules; `step()` then advances one
  /// iteration at a time. This is what schedules across many registrations
  /// build on (several initial guesses, many objects: run a few iterations of
  /// each, continue with the promising ones). `reference`, `workspace` and
  /// this Icp must outlive the returned object, and the workspace serves
  /// this registration alone while it is live: give each registration of a
  /// schedule its own (a later start on it makes this one's step() and
  /// result() throw, naming "workspace"). Throws like `align`.
  template <typename Search, typename Derived>
  Registration<Search> start(const ReferenceCloud<Scalar, Dim, Search>& reference,
                             const Eigen::MatrixBase<Derived>& test, const Transform* initial,
                             Workspace& workspace) const {
    return Registration<Search>(*this, reference, test, initial, workspace, nullptr);
  }

  /// Same, with the first matching given (see `align` with `first`).
  template <typename Search, typename Derived>
  Registration<Search> start(const ReferenceCloud<Scalar, Dim, Search>& reference,
                             const Eigen::MatrixBase<Derived>& test, const Transform* initial, Workspace& workspace,
                             const std::vector<Neighbor<Scalar>>& first) const {
    reject_centroid_alignment();
    check_dimension(static_cast<Index>(first.size()), test.cols(), "first_matches");
    return Registration<Search>(*this, reference, test, initial, workspace, first.data());
  }

  /// The registration keeps a pointer to the reference: a temporary one
  /// would dangle, so it does not compile.
  template <typename Search, typename Derived>
  Registration<Search> start(const ReferenceCloud<Scalar, Dim, Search>&& reference,
                             const Eigen::MatrixBase<Derived>& test, const Transform* initial,
                             Workspace& workspace) const = delete;
  template <typename Search, typename Derived>
  Registration<Search> start(const ReferenceCloud<Scalar, Dim, Search>&& reference,
                             const Eigen::MatrixBase<Derived>& test, const Transform* initial, Workspace& workspace,
                             const std::vector<Neighbor<Scalar>>& first) const = delete;

 private:
  // Also used by Registration (a nested class sees them).
  using Acc = Accumulator<Scalar>;
  using AccPoint = Point<Acc, Dim>;
  using AccMatrix = SquareMatrix<Acc, Dim>;
  using BlockMatrix = SquareMatrix<Scalar, B>;
  using BlockVector = Point<Scalar, B>;
  using AccBlockMatrix = SquareMatrix<Acc, B>;
  using AccBlockVector = Point<Acc, B>;

  template <typename V>
  static auto block_of(V&& v, Index b) {
    if constexpr (B == Eigen::Dynamic) {
      return v.head(b);
    } else {
      (void)b;
      return v.template head<B>();
    }
  }

  void reject_centroid_alignment() const {
    if (centroid_alignment)
      throw InvalidArgument("centroid_alignment",
                            "is on, so the first matching depends on the whole test set; first_matches need it off");
  }

  /// Working test points p' = W (T0(p) - c), computed as
  /// W (R0 (p - c) + (R0 - I) c + t0), into `ws.test_points` (after the
  /// input checks); returns the model's block size.
  template <typename Search, typename Derived>
  static Index working_test_points(const ReferenceCloud<Scalar, Dim, Search>& reference,
                                   const Eigen::MatrixBase<Derived>& test, const Transform* initial, Workspace& ws) {
    static_assert(std::is_floating_point_v<typename Derived::Scalar>, "iclap::Icp: test points must be floating point");
    if (reference.size() == 0) throw EmptyInput("reference", "is empty (default-constructed)");
    check_not_empty(test, "test");
    const Index d = reference.dim();
    check_dimension(test.rows(), d, "test");
    check_finite(test, "test");
    Model::check_dimension(d);
    if (initial) {
      initial->validate(d, "initial");
      initial->check_rotation(reference.weights(), "initial");
    }
    const Index n = test.cols();
    const AccPoint c = reference.centroid_accurate();
    const AccPoint w = reference.weights().template cast<Acc>();
    ws.test_points.resize(d, n);
    const bool rotate0 = initial && !initial->R.isIdentity(Scalar(0));
    AccMatrix R0 = AccMatrix::Zero(d, d);  // (set when rotate0; zeroed so that GCC 12 sees it initialised)
    AccPoint o = AccPoint::Zero(d);
    if (initial) {
      R0 = initial->R.template cast<Acc>();
      o = initial->t.template cast<Acc>();
      if (rotate0) o += R0 * c - c;
    }
    const Acc limit = static_cast<Acc>(largest_coordinate<Scalar>());
    AccPoint tmp(d), moved(d);
    for (Index j = 0; j < n; ++j) {
      tmp = test.col(j).template cast<Acc>() - c;
      if (rotate0) {
        moved.noalias() = R0 * tmp;
        moved = w.cwiseProduct(moved + o);
      } else {
        moved = w.cwiseProduct(tmp + o);
      }
      check_range(j, tmp, w, moved, initial != nullptr, limit);
      ws.test_points.col(j) = moved.template cast<Scalar>();
    }
    return Model::block_size(d);
  }

  /// Test point `j` beyond the range the scalar type can square
  /// (largest_coordinate) from the reference centroid, weighted, is refused
  /// naming "test": its squared distances would overflow (in float, an
  /// offset of 1e18 gave an error of inf that no stopping rule could
  /// compare). Where the point is in range but `initial` (`moved_by_initial`)
  /// moves it beyond, "initial" is named instead, since the search would
  /// find no finite distance for it. `own` is the point about the centroid
  /// before the motion and unweighted, `moved` after it and weighted by `w`.
  /// Checked as each point is written, so the test is read once.
  static void check_range(Index j, const AccPoint& own, const AccPoint& w, const AccPoint& moved,
                          bool moved_by_initial, Acc limit) {
    const Acc reach = moved.cwiseAbs().maxCoeff();
    if (reach <= limit) return;  // false for NaN and inf
    const Acc own_reach = moved_by_initial ? w.cwiseProduct(own).cwiseAbs().maxCoeff() : reach;
    const auto beyond = [limit](Acc v) {
      return "a weighted coordinate of " + format_value(static_cast<double>(v)) +
             " from the reference centroid, beyond what the registration's scalar type can square (|v| <= " +
             format_value(static_cast<double>(limit)) + ")";
    };
    if (!(own_reach <= limit))
      throw InvalidArgument("test", "point " + std::to_string(j) + " is at " + beyond(own_reach) +
                                        "; check the units of the test and the reference");
    throw InvalidArgument("initial", "moves test point " + std::to_string(j) + " to " + beyond(reach) +
                                         "; check the unit of its translation and rotation");
  }

  /// Matches every working test point under (R, t) and applies the rejector.
  /// Returns E over the kept pairs, which are moved to the front. `given`:
  /// see `match`.
  template <typename Search>
  Acc correspond(const Cloud<Scalar, Dim>& P, const BlockMatrix& R, const BlockVector& t,
                 const ReferenceCloud<Scalar, Dim, Search>& reference, Point<Scalar, Dim>& y,
                 std::vector<Correspondence<Scalar>>& pairs, std::vector<Index>& hints, Index b, Index& kept,
                 const Neighbor<Scalar>* given) const {
    const Index n = P.cols();
    const Acc all = match(P, R, t, reference, y, pairs, hints, b, given);
    kept = rejection.select(pairs.data(), n);
    // A policy of the user's own that miscounts would make E a sum over
    // pairs that do not exist (a negative count, or one past the pairs).
    if (kept < 0 || kept > n)
      throw InvalidArgument("rejection", "kept " + std::to_string(kept) + " of " + std::to_string(n) +
                                             " pairs; a rejector returns how many of the n pairs it kept, in [0, n]");
    if (kept == n) return all;
    Acc e = 0;
    for (Index k = 0; k < kept; ++k) e += static_cast<Acc>(pairs[static_cast<std::size_t>(k)].squared_distance);
    return e;
  }

  /// Matches every working test point under (R, t), in test order, and
  /// returns E over every pair. With `given` (one match per test point, see
  /// `first_matches`) the matches are taken from it instead of searched,
  /// after checking that each names a reference point at the distance the
  /// search would have reported.
  template <typename Search>
  Acc match(const Cloud<Scalar, Dim>& P, const BlockMatrix& R, const BlockVector& t,
            const ReferenceCloud<Scalar, Dim, Search>& reference, Point<Scalar, Dim>& y,
            std::vector<Correspondence<Scalar>>& pairs, std::vector<Index>& hints, Index b,
            const Neighbor<Scalar>* given) const {
    const auto& search = reference.search();
    const Index n = P.cols(), d = P.rows();
    Acc all = 0;  // E over every pair, summed in test order
    for (Index i = 0; i < n; ++i) {
      // y = block motion applied to the moved coordinates, the rest copied.
      if constexpr (Dim != Eigen::Dynamic && B == Dim) {
        y.noalias() = R * P.col(i);
        y += t;
      } else {
        auto yb = block_of(y, b);
        yb.noalias() = R * block_of(P.col(i), b);
        yb += t;
        if (d > b) y.tail(d - b) = P.col(i).tail(d - b);
      }
      Neighbor<Scalar> nb;
      if (given) {
        nb = given[i];
        check_given(nb, y, reference.working_points(), i);
        hints[static_cast<std::size_t>(i)] = nb.index;
      } else if constexpr (detail::has_hinted_nearest<Search, Scalar>::value) {
        nb = search.nearest(y.data(), hints[static_cast<std::size_t>(i)]);  // same answer, found sooner
        hints[static_cast<std::size_t>(i)] = nb.index;
      } else {
        (void)hints;
        nb = search.nearest(y.data());
      }
      // A search answers "no neighbour" when every squared distance
      // overflows: the coordinates (times the weights) are beyond what the
      // scalar type can square.
      if (nb.index >= reference.size())
        throw InvalidArgument("search", "answered reference point " + std::to_string(nb.index) + " of " +
                                            std::to_string(reference.size()) + " for test point " + std::to_string(i));
      if (nb.index < 0)
        throw InvalidArgument("test", "point " + std::to_string(i) +
                                          " has no finite squared distance to any reference point: the coordinates "
                                          "(times the weights) overflow the scalar type when squared; rescale them "
                                          "or use double");
      pairs[static_cast<std::size_t>(i)] = {i, nb.index, nb.squared_distance};
      all += static_cast<Acc>(nb.squared_distance);
    }
    return all;
  }

  /// A given match must name a reference point and carry the squared
  /// distance between it and the matched point (up to the rounding of a
  /// search policy that sums in another order): this catches matches of
  /// another reference, pool or initial transform.
  static void check_given(const Neighbor<Scalar>& nb, const Point<Scalar, Dim>& y, const Cloud<Scalar, Dim>& M,
                          Index i) {
    const auto where = [&] { return "entry " + std::to_string(i) + " "; };
    if (nb.index < 0 || nb.index >= M.cols())
      throw InvalidArgument("first_matches", where() + "names reference point " + std::to_string(nb.index) +
                                                 " of " + std::to_string(M.cols()));
    const Scalar actual = detail::squared_distance<Dim>(y.data(), M.col(nb.index).data(), M.rows());
    const Scalar tolerance =
        Scalar(64) * std::numeric_limits<Scalar>::epsilon() * std::max(actual, nb.squared_distance);
    if (!std::isfinite(nb.squared_distance) || !(std::abs(actual - nb.squared_distance) <= tolerance))
      throw InvalidArgument("first_matches", where() + "gives squared distance " + format_value(static_cast<double>(nb.squared_distance)) +
                                                 " to reference point " + std::to_string(nb.index) + ", which is at " +
                                                 format_value(static_cast<double>(actual)) +
                                                 " (matches of another reference, test point or initial transform)");
  }

  /// Centroids and cross-covariance of the kept pairs (block coordinates) in
  /// one pass, shifted by the first pair so that no precision is lost to a
  /// large common offset, then the model's closed-form estimate.
  BlockEstimate<Acc, B> estimate(const Cloud<Scalar, Dim>& P, const Cloud<Scalar, Dim>& M,
                                 const std::vector<Correspondence<Scalar>>& pairs, Index kept, Index b) const {
    const auto& first = pairs.front();
    const AccBlockVector p0 = block_of(P.col(first.test), b).template cast<Acc>();
    const AccBlockVector q0 = block_of(M.col(first.model), b).template cast<Acc>();
    AccBlockVector sp = AccBlockVector::Zero(b), sq = AccBlockVector::Zero(b), dp(b), dq(b);
    AccBlockMatrix H = AccBlockMatrix::Zero(b, b);
    for (Index k = 0; k < kept; ++k) {
      const auto& c = pairs[static_cast<std::size_t>(k)];
      dp = block_of(P.col(c.test), b).template cast<Acc>() - p0;
      dq = block_of(M.col(c.model), b).template cast<Acc>() - q0;
      sp += dp;
      sq += dq;
      if constexpr (Model::uses_covariance) H.noalias() += dp * dq.transpose();
    }
    const Acc inv = Acc(1) / static_cast<Acc>(kept);
    if constexpr (Model::uses_covariance) H.noalias() -= (sp * inv) * sq.transpose();
    const AccBlockVector cp = p0 + sp * inv, cq = q0 + sq * inv;
    return Model::template estimate<Acc, B>(cp, cq, H, detail::rank_tolerance<Scalar>(b));
  }
};

/// A registration in progress (see Icp::start). After construction the
/// current transform's closest-point error is known; each `step()` makes one
/// transform update and one matching. Without a `max_distance` the error
/// never increases from one step to the next (the closed-form update
/// minimises E over the kept pairs, and each point's new match is at least
/// as close; with trimming, the closest pairs after matching sum to no more
/// than the previously kept ones now do), which pruning schedules rely on;
/// "never" is up to rounding (a few ulps: trimming sums the kept pairs in a
/// different order each step).
template <typename Scalar, int Dim, typename Model, typename Rejector, typename Termination>
template <typename Search>
class Icp<Scalar, Dim, Model, Rejector, Termination>::Registration {
 public:
  /// `first`: the given first matching (see Icp::align with `first`), one
  /// entry per test point, or null.
  template <typename Derived>
  Registration(const Icp& icp, const ReferenceCloud<Scalar, Dim, Search>& reference,
               const Eigen::MatrixBase<Derived>& test, const Transform* initial, Workspace& ws,
               const Neighbor<Scalar>* first)
      : icp_(&icp), reference_(&reference), ws_(&ws), registration_(++ws.registrations) {
    icp.termination.validate();
    icp.rejection.validate();
    b_ = working_test_points(reference, test, initial, ws);
    const Index d = reference.dim(), n = test.cols();
    if (initial) {
      initial_ = *initial;
      has_initial_ = true;
    }
    ws.pairs.resize(static_cast<std::size_t>(n));
    // Sized now, so that no iteration allocates (the first step swaps it in).
    ws.previous_pairs.resize(static_cast<std::size_t>(n));
    ws.hints.assign(static_cast<std::size_t>(n), Index(-1));

    // Block motion in working coordinates.
    R_acc_ = AccBlockMatrix::Identity(b_, b_);
    t_acc_ = AccBlockVector::Zero(b_);
    if (icp.centroid_alignment) {
      for (Index j = 0; j < n; ++j) t_acc_ -= block_of(ws.test_points.col(j), b_).template cast<Acc>();
      t_acc_ /= static_cast<Acc>(n);  // the reference centroid is the working origin
    }
    R_ = R_acc_.template cast<Scalar>();
    t_ = t_acc_.template cast<Scalar>();
    y_.resize(d);
    match_and_check(first);
  }

  /// Not copyable: a copy would share the workspace and overwrite the
  /// original's pairs. Movable (schedules keep registrations in vectors).
  Registration(const Registration&) = delete;
  Registration& operator=(const Registration&) = delete;
  Registration(Registration&&) = default;
  Registration& operator=(Registration&&) = default;

  /// True once a stopping rule has fired (or no pair survived rejection).
  bool done() const noexcept { return done_; }
  /// E at the current transform (+infinity without pairs).
  Scalar error() const noexcept {
    return kept_ > 0 ? static_cast<Scalar>(error_) : std::numeric_limits<Scalar>::infinity();
  }
  Index pairs() const noexcept { return kept_; }
  int iterations() const noexcept { return iterations_; }
  StopReason stop_reason() const noexcept { return reason_; }

  /// One iteration: re-estimate the motion from the current pairs, match
  /// again, check the stopping rules. Returns !done(); a no-op once done.
  bool step() {
    if (done_) return false;
    check_workspace();
    if (fixed_point_) {
      // The pairs matched under the current transform are the pairs it was
      // estimated from: this update would give the same transform, pairs and
      // E again, so only the count and the stopping rules move (no search).
      ++iterations_;
      previous_ = error_;
      check_stop();
      return !done_;
    }
    ws_->pairs.swap(ws_->previous_pairs);
    previous_kept_ = kept_;
    const auto e = icp_->estimate(ws_->test_points, reference_->working_points(), ws_->previous_pairs, kept_, b_);
    ws_->pairs.resize(ws_->previous_pairs.size());
    R_acc_ = e.R;
    t_acc_ = e.t;
    R_ = R_acc_.template cast<Scalar>();
    t_ = t_acc_.template cast<Scalar>();
    ++iterations_;
    previous_ = error_;
    match_and_check();
    if (!done_) fixed_point_ = same_pairs();
    return !done_;
  }

  /// Steps until a stopping rule fires.
  void run() {
    while (step()) {
    }
  }

  /// The outcome so far (final once done()): the transform in original
  /// coordinates, E, RMSE, and the degeneracy of the current pairs.
  Result result() const {
    check_workspace();
    Result result;
    result.iterations = iterations_;
    result.stop_reason = reason_;
    result.converged = done_ && (reason_ == StopReason::AbsoluteTolerance || reason_ == StopReason::RelativeTolerance);
    result.pairs = kept_;
    if (kept_ > 0) {
      result.error = static_cast<Scalar>(error_);
      result.rmse = static_cast<Scalar>(std::sqrt(error_ / static_cast<Acc>(kept_)));
      result.degenerate =
          icp_->estimate(ws_->test_points, reference_->working_points(), ws_->pairs, kept_, b_).degenerate;
    } else {
      result.error = result.rmse = std::numeric_limits<Scalar>::infinity();
      result.degenerate = true;
    }
    result.T_model_test = transform();
    return result;
  }

  /// The current T_model_test in original coordinates: with
  /// A = W^-1 blockdiag(R_w, I) W and b' = (t_w, 0), T = A T0 + (I - A) c + W^-1 b'.
  Transform transform() const {
    const Index d = reference_->dim();
    const AccPoint c = reference_->centroid_accurate();
    const AccPoint w = reference_->weights().template cast<Acc>();
    AccMatrix A = AccMatrix::Identity(d, d);
    const AccBlockVector wb = block_of(w, b_);
    A.topLeftCorner(b_, b_) = wb.cwiseInverse().asDiagonal() * R_acc_ * wb.asDiagonal();
    AccPoint translation = AccPoint::Zero(d);
    translation.head(b_) = (AccBlockMatrix::Identity(b_, b_) - A.topLeftCorner(b_, b_)) * block_of(c, b_) +
                           t_acc_.cwiseQuotient(wb);
    AccMatrix R_final = A;
    if (has_initial_) {
      R_final = A * initial_.R.template cast<Acc>();
      translation += A * initial_.t.template cast<Acc>();
    }
    Transform T;
    T.R = R_final.template cast<Scalar>();
    T.t = translation.template cast<Scalar>();
    return T;
  }

 private:
  // The precision aliases (Acc, AccPoint, BlockMatrix, ...) are Icp's.

  /// The kept pairs, in order, equal those the current transform was
  /// estimated from (the first previous_kept_ of ws_->previous_pairs)?
  bool same_pairs() const {
    if (kept_ != previous_kept_) return false;
    for (std::size_t k = 0; k < static_cast<std::size_t>(kept_); ++k)
      if (ws_->pairs[k].test != ws_->previous_pairs[k].test || ws_->pairs[k].model != ws_->previous_pairs[k].model)
        return false;
    return true;
  }

  void check_stop() {
    std::optional<StopReason> stop;
    if constexpr (detail::has_floor_check<Termination, Scalar>::value)
      stop = icp_->termination.check(iterations_, static_cast<Scalar>(error_), static_cast<Scalar>(previous_),
                                     rounding_floor());
    else
      stop = icp_->termination.check(iterations_, static_cast<Scalar>(error_), static_cast<Scalar>(previous_));
    if (stop) {
      done_ = true;
      reason_ = *stop;
    }
  }

  /// The E that rounding alone gives an exact fit: each of the d coordinate
  /// differences of a kept pair is off by a few units in the last place of
  /// the clouds' scale (a point moved by R and t in Scalar, then
  /// subtracted). 64 units leave a wide margin: exact fits measured up to
  /// 5.4 units RMS per coordinate (2352 registrations of exact copies,
  /// float and double, 3-, 4- and 8-D, trimmed and not, objects of 1 mm to
  /// 100 m, offsets up to 10 times their size). Far below any real fit:
  /// in float, for a 0.1 m object, an RMS distance of about 1.5 um (4-D).
  Scalar rounding_floor() const {
    const Acc unit = Acc(64) * static_cast<Acc>(std::numeric_limits<Scalar>::epsilon()) *
                     static_cast<Acc>(reference_->spread());
    return static_cast<Scalar>(static_cast<Acc>(kept_) * static_cast<Acc>(reference_->dim()) * unit * unit);
  }

  void match_and_check(const Neighbor<Scalar>* given = nullptr) {
    error_ = icp_->correspond(ws_->test_points, R_, t_, *reference_, y_, ws_->pairs, ws_->hints, b_, kept_, given);
    if (kept_ == 0) {
      done_ = true;
      reason_ = StopReason::NoCorrespondences;
      return;
    }
    check_stop();
  }

  /// The workspace holds this registration's pairs only while no later one
  /// has started on it.
  void check_workspace() const {
    if (ws_->registrations != registration_)
      throw InvalidArgument("workspace", "another registration was started on this registration's workspace, "
                                         "which now holds that one's pairs; give each live registration a "
                                         "workspace of its own");
  }

  const Icp* icp_;
  const ReferenceCloud<Scalar, Dim, Search>* reference_;
  Workspace* ws_;
  std::uint64_t registration_;
  // Not a std::optional: g++ 12 at -O1 took the payload of an empty one,
  // moved in std::stable_partition of RegistrationClassifier's live
  // registrations, for uninitialised (a -Wmaybe-uninitialized false
  // positive, an error under -Werror). The identity (0 x 0 for a run-time
  // dimension) is never used; it only keeps a fixed-size one initialised.
  Transform initial_ = Transform::identity();
  bool has_initial_ = false;
  Index b_ = 0;
  AccBlockMatrix R_acc_;
  AccBlockVector t_acc_;
  BlockMatrix R_;
  BlockVector t_;
  Point<Scalar, Dim> y_;
  Acc error_ = 0, previous_ = 0;
  Index kept_ = 0, previous_kept_ = 0;
  int iterations_ = 0;
  bool done_ = false;
  bool fixed_point_ = false;  // see step()
  StopReason reason_ = StopReason::MaxIterations;
};

}  // namespace iclap

// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/recognition/classifier.hpp"
#include "iclap/search/distance_field.hpp"

namespace iclap {

/// A bounded grid of planar placements of an object on its table (beyond
/// the paper): shifts (dx, dy) on a square lattice of spacing `shift_step`
/// within a disc of radius `max_shift`, times turns about the vertical in
/// steps of `yaw_step` within +-`max_yaw`. It models how precisely the
/// object is put back between explorations: the scene's prior, which the
/// unbounded planar ICP ignores (it may slide a test anywhere on the table).
/// Set it to the rig; the simulator re-places its objects within 10 mm and
/// +-10 degrees by default (ExplorationSettings::placement_shift, _yaw).
struct PlanarPlacements {
  double max_shift = 10e-3;                              ///< metres, >= 0
  double shift_step = 4e-3;                              ///< metres, > 0
  double max_yaw = 10.0 * 3.14159265358979323846 / 180;  ///< radians, in [0, pi]
  double yaw_step = 5.0 * 3.14159265358979323846 / 180;  ///< radians, > 0

  /// Largest number of placements a grid may have.
  static constexpr double kMaxPlacements = 1e5;

  /// Throws InvalidArgument naming `argument`.max_shift / .shift_step /
  /// .max_yaw / .yaw_step for a value out of range, or `argument` for a grid
  /// of more than kMaxPlacements placements.
  void validate(const std::string& argument = "placements") const {
    check_non_negative(max_shift, argument + ".max_shift");
    check_positive(shift_step, argument + ".shift_step");
    if (!(max_yaw >= 0 && max_yaw <= 3.14159265358979323846))
      throw InvalidArgument(argument + ".max_yaw", "must be in [0, pi] rad, got " + format_value(max_yaw));
    check_positive(yaw_step, argument + ".yaw_step");
    // The steps each way that grid() takes (the same rounding: 0.3 / 0.1 is
    // 2.9999999999999996 and takes 3).
    const double shifts = std::pow(2 * steps(max_shift, shift_step) + 1, 2);
    const double yaws = 2 * steps(max_yaw, yaw_step) + 1;
    if (!(shifts * yaws <= kMaxPlacements))
      throw InvalidArgument(argument, "a grid of up to " + format_value(shifts * yaws) + " placements exceeds " +
                                          format_value(kMaxPlacements) + "; use larger steps");
  }

  /// The grid as (dx, dy, yaw) columns, the identity first, then by
  /// increasing shift and turn (ties between equal errors go to the smaller
  /// motion). Throws like validate().
  Eigen::Matrix3Xd grid(const std::string& argument = "placements") const {
    validate(argument);
    const int ns = static_cast<int>(steps(max_shift, shift_step));
    const int ny = static_cast<int>(steps(max_yaw, yaw_step));
    std::vector<Eigen::Vector3d> out;
    for (int a = -ns; a <= ns; ++a)
      for (int b = -ns; b <= ns; ++b) {
        const double dx = a * shift_step, dy = b * shift_step;
        if (std::hypot(dx, dy) > max_shift * (1 + 1e-9)) continue;
        for (int y = -ny; y <= ny; ++y) out.emplace_back(dx, dy, y * yaw_step);
      }
    std::stable_sort(out.begin(), out.end(), [](const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
      const double sp = p.head<2>().squaredNorm(), sq = q.head<2>().squaredNorm();
      return sp != sq ? sp < sq : std::abs(p.z()) < std::abs(q.z());
    });
    Eigen::Matrix3Xd m(3, static_cast<Index>(out.size()));
    for (std::size_t k = 0; k < out.size(); ++k) m.col(static_cast<Index>(k)) = out[k];
    return m;
  }

 private:
  /// Whole steps of `step` within `range`, a ratio within 1e-9 of a whole
  /// number counting as that number.
  static double steps(double range, double step) { return std::floor(range / step + 1e-9); }
};

/// What is known of one object's surface: points where it was felt
/// (`occupied`, e.g. the contact points of its training touches, or points
/// sampled on a CAD model, sample_surface) and points where a pad was and it
/// was not (`free`, the taxels of those touches that felt nothing; may be
/// empty). Metres, in the table frame of the references. `turn_centre` is
/// the vertical axis (x, y) the placements turn the object about; without
/// it, the centroid of the occupied points, about which a turn moves the
/// known surface least. (For the training touches of the built-in objects
/// the centroid gave 72.8% at 20 touches, the centre of their bounding box
/// 69.6%; a CAD model that the scene turns about its origin wants that.)
struct OccupancyEvidence {
  Eigen::Matrix3Xd occupied;
  Eigen::Matrix3Xd free;
  std::optional<Eigen::Vector2d> turn_centre;
};

/// Recognition from where the pad felt the object and where it did not
/// (beyond the paper). Every touch of a tactile array is a small map: the
/// pressed taxels lie on the surface (its contact points), and the others
/// lie where, at that moment, there was no surface within the foam's reach
/// (its free points, TouchSet::free_points). The training touches of each
/// object give two truncated distance fields: D_occ to the closest occupied
/// point (truncated at tau = `truncation`) and D_free to the closest free
/// point (truncated at rho = `free_radius`). A test touch i is scored under
/// a planar placement g of the object (PlanarPlacements, turning about
/// OccupancyEvidence::turn_centre, by default the centroid of the object's
/// occupied points) as
///
///   c_i(g) = sum over its contact points p of  min(D_occ(g p)^2, tau^2)
///                + gamma tau^2 [D_free(g p) < min(D_occ(g p), rho)]
///              (or kappa tau^2 where D_occ(g p) >= tau and D_free(g p) >= rho)
///          + sum over its free points u of  gamma tau^2 [D_occ(g u) < min(D_free(g u), rho)]
///
/// (the fields interpolated trilinearly, except in the free points' test,
/// which reads the nearest lattice node)
/// and the distance of a test to the object is E = min_g sum_i c_i(g).
/// With `back_depth` b > 0, the slab behind each pad, up to b from its
/// surface, counts as free as well: the pad's body was there, so the object
/// was not (beyond the paper). Every taxel of a touch, pressed or not, is
/// moved back along the pad normal n (TouchSet::normals) to layers at
/// depths b k / m, k = 1..m, m = ceil(b / (1.5 rho)) (so the free radius
/// covers the slab without gaps): for the training touches these points
/// join the free evidence, and for a test touch they are tested like its
/// free points (the last sum above). A test touch pressed above a surface
/// that a training pad felt from above, or a test pad whose back would cut
/// through felt surface, then pays a contradiction.
/// The first term is the paper's point-to-point error (Section IV, E_ICP)
/// with every pressed taxel as a point, truncated so that a touch on
/// surface the references never saw costs tau^2 whatever the object; the
/// two bracketed terms (gamma = `conflict_weight`) charge a contradiction:
/// the test pressed where a training pad felt nothing, or felt nothing
/// where a training pad pressed. A thin handle and a broad face at one
/// height, or the overhang of a pad past an edge that one look-alike has
/// and the other has not, then differ even where the explorations touched
/// different places. The placement is searched exhaustively over the grid,
/// not by ICP iterations: there is no sliding into a wrong local fit
/// outside the prior, and the per-touch costs of a pool of touches can be
/// computed once for every subset drawn from it (`prepare_pool`).
///
/// Costs O(placements x objects x taxels per touch) field lookups per test
/// touch (105 placements by default; about 1.8 M lookups for 20 touches
/// against 20 objects of the 14 x 6 pad, at most: free and slab points
/// lying too far above or below all of an object's felt surface to be
/// charged are dropped once per touch). The fields take memory in
/// proportion to the surface the evidence covers (TruncatedDistanceField).
/// `distances` is const and thread-safe.
class OccupancyClassifier final : public Classifier {
 public:
  /// Field lattice spacing, metres (1 mm: a third of the WTS taxel pitch).
  double voxel = 1e-3;
  /// tau: the largest squared distance a contact point is charged is tau^2,
  /// metres (3 mm, about the taxel pitch); at most 64 voxels.
  double truncation = 3e-3;
  /// rho: how close a point of the other kind must be for a contradiction,
  /// metres; in (0, truncation].
  double free_radius = 2e-3;
  /// gamma: the cost of a contradiction in units of tau^2; >= 0 (0: the
  /// free points are not used).
  double conflict_weight = 0.3;
  /// kappa: the cost of a contact point with no evidence of either kind within
  /// reach (D_occ at tau and D_free at rho: where no training pad ever
  /// was), in units of tau^2; in [0, 1]. 1 (the default) charges it as a
  /// miss, the same as a point near neither kind that the references saw
  /// differently; less charges surface the training never explored less
  /// than surface it explored and found elsewhere.
  double unknown_cost = 1;
  /// b: the depth of the slab behind the pad that counts as free, metres;
  /// 0 (the default): none. At most kMaxBackRadii free radii (so at most
  /// 11 layers). Needs the pad normals of the touches (TouchSet::normals).
  double back_depth = 0;
  /// The placements searched.
  PlanarPlacements placements;
  /// The name in a Recognizer; empty (the default): "occupancy".
  std::string label;

  std::string name() const override { return label.empty() ? "occupancy" : label; }

  /// Throws InvalidArgument naming the first setting out of range ("voxel",
  /// "truncation", "free_radius", ...), so that fit refuses nothing
  /// validate() accepted.
  void validate() const {
    check_field(truncation, "truncation");
    if (!(std::isfinite(free_radius) && free_radius > 0 && free_radius <= truncation))
      throw InvalidArgument("free_radius", "must be > 0 and at most truncation (" + format_value(truncation) +
                                               " m), got " + format_value(free_radius));
    check_field(free_radius, "free_radius");  // the free points' field
    check_non_negative(conflict_weight, "conflict_weight");
    if (!(unknown_cost >= 0 && unknown_cost <= 1))
      throw InvalidArgument("unknown_cost", "must be in [0, 1], got " + format_value(unknown_cost));
    if (!(back_depth >= 0 && back_depth <= kMaxBackRadii * free_radius))
      throw InvalidArgument("back_depth", "must be >= 0 and at most " + std::to_string(kMaxBackRadii) +
                                              " free radii (" + format_value(kMaxBackRadii * free_radius) +
                                              " m), got " + format_value(back_depth));
    placements.validate("placements");
  }

  /// The deepest slab behind the pad (back_depth), in free radii.
  static constexpr int kMaxBackRadii = 16;

  /// The depths behind the pad at which the taxels are moved (back_depth):
  /// b k / m for k = 1..m, m = ceil(b / (1.5 free_radius)); empty for b = 0.
  /// Validates the settings first.
  std::vector<double> back_layers() const {
    validate();
    return layers_of(back_depth, free_radius);
  }

  /// The references from training touches: object j's contact points are
  /// its occupied evidence and its free points its free evidence, with the
  /// slab behind its pads under back_depth (turning about the centroid of
  /// the contact points). Throws
  /// EmptyInput naming "objects" for none, "objects[j].contact_points" /
  /// "objects[j].free_points" for an object without them (touches without
  /// the pad orientation), "objects[j].normals" under back_depth for an
  /// object without pad normals, and what fit_evidence throws.
  void fit(const std::vector<TouchSet>& objects, Index /*vocabulary*/) override {
    const std::vector<double> layers = back_layers();
    std::vector<OccupancyEvidence> evidence(objects.size());
    for (std::size_t j = 0; j < objects.size(); ++j) {
      const TouchSet& t = objects[j];
      const std::string arg = "objects[" + std::to_string(j) + "]";
      t.validate(arg);
      require_taxels(t, arg, !layers.empty());
      evidence[j].occupied = t.contact_points;
      evidence[j].free.resize(3, t.free_points.cols() + static_cast<Index>(layers.size()) *
                                                            (t.free_points.cols() + t.contact_points.cols()));
      evidence[j].free.leftCols(t.free_points.cols()) = t.free_points;
      Index k = t.free_points.cols();
      for (Index i = 0; i < t.size(); ++i)
        for_back_points(t, i, layers, [&](const Eigen::Vector3d& q) { evidence[j].free.col(k++) = q; });
    }
    fit_evidence(evidence);
  }

  /// The references from any evidence (e.g. surfaces sampled from CAD
  /// models, with no free points). Throws what validate() throws, EmptyInput
  /// naming "objects" for none or "objects[j].occupied" for an object with
  /// no occupied point, NonFiniteValue naming "objects[j].turn_centre", and
  /// what TruncatedDistanceField throws (naming "objects[j].occupied" /
  /// ".free").
  void fit_evidence(const std::vector<OccupancyEvidence>& objects) {
    validate();
    if (objects.empty()) throw EmptyInput("objects", "no object to recognise");
    std::vector<Reference> refs;
    refs.reserve(objects.size());
    for (std::size_t j = 0; j < objects.size(); ++j) {
      const std::string arg = "objects[" + std::to_string(j) + "]";
      if (objects[j].occupied.cols() == 0) throw EmptyInput(arg + ".occupied", "no point where the object was felt");
      Reference r;
      r.occupied = TruncatedDistanceField(objects[j].occupied, {voxel, truncation}, arg + ".occupied");
      r.free = TruncatedDistanceField(objects[j].free, {voxel, free_radius}, arg + ".free");
      r.low = objects[j].occupied.rowwise().minCoeff();
      r.high = objects[j].occupied.rowwise().maxCoeff();
      if (objects[j].turn_centre) {
        check_finite(*objects[j].turn_centre, arg + ".turn_centre");
        r.centre = *objects[j].turn_centre;
      } else {
        r.centre = objects[j].occupied.topRows<2>().rowwise().mean();
      }
      r.radius = (objects[j].occupied.topRows<2>().colwise() - r.centre).colwise().norm().maxCoeff();
      refs.push_back(std::move(r));
    }
    grid_ = placements.grid("placements");
    fitted_ = Fitted{truncation, free_radius, conflict_weight, unknown_cost, layers_of(back_depth, free_radius)};
    references_ = std::move(refs);
    fit_id_ = detail::next_fit_id();
  }

  Index objects() const override { return static_cast<Index>(references_.size()); }

  /// Number of placements searched per object (of the last fit).
  Index placement_count() const noexcept { return grid_.cols(); }

  /// Uses the settings of the last fit, whatever they are now. Throws
  /// InvalidArgument naming "distances" before a fit, EmptyInput naming
  /// "test.contact_points" / "test.free_points" for touches without them,
  /// and "test.normals" for touches without pad normals when the fit had a
  /// back_depth.
  void distances(const TouchSet& test, Eigen::Ref<Eigen::VectorXd> out) const override {
    check_fitted("distances");
    check_dimension(out.size(), objects(), "out");
    test.validate("test");
    require_taxels(test, "test", !fitted_.back_layers.empty());
    std::vector<Index> all(static_cast<std::size_t>(test.size()));
    for (Index i = 0; i < test.size(); ++i) all[static_cast<std::size_t>(i)] = i;
    std::vector<double> costs;
    for (Index j = 0; j < objects(); ++j) {
      touch_costs(test, j, costs);
      out(j) = best_sum(costs, test.size(), all);
    }
  }

  /// The cost c_i(g) of every touch of `pool` under every placement, for
  /// every object: what every test drawn from the pool sums. Throws like
  /// distances (naming "pool"; "pool.normals" as below).
  std::shared_ptr<const PreparedPool> prepare_pool(const TouchSet& pool) const override {
    check_fitted("prepare_pool");
    pool.validate("pool");
    require_taxels(pool, "pool", !fitted_.back_layers.empty());
    auto prepared = std::make_shared<Costs>(fit_id_, pool);
    prepared->costs.resize(references_.size());
    for (Index j = 0; j < objects(); ++j) touch_costs(pool, j, prepared->costs[static_cast<std::size_t>(j)]);
    return prepared;
  }

  /// Exactly the distances of `distances(select_touches(pool, subset), out)`
  /// (the same per-touch costs summed in the same order). Throws
  /// InvalidArgument naming "prepared" for a preparation of another
  /// classifier, pool or fit, and "subset" for an index outside the pool.
  void pool_distances(const TouchSet& pool, const PreparedPool* prepared, const std::vector<Index>& subset,
                      Eigen::Ref<Eigen::VectorXd> out) const override {
    if (!prepared) return Classifier::pool_distances(pool, prepared, subset, out);
    const Costs* costs = checked_preparation<Costs>(prepared, fit_id_, pool, subset);
    check_dimension(out.size(), objects(), "out");
    if (subset.empty()) throw EmptyInput("test", "holds no touch");
    for (Index j = 0; j < objects(); ++j) out(j) = best_sum(costs->costs[static_cast<std::size_t>(j)], pool.size(), subset);
  }

 private:
  /// TruncatedDistanceField::validate of a field with lattice `voxel` and
  /// reach `reach`, its errors named by this classifier's members ("voxel",
  /// and `name` for the reach) rather than the field's "settings.*".
  void check_field(double reach, const char* name) const {
    rename_argument("settings.voxel", "voxel", [&] {
      rename_argument("settings.truncation", name, [&] { TruncatedDistanceField::validate({voxel, reach}); });
    });
  }

  struct Reference {
    TruncatedDistanceField occupied, free;
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();  // the turns' vertical axis
    Eigen::Vector3d low, high;                         // the occupied points' bounding box
    double radius = 0;                                 // their largest horizontal distance from centre
  };
  struct Fitted {
    double truncation = 0, free_radius = 0, conflict_weight = 0, unknown_cost = 1;
    std::vector<double> back_layers;
  };
  struct Costs final : PreparedPool {
    Costs(std::uint64_t fit_id, const TouchSet& pool) : PreparedPool(fit_id, pool) {}
    std::vector<std::vector<double>> costs;  // per object: placements x touches, touch fastest
  };

  void check_fitted(const std::string& what) const {
    if (references_.empty()) throw InvalidArgument(what, "called before fit");
  }

  /// back_layers() of valid settings.
  static std::vector<double> layers_of(double depth, double free_radius) {
    std::vector<double> out;
    if (!(depth > 0)) return out;
    const int m = static_cast<int>(std::ceil(depth / (1.5 * free_radius) - 1e-9));
    for (int k = 1; k <= m; ++k) out.push_back(depth * k / m);
    return out;
  }

  /// Calls f(p - d n) for every taxel p of touch i of `s` (its contact
  /// points, then its free points) and every depth d of `layers`, n the
  /// touch's pad normal: the slab behind its pad.
  template <typename F>
  static void for_back_points(const TouchSet& s, Index i, const std::vector<double>& layers, F&& f) {
    if (layers.empty()) return;
    const Eigen::Vector3d n = s.normals.col(i);
    const auto u = static_cast<std::size_t>(i);
    for (const double d : layers) {
      for (Index k = s.contact_offsets[u]; k < s.contact_offsets[u + 1]; ++k) f(s.contact_points.col(k) - d * n);
      for (Index k = s.free_offsets[u]; k < s.free_offsets[u + 1]; ++k) f(s.free_points.col(k) - d * n);
    }
  }

  void require_taxels(const TouchSet& s, const std::string& argument, bool normals = false) const {
    if (!s.has_contacts())
      throw EmptyInput(argument + ".contact_points", "the " + name() +
                                                          " classifier needs the pressed taxels of every touch, placed "
                                                          "by the pad orientation (dataset columns qw, qx, qy, qz)");
    if (!s.has_free())
      throw EmptyInput(argument + ".free_points", "the " + name() +
                                                       " classifier needs the taxels that were not pressed, placed by "
                                                       "the pad orientation (dataset columns qw, qx, qy, qz)");
    if (normals && !s.has_normals())
      throw EmptyInput(argument + ".normals", "the " + name() +
                                                  " classifier with a back_depth needs the pad normal of every touch "
                                                  "(dataset columns qw, qx, qy, qz)");
  }

  /// costs[g * n + i] = c_i(g) for every touch i of `s` against object j.
  void touch_costs(const TouchSet& s, Index j, std::vector<double>& costs) const {
    const Reference& r = references_[static_cast<std::size_t>(j)];
    const Index n = s.size(), G = grid_.cols();
    costs.assign(static_cast<std::size_t>(G * n), 0.0);
    const auto cap = static_cast<float>(fitted_.truncation * fitted_.truncation);
    const auto rho2 = static_cast<float>(fitted_.free_radius * fitted_.free_radius);
    const double penalty = fitted_.conflict_weight * static_cast<double>(cap);
    const bool conflicts = fitted_.conflict_weight > 0;
    const bool unknown = fitted_.unknown_cost != 1;
    // Fields at their truncation (all eight nodes of the interpolation).
    const float far_occ = cap * (1 - 1e-5f), far_free = rho2 * (1 - 1e-5f);
    const double unknown_charge = fitted_.unknown_cost * static_cast<double>(cap);
    // Placement g: q = R (p - c) + c + t, the test point in the reference's
    // frame, as q = (cos * p.x - sin * p.y + b.x, sin * p.x + cos * p.y + b.y, p.z).
    std::vector<double> cosines(static_cast<std::size_t>(G)), sines(static_cast<std::size_t>(G));
    std::vector<Eigen::Vector2d> shifts(static_cast<std::size_t>(G));
    for (Index g = 0; g < G; ++g) {
      const auto u = static_cast<std::size_t>(g);
      const double cy = std::cos(grid_(2, g)), sy = std::sin(grid_(2, g));
      cosines[u] = cy;
      sines[u] = sy;
      shifts[u] = r.centre + grid_.col(g).head<2>() -
                  Eigen::Vector2d(cy * r.centre.x() - sy * r.centre.y(), sy * r.centre.x() + cy * r.centre.y());
    }
    // A free point (or a point of the slab behind the pad) is charged only
    // where the occupied field's nearest node is within the free radius of
    // felt surface. The nearest node is at most half a voxel away along
    // each axis (sqrt(3)/2 of one in all, sqrt(2)/2 across the table), and
    // `reach` below allows a whole voxel, which covers both with room for
    // rounding. A placement keeps heights, so a point more than `reach`
    // above or below every occupied point is never charged under any
    // placement: it is dropped once per touch, not tested under every
    // placement. Likewise across:
    // a placement turns p about the centre c by at most a and shifts it by
    // at most s, so p lands at least |p - c| - s from c, and within
    // s + 2 |p - c| sin(a / 2) of where it was. A point farther than the
    // occupied points' radius + s + that reach from c, or farther from
    // their bounding box than s + 2 |p - c| sin(a / 2) + that reach, is
    // never charged either. The charges, and the order they are summed in,
    // are the same.
    const double reach = fitted_.free_radius + r.occupied.voxel();
    const double z_min = r.low.z() - reach, z_max = r.high.z() + reach;
    double max_shift = 0, max_turn = 0;
    for (Index g = 0; g < G; ++g) {
      max_shift = std::max(max_shift, grid_.col(g).head<2>().norm());
      max_turn = std::max(max_turn, std::abs(grid_(2, g)));
    }
    const double out = r.radius + max_shift + reach, out2 = out * out;
    const double chord = 2 * std::sin(std::min(max_turn, 3.14159265358979323846) / 2);
    auto within_reach = [&](const Eigen::Vector3d& p) {
      if (p.z() < z_min || p.z() > z_max) return false;
      const Eigen::Vector2d d = p.head<2>() - r.centre;
      const double d2 = d.squaredNorm();
      if (d2 > out2) return false;
      const Eigen::Vector2d gap =
          (r.low.head<2>() - p.head<2>()).cwiseMax(p.head<2>() - r.high.head<2>()).cwiseMax(Eigen::Vector2d::Zero());
      const double m = max_shift + chord * std::sqrt(d2) + reach;
      return gap.squaredNorm() <= m * m;
    };
    std::vector<Eigen::Vector3d> near;
    for (Index i = 0; i < n; ++i) {
      const auto ui = static_cast<std::size_t>(i);
      near.clear();
      if (conflicts) {
        auto keep = [&](const Eigen::Vector3d& p) {
          if (within_reach(p)) near.push_back(p);
        };
        for (Index k = s.free_offsets[ui]; k < s.free_offsets[ui + 1]; ++k) keep(s.free_points.col(k));
        for_back_points(s, i, fitted_.back_layers, keep);
      }
      const Index c0 = s.contact_offsets[ui], c1 = s.contact_offsets[ui + 1];
      for (Index g = 0; g < G; ++g) {
        const auto ug = static_cast<std::size_t>(g);
        const double cy = cosines[ug], sy = sines[ug];
        const Eigen::Vector2d& b = shifts[ug];
        auto place = [&](const Eigen::Vector3d& p) {
          return Eigen::Vector3d(cy * p.x() - sy * p.y() + b.x(), sy * p.x() + cy * p.y() + b.y(), p.z());
        };
        double c = 0;
        for (Index k = c0; k < c1; ++k) {
          const Eigen::Vector3d q = place(s.contact_points.col(k));
          const float dn = r.occupied.squared_distance(q);
          if (!conflicts && !unknown) {
            c += static_cast<double>(dn);
            continue;
          }
          const float df = r.free.squared_distance(q);
          if (unknown && dn >= far_occ && df >= far_free) {
            c += unknown_charge;
            continue;
          }
          c += static_cast<double>(dn);
          if (conflicts && df < dn && df < rho2) c += penalty;
        }
        // The free points, five times as many as the contact points on a
        // typical touch, are tested at the nearest lattice node (one read
        // instead of eight): 1.8x faster distances, and no change of the
        // recognition rates beyond their noise (README).
        for (const Eigen::Vector3d& p : near) {
          const Eigen::Vector3d q = place(p);
          const float dn = r.occupied.node_squared_distance(q);
          if (dn < rho2 && dn < r.free.node_squared_distance(q)) c += penalty;
        }
        costs[static_cast<std::size_t>(g * n + i)] = c;
      }
    }
  }

  /// min over placements g of the sum over `subset` (in its order) of
  /// costs[g * n + i].
  double best_sum(const std::vector<double>& costs, Index n, const std::vector<Index>& subset) const {
    double best = std::numeric_limits<double>::infinity();
    for (Index g = 0; g < grid_.cols(); ++g) {
      const double* row = costs.data() + g * n;
      double e = 0;
      for (const Index i : subset) e += row[i];
      best = std::min(best, e);
    }
    return best;
  }

  std::vector<Reference> references_;
  Eigen::Matrix3Xd grid_;
  Fitted fitted_;
  std::uint64_t fit_id_ = 0;
};

}  // namespace iclap

// SPDX-License-Identifier: MIT
#pragma once

// One haptic exploration of one object: the paper's uninformed strategy
// (Section V) played by a simulated operator on a simulated Phantom Omni.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/random.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/mesh/primitives.hpp"  // detail::kPi
#include "iclap/sim/objects.hpp"
#include "iclap/sim/sensor.hpp"

namespace iclap {

/// The arm that carries the pad and reports its pose (a Phantom Omni).
struct ArmSettings {
  /// Reported positions are multiples of this, m (the Omni's nominal
  /// position resolution, about 0.055 mm; paper, Section V).
  double position_resolution = 0.055e-3;
  /// Standard deviation of the tracking error per axis, m, added before
  /// quantisation (encoder and linkage error; an assumption).
  double position_noise = 0.1e-3;
  /// Standard deviation of the reported orientation's error, rad.
  double orientation_noise = 0.3 * 3.14159265358979323846 / 180.0;

  /// Throws InvalidArgument naming the first setting that is not finite and
  /// >= 0, or a position resolution finer than 1e-12 m but not 0: positions
  /// are divided by it, and a subnormal one made every position infinite.
  void validate() const {
    check_non_negative(position_resolution, "arm.position_resolution");
    if (position_resolution > 0 && position_resolution < 1e-12)
      throw InvalidArgument("arm.position_resolution", "must be 0 (no quantisation) or at least 1e-12 m, got " +
                                                           format_value(position_resolution));
    check_non_negative(position_noise, "arm.position_noise");
    check_non_negative(orientation_noise, "arm.orientation_noise");
  }
};

/// How the simulated operator explores (README, "Simulator"). Speeds and
/// rates follow the paper (5 mm/s, 5 frames/s, pad normal to the surface,
/// five explorations per object, about 85 frames each); the jitter terms
/// describe a human hand and are assumptions, not fitted values.
struct ExplorationSettings {
  double frame_rate = 5.0;           ///< sensor frames per second (paper: 5)
  double sweep_speed = 5e-3;         ///< pad speed along the surface, m/s (paper: about 5 mm/s)
  double speed_jitter = 0.15;        ///< relative standard deviation of the speed, per frame
  double heading_jitter = 3.0 * 3.14159265358979323846 / 180.0;  ///< sweep direction wander per frame, rad
  double approach_speed = 10e-3;     ///< lowering and lifting along the pad normal, m/s
  double air_speed = 100e-3;         ///< moving to the next sweep through the air, m/s
  /// At the end of a sweep the operator turns to a new random direction and
  /// goes on sliding with this probability, or else lifts the pad and moves
  /// to a new random start point. A sweep that ran off the object always
  /// ends in a lift.
  double turn_probability = 0.75;
  /// How the operator chooses each new start point. With 1 (default) it is
  /// drawn by area over the reachable surface: the paper's uninformed
  /// strategy. With K > 1 the operator covers the object ("in this manner,
  /// the object surface was covered", the paper's Section V): of K such
  /// draws it takes the one farthest from every place the pad has touched
  /// in this exploration (best-candidate sampling). In [1, kMaxStartCandidates].
  int start_candidates = 1;
  double clearance = 3e-3;           ///< hover distance before a touch and after a lift, m
  double sweep_length_min = 30e-3;   ///< each sweep's planned length is uniform in [min, max], m
  double sweep_length_max = 80e-3;
  double force_min = 2.0;            ///< each sweep's pressing force is uniform in [min, max], N
  double force_max = 5.0;
  double force_jitter = 0.1;         ///< relative standard deviation of the force, per frame
  /// Fraction of the angle between the pad normal and the surface normal
  /// under it that the operator corrects per frame (keeps the pad normal to
  /// the surface, smoothly).
  double normal_follow = 0.5;
  /// The operator follows the surface down by at most this per frame, m;
  /// a larger drop (running off an edge) ends the sweep.
  double follow_drop = 10e-3;
  double table_clearance = 1e-3;     ///< pad corners stay this far above the table, m
  double max_frames_mean = 85;       ///< mean frames per exploration (paper: 8492 / 100)
  double frames_spread = 0.15;       ///< frames per exploration uniform in mean x (1 +- spread)
  /// The object is put down again before each exploration: a planar shift
  /// uniform in a disc of this radius (m) and a yaw uniform in +-
  /// placement_yaw (rad). Zero keeps it in place.
  double placement_shift = 10e-3;
  double placement_yaw = 10.0 * 3.14159265358979323846 / 180.0;

  /// Largest max_frames_mean (the frame count is cast to an integer; the
  /// `iclap simulate --frames` option has the same bound).
  static constexpr double kMaxFramesMean = 1e6;
  /// Largest start_candidates.
  static constexpr int kMaxStartCandidates = 64;

  /// Smallest frame_rate, frames per second: frame times and steps are
  /// divided by it, and a subnormal one made them infinite.
  static constexpr double kMinFrameRate = 1e-3;

  /// Throws InvalidArgument naming the first setting out of range; every
  /// setting must be finite.
  void validate() const {
    check_positive(frame_rate, "exploration.frame_rate");
    if (frame_rate < kMinFrameRate)
      throw InvalidArgument("exploration.frame_rate", "must be at least " + format_value(kMinFrameRate) +
                                                          " frames per second, got " + format_value(frame_rate));
    check_positive(sweep_speed, "exploration.sweep_speed");
    check_non_negative(speed_jitter, "exploration.speed_jitter");
    check_non_negative(heading_jitter, "exploration.heading_jitter");
    check_positive(approach_speed, "exploration.approach_speed");
    check_positive(air_speed, "exploration.air_speed");
    if (!(turn_probability >= 0 && turn_probability <= 1))
      throw InvalidArgument("exploration.turn_probability", "must be in [0, 1], got " + format_value(turn_probability));
    if (!(start_candidates >= 1 && start_candidates <= kMaxStartCandidates))
      throw InvalidArgument("exploration.start_candidates", "must be in [1, " + std::to_string(kMaxStartCandidates) +
                                                                "], got " + std::to_string(start_candidates));
    check_positive(clearance, "exploration.clearance");
    check_positive(sweep_length_min, "exploration.sweep_length_min");
    check_positive(sweep_length_max, "exploration.sweep_length_max");
    if (!(sweep_length_max >= sweep_length_min))
      throw InvalidArgument("exploration.sweep_length_max", "must be >= sweep_length_min, got " +
                                                                format_value(sweep_length_max));
    check_positive(force_min, "exploration.force_min");
    check_positive(force_max, "exploration.force_max");
    if (!(force_max >= force_min))
      throw InvalidArgument("exploration.force_max", "must be >= force_min, got " + format_value(force_max));
    check_non_negative(force_jitter, "exploration.force_jitter");
    if (!(normal_follow > 0 && normal_follow <= 1))
      throw InvalidArgument("exploration.normal_follow", "must be in (0, 1], got " + format_value(normal_follow));
    check_positive(follow_drop, "exploration.follow_drop");
    check_non_negative(table_clearance, "exploration.table_clearance");
    if (!(max_frames_mean >= 1 && max_frames_mean <= kMaxFramesMean))
      throw InvalidArgument("exploration.max_frames_mean",
                            "must be in [1, " + format_value(kMaxFramesMean) + "], got " + format_value(max_frames_mean));
    if (!(frames_spread >= 0 && frames_spread < 1))
      throw InvalidArgument("exploration.frames_spread", "must be in [0, 1), got " + format_value(frames_spread));
    check_non_negative(placement_shift, "exploration.placement_shift");
    check_non_negative(placement_yaw, "exploration.placement_yaw");
  }
};

namespace detail {

/// Surfaces more than this behind the pad plane are the pad's body running
/// into the object, not something the sensing face feels (m). Steps lower
/// than this the operator rides over.
inline constexpr double kMaxRise = 0.01;

/// A random unit vector orthogonal to the unit vector `n`.
inline Eigen::Vector3d random_tangent(const Eigen::Vector3d& n, Rng& rng) {
  const Eigen::Vector3d u = n.unitOrthogonal(), w = n.cross(u);
  const double a = rng.uniform(0, 2 * kPi);
  return std::cos(a) * u + std::sin(a) * w;
}

/// Lowest z of the pad outline (its four corners) at `pose`.
inline double pad_lowest_z(const PadPose& pose, const TactileSensorSettings& s) {
  const Eigen::Vector3d hx = pose.axes.col(0) * (s.pad_length / 2), hy = pose.axes.col(1) * (s.pad_width / 2);
  return pose.centre.z() - std::abs(hx.z()) - std::abs(hy.z());
}

/// Axes with the given pad x direction and pressing direction ez.
inline Eigen::Matrix3d pad_axes(const Eigen::Vector3d& ex, const Eigen::Vector3d& ez) {
  Eigen::Matrix3d a;
  const Eigen::Vector3d x = (ex - ex.dot(ez) * ez).normalized();
  a.col(0) = x;
  a.col(1) = ez.cross(x);
  a.col(2) = ez;
  return a;
}

/// One exploration, state and all: see simulate_exploration.
class Explorer {
 public:
  Explorer(const SimObject& object, const TactileSensorModel& sensor, const ArmSettings& arm,
           const ExplorationSettings& ex, Rng& rng)
      : obj_(object), sensor_(sensor), arm_(arm), ex_(ex), rng_(rng), dt_(1.0 / ex.frame_rate) {
    // Reachable surface: triangles not facing down, sampled by area.
    const TriangleMesh& m = obj_.shape.mesh();
    double total = 0;
    for (Index t = 0; t < m.triangle_count(); ++t) {
      const Eigen::Vector3d an = m.area_normal(t);
      const double a = 0.5 * an.norm();
      if (a > 0 && an.z() / (2 * a) >= -0.1) {
        total += a;
        cdf_.push_back(total);
        tris_.push_back(t);
      }
    }
    top_z_ = obj_.shape.bounds().max().z();
  }

  std::vector<Frame> run(std::int64_t exploration, std::size_t frames) {
    // Where the object was put down this time (world <- object).
    const double r = ex_.placement_shift * std::sqrt(rng_.uniform());
    const double phi = rng_.uniform(0, 2 * kPi);
    const double yaw = rng_.uniform(-1.0, 1.0) * ex_.placement_yaw;
    T_world_obj_ = Eigen::Isometry3d::Identity();
    T_world_obj_.translate(Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), 0));
    T_world_obj_.rotate(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));

    std::vector<Frame> out;
    out.reserve(frames);
    touched_.clear();
    plan_sweep();
    pose_ = hover_pose();
    // Start out of contact: rise until nothing touches.
    for (int i = 0; i < 40 && touches(pose_); ++i) pose_.centre -= 1e-3 * pose_.axes.col(2);
    mode_ = Mode::approach;
    travelled_ = 0;
    for (std::size_t k = 0; k < frames; ++k) {
      if (k > 0) step();
      else reading_ = read(pose_, 0.0);
      out.push_back(record(exploration, static_cast<std::int64_t>(k)));
    }
    return out;
  }

 private:
  enum class Mode { approach, sweep, lift, travel };

  bool touches(const PadPose& p) {
    sensor_.probe(obj_.shape, p, contact_);
    return contact_.max_depth > 0;
  }

  // Reading at `p` moved by `shift` along its z; probes first.
  Eigen::MatrixXd read(const PadPose& p, double shift) {
    sensor_.probe(obj_.shape, p, contact_);
    return sensor_.render(contact_, shift, &rng_);
  }

  // Half the pad's diagonal: how far it reaches from its centre.
  double pad_reach() const {
    const TactileSensorSettings& s = sensor_.settings();
    return 0.5 * std::hypot(s.pad_length, s.pad_width);
  }

  // How far to back away from `pose` along -z (its normal, away from the
  // object) until moving vertically from there cannot touch the object:
  // the pad is higher than the object's top by its reach, or outside the
  // object's footprint (bounds in x, y) by its reach, whichever comes first.
  double retreat_distance(const PadPose& pose) const {
    const Eigen::AlignedBox3d box = obj_.shape.bounds();
    const Eigen::Vector3d away = -pose.axes.col(2), c = pose.centre;
    const double reach = pad_reach() + 0.005;
    double d = std::numeric_limits<double>::infinity();
    if (away.z() > 1e-9) d = std::max(0.0, (box.max().z() + reach - c.z()) / away.z());
    // Leaving the footprint grown by the reach: the ray exits its rectangle.
    double exit = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 2; ++k) {
      if (std::abs(away[k]) < 1e-9) continue;
      const double bound = away[k] > 0 ? box.max()[k] + reach : box.min()[k] - reach;
      exit = std::min(exit, std::max(0.0, (bound - c[k]) / away[k]));
    }
    d = std::min(d, exit);
    if (!std::isfinite(d)) d = reach;
    return std::max(d, ex_.clearance);
  }

  // Height above which the pad can turn freely: the object's top plus the
  // pad's reach.
  double safe_height() const { return top_z_ + pad_reach() + 0.005; }

  // True if the pad can move straight up from `pose` to the safe height
  // without touching the object: vertical rays from a grid over the pad
  // (taxel pitch, plus the corners) meet nothing.
  bool vertical_clear(const PadPose& pose) const {
    const TactileSensorSettings& s = sensor_.settings();
    const double reach = safe_height() - pose.centre.z() + pad_reach();
    if (reach <= 0) return true;
    const int nx = static_cast<int>(std::ceil(s.pad_length / s.pitch)), ny = static_cast<int>(std::ceil(s.pad_width / s.pitch));
    for (int i = 0; i <= nx; ++i)
      for (int j = 0; j <= ny; ++j) {
        const double u = (static_cast<double>(i) / nx - 0.5) * s.pad_length, v = (static_cast<double>(j) / ny - 0.5) * s.pad_width;
        const Eigen::Vector3d from = pose.centre + u * pose.axes.col(0) + v * pose.axes.col(1);
        if (obj_.shape.intersect(from, Eigen::Vector3d::UnitZ(), reach)) return false;
      }
    return true;
  }

  // Chooses the next sweep: a start point on the reachable surface (top and
  // sides: triangles not facing down, by area) where the flat pad, pressed
  // along the surface normal, fits (it touches that point first, nothing
  // else of the object is in its way back along the normal) and stays above
  // the table; a random pad yaw (or the long side level, on steep faces), a
  // random direction, length and force. With start_candidates K > 1, the
  // first K such starts found compete and the one farthest from the
  // touched places of this exploration wins (the covering operator).
  void plan_sweep() {
    const TactileSensorSettings& s = sensor_.settings();
    const int wanted = ex_.start_candidates;
    int found = 0;
    double best = -1;
    for (int attempt = 0; attempt < 200 && !cdf_.empty() && found < wanted; ++attempt) {
      const double u = rng_.uniform(0, cdf_.back());
      const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
      const Index t = tris_[static_cast<std::size_t>(
          std::min<std::ptrdiff_t>(it - cdf_.begin(), static_cast<std::ptrdiff_t>(tris_.size()) - 1))];
      const TriangleMesh& m = obj_.shape.mesh();
      double a = rng_.uniform(), b = rng_.uniform();
      if (a + b > 1) {
        a = 1 - a;
        b = 1 - b;
      }
      const Eigen::Vector3d p =
          m.corner(t, 0) + a * (m.corner(t, 1) - m.corner(t, 0)) + b * (m.corner(t, 2) - m.corner(t, 0));
      const Eigen::Vector3d ez = -m.area_normal(t).normalized();
      const Eigen::Vector3d yaw = random_tangent(ez, rng_);
      const Eigen::Vector3d dir = random_tangent(ez, rng_);
      const double length = rng_.uniform(ex_.sweep_length_min, ex_.sweep_length_max);
      const double force = rng_.uniform(ex_.force_min, ex_.force_max);
      PadPose pose;
      pose.centre = p;
      pose.axes = pad_axes(yaw, ez);
      if (pad_lowest_z(pose, s) < ex_.table_clearance) {
        // Try the long side level with the table.
        const Eigen::Vector3d level = ez.cross(Eigen::Vector3d::UnitZ());
        if (level.norm() < 1e-6) continue;
        pose.axes = pad_axes(level.normalized(), ez);
        if (pad_lowest_z(pose, s) < ex_.table_clearance) continue;
      }
      // The pad touches this point first (nothing else of the object within
      // the hover clearance; also rejects points inside another shell of a
      // union), and it can get there: straight down from above, or else in
      // along the normal from outside the object.
      const double inf = std::numeric_limits<double>::infinity();
      sensor_.probe(obj_.shape, pose, contact_, ex_.clearance + kMaxRise + 0.002, 0.001, inf);
      if (!contact_.any_surface() || contact_.max_depth > 0.5e-3) continue;
      PadPose hover = pose;
      hover.centre -= ex_.clearance * pose.axes.col(2);
      bool vertical = vertical_clear(hover);
      if (!vertical) {
        sensor_.probe(obj_.shape, pose, contact_, retreat_distance(pose) + ex_.clearance, 0.001, inf);
        if (!contact_.any_surface() || contact_.max_depth > 0.5e-3) continue;
      }
      ++found;
      const double gap = distance_to_touched(p);
      if (found > 1 && !(gap > best)) continue;
      best = gap;
      arrive_vertically_ = vertical;
      start_ = pose;
      direction_ = dir;
      sweep_length_ = length;
      force_ = force;
    }
    if (found > 0) return;
    // Fallback: straight down onto the highest point.
    const TriangleMesh& m = obj_.shape.mesh();
    Index top = 0;
    m.vertices.row(2).maxCoeff(&top);
    start_.centre = m.vertices.col(top);
    start_.axes = pad_axes(Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitZ());
    arrive_vertically_ = true;
    direction_ = Eigen::Vector3d::UnitX();
    sweep_length_ = ex_.sweep_length_min;
    force_ = ex_.force_min;
  }

  // Distance from `p` (object frame) to the nearest pad centre of a touch
  // so far in this exploration; infinite before the first touch. Only the
  // covering operator (start_candidates > 1) keeps those centres.
  double distance_to_touched(const Eigen::Vector3d& p) const {
    double d2 = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& q : touched_) d2 = std::min(d2, (q - p).squaredNorm());
    return std::sqrt(d2);
  }

  // At the end of a sweep (planned length reached, or blocked by a part too
  // high to ride over, the table, a surface facing down) the operator turns
  // to a new random direction and goes on sliding with probability
  // turn_probability, or else lifts the pad and moves to a new start point.
  void end_sweep() {
    if (rng_.uniform() < ex_.turn_probability) turn();
    else start_lift();
  }

  // A new sweep from where the pad is, without lifting it: a new random
  // direction in the surface, length and force.
  void turn() {
    direction_ = random_tangent(pose_.axes.col(2), rng_);
    sweep_length_ = rng_.uniform(ex_.sweep_length_min, ex_.sweep_length_max);
    force_ = rng_.uniform(ex_.force_min, ex_.force_max);
    travelled_ = 0;
  }

  PadPose hover_pose() const {
    PadPose p = start_;
    p.centre -= ex_.clearance * p.axes.col(2);
    return p;
  }

  // Moving to the next sweep through the air, never through the object:
  // straight up if that is free, else first back away along the pad normal
  // until clear of the object; across above the object while turning the
  // pad to its new orientation; down, and in along the new normal if the
  // hover pose cannot be reached from straight above.
  void start_travel() {
    plan_sweep();
    const PadPose goal = hover_pose();
    const Eigen::Vector3d out_from =
        vertical_clear(pose_) ? pose_.centre : Eigen::Vector3d(pose_.centre - retreat_distance(pose_) * pose_.axes.col(2));
    const Eigen::Vector3d out_to =
        arrive_vertically_ ? goal.centre : Eigen::Vector3d(goal.centre - retreat_distance(goal) * goal.axes.col(2));
    const double safe = std::max({safe_height(), out_from.z(), out_to.z()});
    path_ = {pose_.centre,
             out_from,
             Eigen::Vector3d(out_from.x(), out_from.y(), safe),
             Eigen::Vector3d(out_to.x(), out_to.y(), safe),
             out_to,
             goal.centre};
    path_length_ = 0;
    for (std::size_t i = 1; i < path_.size(); ++i) path_length_ += (path_[i] - path_[i - 1]).norm();
    q_from_ = Eigen::Quaterniond(pose_.axes);
    q_to_ = Eigen::Quaterniond(goal.axes);
    travelled_ = 0;
    mode_ = Mode::travel;
  }

  Eigen::Vector3d along_path(double s) const {
    for (std::size_t i = 1; i < path_.size(); ++i) {
      const double len = (path_[i] - path_[i - 1]).norm();
      if (s <= len && len > 0) return path_[i - 1] + (s / len) * (path_[i] - path_[i - 1]);
      s -= len;
    }
    return path_.back();
  }

  void start_lift() {
    mode_ = Mode::lift;
    travelled_ = 0;
  }

  // Rotates the pad about its centre so its z turns towards `target_z` by
  // the follow fraction (minimal rotation: the pad does not spin).
  void follow_normal(const Eigen::Vector3d& target_z) {
    const Eigen::Vector3d ez = pose_.axes.col(2);
    Eigen::Vector3d goal = ez + ex_.normal_follow * (target_z - ez);
    if (goal.norm() < 1e-9) return;
    goal.normalize();
    const Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(ez, goal).toRotationMatrix();
    pose_.axes = R * pose_.axes;
    direction_ = R * direction_;
  }

  // Advances one frame period and takes the reading.
  void step() {
    const double dt = dt_;
    const TactileSensorSettings& s = sensor_.settings();
    switch (mode_) {
      case Mode::approach: {
        const double d = ex_.approach_speed * dt;
        pose_.centre += d * pose_.axes.col(2);
        travelled_ += d;
        sensor_.probe(obj_.shape, pose_, contact_);
        const double target = force_ * jitter(ex_.force_jitter);
        double shift = 0;
        if (contact_.any_surface() && sensor_.force(contact_, 0.0) >= target) {
          // Touched: the operator settles at the intended force.
          shift = sensor_.balance(contact_, target);
          pose_.centre += shift * pose_.axes.col(2);
          last_normal_ = sensor_.contact_normal(contact_, shift);
          mode_ = Mode::sweep;
          travelled_ = 0;
        } else if (travelled_ > ex_.clearance + 0.02) {
          start_lift();  // nothing there after all
        }
        reading_ = sensor_.render(contact_, shift, &rng_);
        return;
      }
      case Mode::sweep: {
        const PadPose before = pose_;
        const Eigen::Vector3d before_dir = direction_;
        if (last_normal_.squaredNorm() > 0) follow_normal(-last_normal_);
        // Wander the heading, then move along the surface.
        const Eigen::Vector3d ez = pose_.axes.col(2);
        direction_ = Eigen::AngleAxisd(ex_.heading_jitter * rng_.normal(), ez) * direction_;
        direction_ = (direction_ - direction_.dot(ez) * ez).normalized();
        const double d = std::max(0.0, ex_.sweep_speed * dt * jitter(ex_.speed_jitter));
        pose_.centre += d * direction_;
        travelled_ += d;
        sensor_.probe(obj_.shape, pose_, contact_);
        const double target = force_ * jitter(ex_.force_jitter);
        if (contact_.blocked > 0) {
          // Ran into a part higher than the pad can ride over: stop here.
          pose_ = before;
          direction_ = before_dir;
          reading_ = read(pose_, 0.0);
          end_sweep();
          return;
        }
        if (!contact_.any_surface() || contact_.max_depth < -ex_.follow_drop) {
          reading_ = sensor_.render(contact_, 0.0, &rng_);  // ran off: nothing under the pad
          start_lift();
          return;
        }
        const double shift = sensor_.balance(contact_, target);
        PadPose pressed = pose_;
        pressed.centre += shift * pose_.axes.col(2);
        if (pad_lowest_z(pressed, s) < ex_.table_clearance || pressed.axes(2, 2) > 0.3) {
          // The pad would hit the table or press upwards: stop here.
          pose_ = before;
          direction_ = before_dir;
          reading_ = read(pose_, 0.0);
          end_sweep();
          return;
        }
        pose_ = pressed;
        if (ex_.start_candidates > 1) touched_.push_back(pose_.centre);
        reading_ = sensor_.render(contact_, shift, &rng_);
        last_normal_ = sensor_.contact_normal(contact_, shift);
        if (travelled_ >= sweep_length_) end_sweep();
        return;
      }
      case Mode::lift: {
        const double d = ex_.approach_speed * dt;
        pose_.centre -= d * pose_.axes.col(2);
        travelled_ += d;
        reading_ = read(pose_, 0.0);
        if (travelled_ >= ex_.clearance) start_travel();
        return;
      }
      case Mode::travel: {
        travelled_ = std::min(path_length_, travelled_ + ex_.air_speed * dt);
        // Turn only on the leg across, high above the object.
        const double before = (path_[1] - path_[0]).norm() + (path_[2] - path_[1]).norm();
        const double across = (path_[3] - path_[2]).norm();
        const double f = across > 0 ? std::clamp((travelled_ - before) / across, 0.0, 1.0)
                                    : (travelled_ > before ? 1.0 : 0.0);
        pose_.centre = along_path(travelled_);
        pose_.axes = q_from_.slerp(f, q_to_).toRotationMatrix();
        reading_ = read(pose_, 0.0);
        if (travelled_ >= path_length_) {
          pose_ = hover_pose();
          mode_ = Mode::approach;
          travelled_ = 0;
        }
        return;
      }
    }
  }

  // Every random draw happens whatever the settings, so that switching one
  // effect off does not change the others.
  double jitter(double rel) { return std::max(0.0, 1.0 + rel * rng_.normal()); }

  Frame record(std::int64_t exploration, std::int64_t k) {
    Frame f;
    f.object = obj_.name;
    f.exploration = exploration;
    f.frame = k;
    f.time = static_cast<double>(k) / ex_.frame_rate;
    Eigen::Vector3d p = T_world_obj_ * pose_.centre;
    for (int i = 0; i < 3; ++i) {
      p[i] += arm_.position_noise * rng_.normal();
      if (arm_.position_resolution > 0)
        p[i] = std::round(p[i] / arm_.position_resolution) * arm_.position_resolution;
    }
    f.position = p;
    Eigen::Quaterniond q(T_world_obj_.linear() * pose_.axes);
    const Eigen::Vector3d axis(rng_.normal(), rng_.normal(), rng_.normal());
    const double angle = arm_.orientation_noise * rng_.normal();
    if (axis.norm() > 0 && angle != 0) q = Eigen::AngleAxisd(angle, axis.normalized()) * q;
    q.normalize();
    if (q.w() < 0) q.coeffs() *= -1;
    f.orientation = q;
    f.pressures = reading_;
    return f;
  }

  const SimObject& obj_;
  const TactileSensorModel& sensor_;
  const ArmSettings& arm_;
  const ExplorationSettings& ex_;
  Rng& rng_;
  double dt_;
  std::vector<double> cdf_;
  std::vector<Index> tris_;
  double top_z_ = 0;
  Eigen::Isometry3d T_world_obj_ = Eigen::Isometry3d::Identity();

  Mode mode_ = Mode::approach;
  PadPose pose_, start_;
  Eigen::Vector3d direction_ = Eigen::Vector3d::UnitX();
  Eigen::Vector3d last_normal_ = Eigen::Vector3d::Zero();
  double sweep_length_ = 0, force_ = 0, travelled_ = 0;
  bool arrive_vertically_ = true;
  std::vector<Eigen::Vector3d> path_;
  double path_length_ = 0;
  Eigen::Quaterniond q_from_, q_to_;
  PadContact contact_;
  Eigen::MatrixXd reading_;
  std::vector<Eigen::Vector3d> touched_;  // pad centres of the sweep frames (covering operator only)
};

}  // namespace detail

}  // namespace iclap

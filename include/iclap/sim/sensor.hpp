// SPDX-License-Identifier: MIT
#pragma once

// Model of the tactile array: a rigid pad with a foam cover pressed onto a
// rigid object. Geometry -> penetration height field -> foam pressure ->
// lateral spread -> taxel average -> 12-bit reading with noise, dead band
// and saturation.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/random.hpp"
#include "iclap/core/types.hpp"
#include "iclap/mesh/bvh.hpp"

namespace iclap {

/// Physical parameters of the simulated tactile array. Defaults describe a
/// Weiss WTS 0614-34A (14 x 6 taxels, 3.4 mm pitch, 51 x 24 mm pad, 12-bit
/// readings; from its datasheet and the paper, Section V). The foam and
/// pressure-scale values are not published: they are plausible values for a
/// few millimetres of rubber foam, stated here so they can be changed, and
/// they were not tuned to any recognition result.
struct TactileSensorSettings {
  Index rows = 14;               ///< taxels along the pad's long side (pad x axis)
  Index cols = 6;                ///< taxels along the short side (pad y axis)
  double pitch = 3.4e-3;         ///< taxel pitch, m
  double pad_length = 51e-3;     ///< rigid pad along x, m (>= rows * pitch)
  double pad_width = 24e-3;      ///< rigid pad along y, m (>= cols * pitch)
  /// Height-field samples per taxel side (3 -> 1.13 mm spacing): features
  /// narrower than a taxel still press the foam.
  int samples_per_taxel = 3;
  double foam_thickness = 3e-3;  ///< uncompressed foam cover, m
  /// Compressive modulus of the foam, Pa. Pressure at compression x of a
  /// foam of thickness h: E x / (h - x) (linear for small strain, stiffening
  /// without bound as the foam bottoms out).
  double foam_modulus = 0.3e6;
  /// Standard deviation of the foam's lateral spreading of pressure, m
  /// (about half the foam thickness).
  double spread_sigma = 1.2e-3;
  double full_scale_pressure = 250e3;  ///< pressure read as `max_raw`, Pa
  double max_raw = 4095;               ///< 12-bit saturation
  double noise_sigma = 2.0;            ///< read noise per taxel, raw units
  /// Readings at or below this (raw units, after noise) are reported as 0,
  /// like the sensor's configurable threshold.
  double dead_band = 8.0;

  /// Largest extent, in height-field samples (pitch / samples_per_taxel),
  /// of the pad along either side and of the spread's sigma: the model sizes
  /// integer grids and kernels from them.
  static constexpr double kMaxSamples = 1e4;

  /// Throws InvalidArgument naming the first setting out of range; every
  /// setting must be finite.
  void validate() const {
    if (rows < 1 || cols < 1) throw InvalidArgument("sensor.rows/cols", "must be >= 1");
    check_positive(pitch, "sensor.pitch");
    if (samples_per_taxel < 1 || samples_per_taxel > 16)
      throw InvalidArgument("sensor.samples_per_taxel", "must be in [1, 16]");
    check_positive(pad_length, "sensor.pad_length");
    check_positive(pad_width, "sensor.pad_width");
    if (pad_length < static_cast<double>(rows) * pitch - 1e-12)
      throw InvalidArgument("sensor.pad_length", "is shorter than rows * pitch");
    if (pad_width < static_cast<double>(cols) * pitch - 1e-12)
      throw InvalidArgument("sensor.pad_width", "is narrower than cols * pitch");
    const double sample = pitch / samples_per_taxel;
    auto in_samples = [&](double v, const char* name) {
      if (!(v / sample <= kMaxSamples))
        throw InvalidArgument(name, format_value(v) + " m spans " + format_value(v / sample) +
                                        " height-field samples (pitch / samples_per_taxel each), more than " +
                                        format_value(kMaxSamples));
    };
    in_samples(pad_length, "sensor.pad_length");
    in_samples(pad_width, "sensor.pad_width");
    check_positive(foam_thickness, "sensor.foam_thickness");
    check_positive(foam_modulus, "sensor.foam_modulus");
    check_non_negative(spread_sigma, "sensor.spread_sigma");
    in_samples(spread_sigma, "sensor.spread_sigma");
    check_positive(full_scale_pressure, "sensor.full_scale_pressure");
    check_positive(max_raw, "sensor.max_raw");
    check_non_negative(noise_sigma, "sensor.noise_sigma");
    check_non_negative(dead_band, "sensor.dead_band");
  }
};

/// Pose of the pad: `centre` is the centre of its sensing surface (what the
/// arm reports), `axes` columns are the pad's x (rows, long side), y
/// (columns) and z = x cross y, the pressing direction: the outward normal
/// of the sensing surface, pointing into the object. Taxel (r, c) sits at
/// centre + ((r - (rows-1)/2) x + (c - (cols-1)/2) y) * pitch.
struct PadPose {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
};

/// What the object looks like from the pad at one pose: for each sample
/// point of the pad surface, how far the object surface reaches past the
/// pad plane along z ("depth", m; negative = a gap; -inf = no surface in
/// reach) and the outward normal there.
struct PadContact {
  std::vector<double> depth;
  std::vector<Eigen::Vector3d> normal;
  double max_depth = -std::numeric_limits<double>::infinity();
  /// Samples whose surface lies further behind the pad plane than the probe's
  /// `max_rise`: not felt (depth -inf), but the pad's body is inside the
  /// object there. A planner must not go on like that.
  Index blocked = 0;
  bool any_surface() const { return std::isfinite(max_depth); }
};

/// The sensor model. Immutable after construction; const members are
/// thread-safe (each thread passes its own Rng and buffers).
class TactileSensorModel {
 public:
  explicit TactileSensorModel(const TactileSensorSettings& s = {}) : s_(s) {
    s_.validate();
    sub_ = s_.pitch / s_.samples_per_taxel;
    // Rim samples beyond the taxel area, up to the pad outline.
    rim_x_ = static_cast<Index>(std::lround((s_.pad_length - static_cast<double>(s_.rows) * s_.pitch) / 2 / sub_));
    rim_y_ = static_cast<Index>(std::lround((s_.pad_width - static_cast<double>(s_.cols) * s_.pitch) / 2 / sub_));
    nx_ = s_.rows * s_.samples_per_taxel + 2 * rim_x_;
    ny_ = s_.cols * s_.samples_per_taxel + 2 * rim_y_;
    // Separable Gaussian kernel (in samples) and its normaliser over the pad.
    // A spread whose square underflows (spread_sigma below about 1e-160
    // samples) spreads nothing, as 0: its centre weight was 0 / 0, NaN, and
    // so was every reading.
    const double sig = s_.spread_sigma / sub_;
    const bool spreads = sig * sig > 0;
    const Index radius = spreads ? static_cast<Index>(std::ceil(3 * sig)) : 0;
    kernel_.resize(static_cast<std::size_t>(2 * radius + 1));
    for (Index k = -radius; k <= radius; ++k)
      kernel_[static_cast<std::size_t>(k + radius)] =
          spreads ? std::exp(-0.5 * static_cast<double>(k * k) / (sig * sig)) : 1.0;
    std::vector<double> ones(static_cast<std::size_t>(nx_ * ny_), 1.0);
    norm_ = blur_raw(ones);
  }

  const TactileSensorSettings& settings() const noexcept { return s_; }
  /// Number of height-field samples (nx * ny): the rays cast per probe.
  Index sample_count() const noexcept { return nx_ * ny_; }
  /// Area of one sample, m^2.
  double sample_area() const noexcept { return sub_ * sub_; }

  /// Offset of sample (i, j) from the pad centre in pad x, y, m.
  Eigen::Vector2d sample_offset(Index i, Index j) const {
    return {(static_cast<double>(i) + 0.5) * sub_ - static_cast<double>(nx_) * sub_ / 2,
            (static_cast<double>(j) + 0.5) * sub_ - static_cast<double>(ny_) * sub_ / 2};
  }

  /// Casts one ray per sample along the pad's z from `behind` metres behind
  /// the pad plane, reaching `ahead` metres past it; fills `out`. Only front
  /// faces count (rays start outside the object). A surface found more than
  /// `max_rise` behind the pad plane is not in front of the sensing face but
  /// behind it: it is not felt and counts as `blocked`.
  void probe(const MeshBvh& shape, const PadPose& pose, PadContact& out, double behind = 0.03,
             double ahead = 0.015, double max_rise = 0.01) const {
    const std::size_t n = static_cast<std::size_t>(sample_count());
    out.depth.assign(n, -std::numeric_limits<double>::infinity());
    out.normal.assign(n, Eigen::Vector3d::Zero());
    out.max_depth = -std::numeric_limits<double>::infinity();
    out.blocked = 0;
    const Eigen::Vector3d ex = pose.axes.col(0), ey = pose.axes.col(1), ez = pose.axes.col(2);
    for (Index i = 0; i < nx_; ++i)
      for (Index j = 0; j < ny_; ++j) {
        const Eigen::Vector2d o = sample_offset(i, j);
        const Eigen::Vector3d origin = pose.centre + o.x() * ex + o.y() * ey - behind * ez;
        const auto hit = shape.intersect(origin, ez, behind + ahead, RaySide::front);
        if (!hit) continue;
        const std::size_t k = static_cast<std::size_t>(i * ny_ + j);
        if (behind - hit->t > max_rise) {
          ++out.blocked;
          continue;
        }
        out.depth[k] = behind - hit->t;
        out.normal[k] = hit->normal;
        out.max_depth = std::max(out.max_depth, out.depth[k]);
      }
  }

  /// Foam pressure (Pa) at compression `x` (m).
  double foam_pressure(double x) const {
    if (!(x > 0)) return 0;
    const double h = s_.foam_thickness;
    if (x >= h) return std::numeric_limits<double>::infinity();
    return s_.foam_modulus * x / (h - x);
  }

  /// Total normal force (N) when the pad is moved `shift` metres further
  /// along its z from the probed pose.
  double force(const PadContact& c, double shift) const {
    double f = 0;
    for (double d : c.depth) f += foam_pressure(d + shift);
    return f * sample_area();
  }

  /// The shift along pad z (m) at which the contact force is `target` (N),
  /// found by bisection (force grows monotonically with the shift). NaN if
  /// no surface is in reach.
  double balance(const PadContact& c, double target) const {
    if (!c.any_surface()) return std::numeric_limits<double>::quiet_NaN();
    // Only samples within a foam thickness of the deepest one can touch
    // before the deepest one bottoms out.
    thread_local std::vector<double> near;
    near.clear();
    for (double d : c.depth)
      if (d > c.max_depth - s_.foam_thickness) near.push_back(d);
    double lo = -c.max_depth, hi = s_.foam_thickness - c.max_depth;
    for (int it = 0; it < 64; ++it) {
      const double mid = 0.5 * (lo + hi);
      double f = 0;
      for (double d : near) f += foam_pressure(d + mid);
      if (f * sample_area() < target) lo = mid;
      else hi = mid;
    }
    return 0.5 * (lo + hi);
  }

  /// Unit normal of the surface under the pad: the pressure-weighted mean
  /// of the contact normals at `shift`; zero if nothing touches.
  Eigen::Vector3d contact_normal(const PadContact& c, double shift) const {
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < c.depth.size(); ++k) {
      const double p = foam_pressure(c.depth[k] + shift);
      if (p > 0) n += std::min(p, 1e9) * c.normal[k];
    }
    const double len = n.norm();
    return len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
  }

  /// The reading at `shift` (rows x cols, raw units): foam pressure per
  /// sample, spread by the Gaussian (normalised over the pad, so a uniform
  /// load stays uniform up to the pad's edges), averaged over each taxel,
  /// scaled to raw units; then, if `noise` is given, read noise; then the
  /// dead band, rounding to integers and saturation at max_raw.
  Eigen::MatrixXd render(const PadContact& c, double shift, Rng* noise) const {
    std::vector<double> p(c.depth.size());
    for (std::size_t k = 0; k < p.size(); ++k) p[k] = std::min(foam_pressure(c.depth[k] + shift), 1e12);
    const std::vector<double> b = blur_raw(p);
    const int spt = s_.samples_per_taxel;
    const double scale = s_.max_raw / s_.full_scale_pressure / (spt * spt);
    Eigen::MatrixXd out(s_.rows, s_.cols);
    for (Index r = 0; r < s_.rows; ++r)
      for (Index col = 0; col < s_.cols; ++col) {
        double sum = 0;
        for (int a = 0; a < spt; ++a)
          for (int bb = 0; bb < spt; ++bb) {
            const std::size_t k = static_cast<std::size_t>((rim_x_ + r * spt + a) * ny_ + rim_y_ + col * spt + bb);
            sum += b[k] / norm_[k];
          }
        double v = sum * scale;
        if (noise) v += s_.noise_sigma * noise->normal();  // drawn even at sigma 0: same stream
        v = v <= s_.dead_band ? 0.0 : std::min(std::round(v), s_.max_raw);
        out(r, col) = v;
      }
    return out;
  }

 private:
  std::vector<double> blur_raw(const std::vector<double>& in) const {
    const Index radius = static_cast<Index>(kernel_.size() / 2);
    std::vector<double> tmp(in.size(), 0.0), out(in.size(), 0.0);
    for (Index i = 0; i < nx_; ++i)
      for (Index j = 0; j < ny_; ++j) {
        double s = 0;
        for (Index k = -radius; k <= radius; ++k) {
          const Index jj = j + k;
          if (jj < 0 || jj >= ny_) continue;
          s += kernel_[static_cast<std::size_t>(k + radius)] * in[static_cast<std::size_t>(i * ny_ + jj)];
        }
        tmp[static_cast<std::size_t>(i * ny_ + j)] = s;
      }
    for (Index i = 0; i < nx_; ++i)
      for (Index j = 0; j < ny_; ++j) {
        double s = 0;
        for (Index k = -radius; k <= radius; ++k) {
          const Index ii = i + k;
          if (ii < 0 || ii >= nx_) continue;
          s += kernel_[static_cast<std::size_t>(k + radius)] * tmp[static_cast<std::size_t>(ii * ny_ + j)];
        }
        out[static_cast<std::size_t>(i * ny_ + j)] = s;
      }
    return out;
  }

  TactileSensorSettings s_;
  double sub_ = 0;
  Index rim_x_ = 0, rim_y_ = 0, nx_ = 0, ny_ = 0;
  std::vector<double> kernel_;
  std::vector<double> norm_;
};

}  // namespace iclap

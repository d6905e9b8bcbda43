// SPDX-License-Identifier: MIT
#pragma once

// A truncated distance field over a 3-D point set: constant-time "how far
// is the closest point, up to a cut-off" for queries near the points.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/point_cloud.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"

namespace iclap {

/// Settings of a TruncatedDistanceField.
struct DistanceFieldSettings {
  /// Lattice spacing, metres; > 0.
  double voxel = 1e-3;
  /// Largest distance represented, metres; > 0 and at most
  /// TruncatedDistanceField::kMaxTruncationVoxels voxels (each point writes
  /// a cube of (2 truncation / voxel + 1)^3 nodes).
  double truncation = 3e-3;
};

/// The squared distance from a query to the closest of a set of 3-D points,
/// truncated at `truncation`^2: sampled exactly at the nodes of a lattice
/// of spacing `voxel` (node (i, j, k) at voxel * (i, j, k)) and interpolated
/// trilinearly between them, truncation^2 wherever no point is within reach.
///
/// Where a kd-tree answers one nearest-neighbour query in O(log n), the field
/// answers in O(1) with eight memory reads, which pays when the same points
/// are queried millions of times (OccupancyClassifier scores every touch of a
/// test under every placement of a grid). The price is memory and an error:
/// between nodes the interpolant of a single point's |x - p|^2 exceeds it by
/// up to 3/4 voxel^2 (0.75 mm^2 at 1 mm voxels), and the field is only as
/// fine as its lattice.
///
/// Storage is sparse: blocks of 8 x 8 x 8 nodes are allocated only within
/// `truncation` of a point, so memory follows the area the points cover
/// (about 64 bytes per square millimetre of a surface sampled at 1 mm voxels
/// and a 3 mm truncation), not the volume of their bounding box; a dense
/// index of blocks covers that box (4 bytes per 8^3 voxels).
///
/// Build O(n (truncation / voxel)^3); immutable afterwards, so const queries
/// are thread-safe. Default-constructed: no point, truncation^2 = 0
/// everywhere.
class TruncatedDistanceField {
 public:
  using Settings = DistanceFieldSettings;

  /// Largest truncation in voxels.
  static constexpr double kMaxTruncationVoxels = 64;
  /// Largest coordinate magnitude in voxels (lattice indices stay far inside
  /// 32-bit integers).
  static constexpr double kMaxCoordinateVoxels = 1e8;
  /// Largest block index (entries of 4 bytes over the points' bounding box
  /// in blocks of 8^3 voxels): 2^26, 256 MiB, a box of 3.2 m at 1 mm voxels.
  static constexpr double kMaxIndexBlocks = 67108864.0;

  TruncatedDistanceField() = default;

  /// Samples the field of `points` (one per column; none is allowed: the
  /// field is then truncation^2 everywhere). Throws InvalidArgument naming
  /// "settings.voxel" or "settings.truncation" for a value out of range,
  /// NonFiniteValue naming `argument` for a NaN or infinite coordinate, and
  /// InvalidArgument naming `argument` for a coordinate beyond
  /// kMaxCoordinateVoxels voxels (e.g. millimetres given as metres with a
  /// 1 mm voxel: 1e5 m) or for points spread over more than
  /// kMaxIndexBlocks blocks (a larger voxel, or fewer objects per field).
  /// DimensionMismatch naming `argument` unless the points have 3 rows.
  template <typename Derived>
  explicit TruncatedDistanceField(const Eigen::MatrixBase<Derived>& points, const Settings& settings = {},
                                  const std::string& argument = "points") {
    // Checked before the conversion to 3 x n, which asserts (debug) or
    // reads the wrong rows (release).
    check_dimension(points.rows(), 3, argument);
    build(points, settings, argument);
  }

  /// A cloud of your own type (a PointCloudTraits specialisation of
  /// dimension 3, see iclap/core/point_cloud.hpp), read once as
  /// `to_cloud<double, 3>` reads it: the field of a matrix of the same
  /// values. Throws what to_cloud throws, naming `argument`, then as the
  /// matrix constructor.
  template <typename C, typename = std::enable_if_t<is_point_cloud_v<C>>>
  explicit TruncatedDistanceField(const C& points, const Settings& settings = {}, const std::string& argument = "points")
      : TruncatedDistanceField(to_cloud<double, 3>(points, argument), settings, argument) {}

  /// Throws InvalidArgument naming the first setting out of range.
  static void validate(const Settings& s) {
    if (!(std::isfinite(s.voxel) && s.voxel > 0))
      throw InvalidArgument("settings.voxel", "must be finite and > 0, got " + format_value(s.voxel));
    if (!(std::isfinite(s.truncation) && s.truncation > 0 && s.truncation <= kMaxTruncationVoxels * s.voxel))
      throw InvalidArgument("settings.truncation", "must be > 0 and at most " + format_value(kMaxTruncationVoxels) +
                                                       " voxels (" + format_value(kMaxTruncationVoxels * s.voxel) +
                                                       " m), got " + format_value(s.truncation));
    // The field stores squared distances in float: a truncation whose square
    // is 0 or subnormal there (below 1.1e-19 m) made every query read 0, as
    // if it touched a point; one whose square overflows (above 1.8e19 m)
    // made the far value inf.
    const double cap = static_cast<double>(static_cast<float>(s.truncation * s.truncation));
    if (!(cap >= static_cast<double>(std::numeric_limits<float>::min()) &&
          cap <= static_cast<double>(std::numeric_limits<float>::max())))
      throw InvalidArgument("settings.truncation",
                            "must square to a normal finite float (about 1.1e-19 to 1.8e19 m), got " +
                                format_value(s.truncation));
  }

  double voxel() const noexcept { return voxel_; }
  double truncation() const noexcept { return truncation_; }
  /// truncation^2 as stored: the value far from every point.
  float cap() const noexcept { return cap_; }
  /// Bytes held by the blocks and their index.
  std::size_t memory_bytes() const noexcept { return blocks_.size() * sizeof(float) + index_.size() * sizeof(std::int32_t); }

  /// The value at the lattice node closest to `p` (no interpolation: one
  /// memory read, for threshold tests that need no smooth value); cap()
  /// beyond the points' reach, including NaN.
  float node_squared_distance(const Eigen::Vector3d& p) const {
    if (index_.empty()) return cap_;
    const double inv = 1.0 / voxel_;
    const double gx = std::round(p.x() * inv), gy = std::round(p.y() * inv), gz = std::round(p.z() * inv);
    const double lx = static_cast<double>(block_lo_.x()) * kBlock, ly = static_cast<double>(block_lo_.y()) * kBlock,
                 lz = static_cast<double>(block_lo_.z()) * kBlock;
    if (!(gx >= lx && gy >= ly && gz >= lz && gx < lx + block_n_.x() * kBlock && gy < ly + block_n_.y() * kBlock &&
          gz < lz + block_n_.z() * kBlock))
      return cap_;
    return node_value(static_cast<int>(gx), static_cast<int>(gy), static_cast<int>(gz));
  }

  /// The interpolated truncated squared distance at `p` (metres); cap() for
  /// a query beyond the points' reach, including NaN.
  float squared_distance(const Eigen::Vector3d& p) const {
    if (index_.empty()) return cap_;
    const double inv = 1.0 / voxel_;
    const double gx = p.x() * inv, gy = p.y() * inv, gz = p.z() * inv;
    // Nodes outside the indexed blocks hold cap(); a query outside them by
    // a node or more (or NaN) needs no lookup.
    const double lx = static_cast<double>(block_lo_.x()) * kBlock, ly = static_cast<double>(block_lo_.y()) * kBlock,
                 lz = static_cast<double>(block_lo_.z()) * kBlock;
    if (!(gx >= lx - 1 && gy >= ly - 1 && gz >= lz - 1 && gx < lx + block_n_.x() * kBlock &&
          gy < ly + block_n_.y() * kBlock && gz < lz + block_n_.z() * kBlock))
      return cap_;
    const double fx0 = std::floor(gx), fy0 = std::floor(gy), fz0 = std::floor(gz);
    const int i = static_cast<int>(fx0), j = static_cast<int>(fy0), k = static_cast<int>(fz0);
    const float fx = static_cast<float>(gx - fx0), fy = static_cast<float>(gy - fy0), fz = static_cast<float>(gz - fz0);
    float c[8];
    if ((i & (kBlock - 1)) != kBlock - 1 && (j & (kBlock - 1)) != kBlock - 1 && (k & (kBlock - 1)) != kBlock - 1) {
      // The cell's eight nodes share one block: one index lookup.
      const std::int32_t b = block_of(floor_div(i, kBlock), floor_div(j, kBlock), floor_div(k, kBlock));
      if (b < 0) return cap_;
      const float* v = &blocks_[static_cast<std::size_t>(b) * kBlockNodes];
      const int o = offset(i, j, k);
      c[0] = v[o];
      c[1] = v[o + 1];
      c[2] = v[o + kBlock];
      c[3] = v[o + kBlock + 1];
      c[4] = v[o + kBlock * kBlock];
      c[5] = v[o + kBlock * kBlock + 1];
      c[6] = v[o + kBlock * kBlock + kBlock];
      c[7] = v[o + kBlock * kBlock + kBlock + 1];
    } else {
      for (int n = 0; n < 8; ++n) c[n] = node_value(i + (n & 1), j + ((n >> 1) & 1), k + ((n >> 2) & 1));
    }
    const float x00 = c[0] + fx * (c[1] - c[0]), x10 = c[2] + fx * (c[3] - c[2]);
    const float x01 = c[4] + fx * (c[5] - c[4]), x11 = c[6] + fx * (c[7] - c[6]);
    const float y0 = x00 + fy * (x10 - x00), y1 = x01 + fy * (x11 - x01);
    return std::min(cap_, y0 + fz * (y1 - y0));
  }

 private:
  /// The constructor's work on 3 x n points.
  void build(const Eigen::Ref<const Eigen::Matrix3Xd>& points, const Settings& settings, const std::string& argument) {
    validate(settings);
    check_finite(points, argument);
    voxel_ = settings.voxel;
    truncation_ = settings.truncation;
    cap_ = static_cast<float>(truncation_ * truncation_);
    const double limit = kMaxCoordinateVoxels * voxel_;
    for (Index c = 0; c < points.cols(); ++c)
      for (Index r = 0; r < 3; ++r)
        if (!(std::abs(points(r, c)) <= limit))
          throw InvalidArgument(argument, "point " + std::to_string(c) + " has coordinate " + format_value(points(r, c)) +
                                              " m, beyond the field's range (|v| <= " + format_value(limit) +
                                              " m at a voxel of " + format_value(voxel_) + " m); check the unit");
    if (points.cols() == 0) return;
    const int reach = static_cast<int>(std::ceil(truncation_ / voxel_));
    // The dense block index covers every node a point can write.
    Eigen::Array3i lo = Eigen::Array3i::Constant(std::numeric_limits<int>::max());
    Eigen::Array3i hi = Eigen::Array3i::Constant(std::numeric_limits<int>::min());
    for (Index c = 0; c < points.cols(); ++c)
      for (int a = 0; a < 3; ++a) {
        const int n = static_cast<int>(std::floor(points(a, c) / voxel_));
        lo(a) = std::min(lo(a), floor_div(n - reach, kBlock));
        hi(a) = std::max(hi(a), floor_div(n + 1 + reach, kBlock));
      }
    const Eigen::Array3d extent = (hi - lo + 1).cast<double>();
    if (!(extent.prod() <= kMaxIndexBlocks))
      throw InvalidArgument(argument, "the points span " + format_value(extent.x() * kBlock * voxel_) + " x " +
                                          format_value(extent.y() * kBlock * voxel_) + " x " +
                                          format_value(extent.z() * kBlock * voxel_) + " m, more than the field indexes (" +
                                          format_value(kMaxIndexBlocks) + " blocks of " + std::to_string(kBlock) +
                                          "^3 voxels of " + format_value(voxel_) + " m); use a larger voxel");
    block_lo_ = lo;
    block_n_ = hi - lo + 1;
    index_.assign(static_cast<std::size_t>(block_n_.prod()), -1);
    const double inv = 1.0 / voxel_;
    for (Index c = 0; c < points.cols(); ++c) {
      const Eigen::Vector3d p = points.col(c);
      Eigen::Array3i n0, n1;
      for (int a = 0; a < 3; ++a) {
        n0(a) = static_cast<int>(std::ceil((p(a) - truncation_) * inv));
        n1(a) = static_cast<int>(std::floor((p(a) + truncation_) * inv));
      }
      for (int k = n0.z(); k <= n1.z(); ++k) {
        const double dz = k * voxel_ - p.z();
        for (int j = n0.y(); j <= n1.y(); ++j) {
          const double dy = j * voxel_ - p.y();
          const double dyz = dy * dy + dz * dz;
          if (dyz > truncation_ * truncation_) continue;
          for (int i = n0.x(); i <= n1.x(); ++i) {
            const double dx = i * voxel_ - p.x();
            const auto d2 = static_cast<float>(dx * dx + dyz);
            if (!(d2 < cap_)) continue;
            float& v = node(i, j, k);
            v = std::min(v, d2);
          }
        }
      }
    }
  }

  static constexpr int kBlock = 8;
  static constexpr int kBlockNodes = kBlock * kBlock * kBlock;

  static int floor_div(int a, int b) noexcept { return a >= 0 ? a / b : -((-a + b - 1) / b); }
  static int offset(int i, int j, int k) noexcept {
    return ((k & (kBlock - 1)) * kBlock + (j & (kBlock - 1))) * kBlock + (i & (kBlock - 1));
  }

  std::int32_t block_of(int bx, int by, int bz) const noexcept {
    const int x = bx - block_lo_.x(), y = by - block_lo_.y(), z = bz - block_lo_.z();
    if (x < 0 || y < 0 || z < 0 || x >= block_n_.x() || y >= block_n_.y() || z >= block_n_.z()) return -1;
    return index_[(static_cast<std::size_t>(z) * static_cast<std::size_t>(block_n_.y()) + static_cast<std::size_t>(y)) *
                      static_cast<std::size_t>(block_n_.x()) +
                  static_cast<std::size_t>(x)];
  }

  float node_value(int i, int j, int k) const noexcept {
    const std::int32_t b = block_of(floor_div(i, kBlock), floor_div(j, kBlock), floor_div(k, kBlock));
    return b < 0 ? cap_ : blocks_[static_cast<std::size_t>(b) * kBlockNodes + static_cast<std::size_t>(offset(i, j, k))];
  }

  /// The node's storage, its block allocated (at cap()) on first use; the
  /// node lies inside the index by construction.
  float& node(int i, int j, int k) {
    const int x = floor_div(i, kBlock) - block_lo_.x(), y = floor_div(j, kBlock) - block_lo_.y(),
              z = floor_div(k, kBlock) - block_lo_.z();
    std::int32_t& b = index_[(static_cast<std::size_t>(z) * static_cast<std::size_t>(block_n_.y()) +
                              static_cast<std::size_t>(y)) *
                                 static_cast<std::size_t>(block_n_.x()) +
                             static_cast<std::size_t>(x)];
    if (b < 0) {
      b = static_cast<std::int32_t>(blocks_.size() / kBlockNodes);
      blocks_.resize(blocks_.size() + kBlockNodes, cap_);
    }
    return blocks_[static_cast<std::size_t>(b) * kBlockNodes + static_cast<std::size_t>(offset(i, j, k))];
  }

  double voxel_ = 1e-3;
  double truncation_ = 0;
  float cap_ = 0;
  Eigen::Array3i block_lo_ = Eigen::Array3i::Zero();
  Eigen::Array3i block_n_ = Eigen::Array3i::Zero();
  std::vector<std::int32_t> index_;  // dense over the blocks' box: block number or -1
  std::vector<float> blocks_;        // kBlockNodes nodes per block, x fastest
};

}  // namespace iclap

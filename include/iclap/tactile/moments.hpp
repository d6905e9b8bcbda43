// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#include <Eigen/Core>

#include "iclap/core/types.hpp"
#include "iclap/tactile/normalization.hpp"
#include "iclap/tactile/tactile_image.hpp"

namespace iclap {

/// Pressure-weighted image moments of a tactile image, the classic contact
/// shape features (Pezzementi et al. 2011; Drimus et al. 2014; Corradi et al.
/// 2015). Coordinates are in taxels with x = column, y = row and the origin
/// at the centre of the grid, so taxel (r, c) sits at
/// (c - (cols - 1) / 2, r - (rows - 1) / 2). A blank image has every field 0.
struct ImageMoments {
  /// Total pressure m00 = sum of the taxels, raw units (infinite only when
  /// the sum is beyond the range of a double; the other fields stay finite).
  double total = 0.0;
  /// Pressure centroid (x, y), taxels from the grid centre.
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  /// Central second moments divided by the total: the pressure-weighted
  /// covariance of the contact, taxels^2. Independent of the pressing force.
  double mu20 = 0.0, mu11 = 0.0, mu02 = 0.0;
  /// Angle of the contact's major axis from +x towards +y, radians in
  /// (-pi/2, pi/2]: 0 for a bar along a row, pi/2 for a bar along a column.
  /// 0 when the contact has no preferred axis (mu20 == mu02 and mu11 == 0,
  /// to within 64 ulps of mu20 + mu02).
  double orientation = 0.0;
  /// Hu's seven moment invariants (Hu 1962), unchanged by translation and
  /// rotation of the contact (hu[6] changes sign under mirroring). Computed
  /// from the normalised central moments eta_pq = mu_pq / m00^(1+(p+q)/2) of
  /// the image scaled to a peak of 1, which makes them independent of the
  /// pressing force and (as for binary images) of the contact's size.
  std::array<double, 7> hu{};
};

/// The moments of `image` (see ImageMoments). Allocation-free, O(rows * cols).
inline ImageMoments compute_moments(const TactileImage& image) noexcept {
  ImageMoments m;
  const Index rows = image.rows();
  const Index cols = image.cols();
  const double x0 = 0.5 * static_cast<double>(cols - 1);
  const double y0 = 0.5 * static_cast<double>(rows - 1);

  double m00 = 0.0, m10 = 0.0, m01 = 0.0;
  auto first_moments = [&](double divisor) {
    m00 = m10 = m01 = 0.0;
    for (Index c = 0; c < cols; ++c) {
      for (Index r = 0; r < rows; ++r) {
        const double p = image(r, c) / divisor;
        m00 += p;
        m10 += p * (static_cast<double>(c) - x0);
        m01 += p * (static_cast<double>(r) - y0);
      }
    }
  };
  first_moments(1.0);
  if (!(m00 > 0.0)) return m;
  const double peak = image.max();
  // Pressures whose sums overflow (two taxels at 1e308 gave an infinite
  // total and a NaN centroid) or whose peak is subnormal (its products
  // round off the centroid) are summed scaled to a peak of 1; the total is
  // then scaled back (infinite only where it is beyond a double). Others are
  // summed as they are, bit for bit.
  if (!(std::isfinite(m00) && std::isfinite(m10) && std::isfinite(m01)) ||
      peak < std::numeric_limits<double>::min()) {
    first_moments(peak);
    m.total = m00 * peak;
  } else {
    m.total = m00;
  }
  const double cx = m10 / m00;
  const double cy = m01 / m00;
  m.centroid = Eigen::Vector2d(cx, cy);

  // Central moments up to order 3 of the peak-normalised image.
  double u00 = 0.0, u20 = 0.0, u11 = 0.0, u02 = 0.0, u30 = 0.0, u21 = 0.0, u12 = 0.0, u03 = 0.0;
  for (Index c = 0; c < cols; ++c) {
    for (Index r = 0; r < rows; ++r) {
      const double p = image(r, c) / peak;
      const double dx = static_cast<double>(c) - x0 - cx;
      const double dy = static_cast<double>(r) - y0 - cy;
      u00 += p;
      u20 += p * dx * dx;
      u11 += p * dx * dy;
      u02 += p * dy * dy;
      u30 += p * dx * dx * dx;
      u21 += p * dx * dx * dy;
      u12 += p * dx * dy * dy;
      u03 += p * dy * dy * dy;
    }
  }
  m.mu20 = u20 / u00;
  m.mu11 = u11 / u00;
  m.mu02 = u02 / u00;
  // + 0.0 turns -0 into +0, so atan2 stays in (-pi, pi] and the angle in
  // (-pi/2, pi/2].
  // A contact with no preferred axis gets 0, also where rounding leaves
  // mu20 - mu02 and mu11 a few ulps from 0 (a symmetric plus-shaped
  // contact gave +-pi/2 or -pi/4 by the sign of that noise).
  const double axis_strength = std::hypot(m.mu20 - m.mu02, 2.0 * m.mu11);
  m.orientation = axis_strength <= 64.0 * std::numeric_limits<double>::epsilon() * (m.mu20 + m.mu02)
                      ? 0.0
                      : 0.5 * std::atan2(2.0 * m.mu11 + 0.0, m.mu20 - m.mu02);

  const double s2 = u00 * u00;              // u00^(1 + 2/2)
  const double s3 = s2 * std::sqrt(u00);    // u00^(1 + 3/2)
  const double n20 = u20 / s2, n11 = u11 / s2, n02 = u02 / s2;
  const double n30 = u30 / s3, n21 = u21 / s3, n12 = u12 / s3, n03 = u03 / s3;
  const double a = n30 + n12, b = n21 + n03;    // shared sums
  const double p = n30 - 3.0 * n12, q = 3.0 * n21 - n03;
  m.hu[0] = n20 + n02;
  m.hu[1] = (n20 - n02) * (n20 - n02) + 4.0 * n11 * n11;
  m.hu[2] = p * p + q * q;
  m.hu[3] = a * a + b * b;
  m.hu[4] = p * a * (a * a - 3.0 * b * b) + q * b * (3.0 * a * a - b * b);
  m.hu[5] = (n20 - n02) * (a * a - b * b) + 4.0 * n11 * a * b;
  m.hu[6] = q * a * (a * a - 3.0 * b * b) - p * b * (3.0 * a * a - b * b);
  return m;
}

/// The image-moments descriptor: a fixed 15-element summary of the contact,
///   [0]      mean pressure / full_scale (in [0, 1] for a calibrated sensor),
///   [1, 2]   centroid x, y,
///   [3 .. 5] mu20, mu11, mu02,
///   [6, 7]   anisotropy ((mu20 - mu02), 2 mu11) / (mu20 + mu02),
///   [8 .. 14] Hu invariants hu[0] .. hu[6], each compressed as
///            sign(h) * log(1 + |h|^(1/d)), d its degree in the normalised
///            central moments eta_pq (1, 2, 2, 2, 4, 3, 4),
/// with lengths divided by the longer side of the grid (areas by its square)
/// so position, spread and the invariants all have ranges of order 0.1 - 1
/// and a Euclidean codebook does not ignore any of them.
///
/// The raw invariants (ImageMoments::hu) do not: hu[i] is a polynomial of
/// degree d in the etas, and the etas of a sparse contact, a few pressed
/// taxels far apart, are large (the scaled image's area is small beside its
/// spread), so two pressed corners gave hu[4] = 1.6e8 and that one entry
/// decided every word. The d-th root brings each invariant to the scale of
/// an eta (about 0.1 for a compact contact) and the logarithm, nearly the
/// identity there, brings the sparsest contacts' (etas up to thousands on a
/// 14 x 6 grid) to about 5: 4.7 for the two corners. Both are odd and
/// monotonic, so the entries keep the invariants' order, their zeros and
/// hu[6]'s sign change under mirroring.
///
/// The orientation enters as the anisotropy vector, whose angle is twice the
/// major-axis angle and whose length is 0 for a round contact and 1 for a
/// line: unlike the raw angle it has no jump at +-pi/2 and no arbitrary value
/// for round contacts, both of which would split one shape across words.
/// A blank image gives zeros. compute() is const, allocation-free and
/// thread-safe.
template <typename Scalar = float>
class MomentsDescriptor {
  static_assert(detail::is_supported_scalar_v<Scalar>, "iclap: MomentsDescriptor Scalar must be float or double");

 public:
  static constexpr int kLength = 15;
  using Feature = Eigen::Matrix<Scalar, kLength, 1>;

  struct Settings {
    /// Sensor full scale in raw units (WTS: 12 bit).
    double full_scale = 4095.0;
  };

  /// Throws InvalidArgument naming "settings.full_scale" unless it is finite
  /// and positive.
  explicit MomentsDescriptor(const Settings& settings = {}) : settings_(settings) {
    check_full_scale(settings_.full_scale, "settings.full_scale");
  }

  const Settings& settings() const noexcept { return settings_; }
  Index length() const noexcept { return kLength; }

  /// The descriptor of `image`. Throws InvalidArgument naming "image" when
  /// the mean pressure over full scale is beyond the range of `Scalar`
  /// (pressures near 1e39 for float, or a tiny full scale).
  Feature compute(const TactileImage& image) const {
    const ImageMoments m = compute_moments(image);
    const double side = static_cast<double>(std::max(image.rows(), image.cols()));
    const double area = side * side;
    const double spread = m.mu20 + m.mu02;
    Eigen::Matrix<double, kLength, 1> f;
    f[0] = mean_over_full_scale(image, m.total);
    f[1] = m.centroid.x() / side;
    f[2] = m.centroid.y() / side;
    f[3] = m.mu20 / area;
    f[4] = m.mu11 / area;
    f[5] = m.mu02 / area;
    f[6] = spread > 0.0 ? (m.mu20 - m.mu02) / spread : 0.0;
    f[7] = spread > 0.0 ? 2.0 * m.mu11 / spread : 0.0;
    for (std::size_t i = 0; i < 7; ++i) f[8 + static_cast<Index>(i)] = compress_invariant(m.hu[i], kHuDegree[i]);
    // The other entries are normalised (lengths by the grid's side); the
    // mean pressure keeps the pressure's scale.
    detail::check_feature_value<Scalar>(f[0], "the mean pressure over full scale (entry 0) is",
                                        "scale the pressures or raise settings.full_scale");
    return f.template cast<Scalar>();
  }

 private:
  /// The mean pressure / full_scale: total / (full_scale * size), or where
  /// the total or that product is beyond a double (pressures near 1e308, a
  /// huge full_scale), peak * mean(p / peak) / full_scale, which is finite
  /// unless the mean itself is beyond a double (a tiny full_scale).
  double mean_over_full_scale(const TactileImage& image, double total) const {
    const double size = static_cast<double>(image.size());
    const double denominator = settings_.full_scale * size;
    if (std::isfinite(total) && std::isfinite(denominator)) return total / denominator;
    const double peak = image.max();
    double relative = 0.0;  // sum(p / peak)
    for (Index c = 0; c < image.cols(); ++c)
      for (Index r = 0; r < image.rows(); ++r) relative += image(r, c) / peak;
    return peak * (relative / size) / settings_.full_scale;
  }

  /// Degree of each Hu invariant in the normalised central moments.
  static constexpr std::array<int, 7> kHuDegree{1, 2, 2, 2, 4, 3, 4};

  /// sign(h) * log(1 + |h|^(1/degree)) (see the class comment).
  static double compress_invariant(double h, int degree) {
    const double root = degree == 1 ? std::abs(h) : std::pow(std::abs(h), 1.0 / static_cast<double>(degree));
    return std::copysign(std::log1p(root), h);
  }

  Settings settings_;
};

}  // namespace iclap

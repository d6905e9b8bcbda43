// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <limits>
#include <string>

#include "iclap/core/error.hpp"
#include "iclap/tactile/tactile_image.hpp"

namespace iclap {

/// How raw taxel pressures are rescaled before they are used as a feature.
enum class PressureNormalization {
  None,       ///< raw units, unchanged
  FullScale,  ///< divided by the sensor's full scale (WTS: 4095), so in [0, 1]
  Max,        ///< divided by the largest taxel: the peak becomes 1 (to rounding)
  Sum,        ///< divided by the total pressure: the taxels sum to 1
  L2,         ///< divided by the Euclidean norm of the grid: unit vector
};

/// Readable name of a normalisation ("none", "full_scale", "max", "sum", "l2").
inline const char* to_string(PressureNormalization n) noexcept {
  switch (n) {
    case PressureNormalization::None: return "none";
    case PressureNormalization::FullScale: return "full_scale";
    case PressureNormalization::Max: return "max";
    case PressureNormalization::Sum: return "sum";
    case PressureNormalization::L2: return "l2";
  }
  return "unknown";
}

namespace detail {

/// The largest magnitude a feature of type `Scalar` holds, as a double.
template <typename Scalar>
constexpr double largest_feature_value() noexcept {
  return static_cast<double>(std::numeric_limits<Scalar>::max());
}

/// Throws InvalidArgument naming "image" unless `value`, an entry of a
/// descriptor computed in double, is finite and fits `Scalar`: a feature
/// beyond the feature type's range is refused, not passed on as an
/// infinity. The message reads "WHAT V, beyond the range of the feature
/// type (largest L); ADVICE"; `what` is a string or a callable returning
/// one, built only for the error.
template <typename Scalar, typename What>
void check_feature_value(double value, const What& what, const char* advice) {
  if (std::abs(value) <= largest_feature_value<Scalar>()) return;
  throw InvalidArgument("image", argument_name(what) + " " + format_value(value) +
                                     ", beyond the range of the feature type (largest " +
                                     format_value(largest_feature_value<Scalar>()) + "); " + advice);
}

}  // namespace detail

/// Throws InvalidArgument naming `argument` unless `full_scale` is finite,
/// positive and has a finite reciprocal (at least about 5.6e-309), the
/// factor FullScale multiplies by.
inline void check_full_scale(double full_scale, const std::string& argument = "full_scale") {
  if (!std::isfinite(full_scale) || full_scale <= 0.0 || !std::isfinite(1.0 / full_scale))
    throw InvalidArgument(argument, "must be finite and > 0 with a finite reciprocal, got " + format_value(full_scale));
}

/// The factor that multiplies every taxel of `image` under normalisation `n`
/// (`full_scale` is used by FullScale only). A blank image (all zeros) gives
/// 0 for Max, Sum and L2, so its normalised image is all zeros, never NaN.
/// A sum or norm beyond the range of a double (finite pressures near
/// 1e308) still gives the factor that makes the taxels sum to 1 (Sum) or
/// their norm 1 (L2). Allocation-free,
/// O(rows * cols). Throws InvalidArgument for a bad `full_scale` when `n`
/// is FullScale, and naming "image" when the image's peak, sum or norm is so
/// small (subnormal, below about 5.6e-309) that the factor would be
/// infinite: rescale such pressures first.
inline double normalization_factor(const TactileImage& image, PressureNormalization n,
                                   double full_scale = 4095.0) {
  double denominator = 1.0;
  switch (n) {
    case PressureNormalization::None: return 1.0;
    case PressureNormalization::FullScale:
      check_full_scale(full_scale);
      return 1.0 / full_scale;
    case PressureNormalization::Max: denominator = image.max(); break;
    case PressureNormalization::Sum: denominator = image.sum(); break;
    case PressureNormalization::L2: denominator = image.pressures().stableNorm(); break;
  }
  if (!(denominator > 0.0)) return 0.0;
  if (!std::isfinite(denominator)) {
    // The sum, or the norm, of pressures near 1e308 is beyond a double (the
    // peak is not): taken relative to the peak, 1 / (peak * s) =
    // (1 / peak) / s with s the same statistic of p / peak, in
    // [1, rows * cols].
    const double inv_peak = 1.0 / image.max();
    return inv_peak / (n == PressureNormalization::Sum ? (image.pressures() * inv_peak).sum()
                                                       : (image.pressures() * inv_peak).norm());
  }
  const double factor = 1.0 / denominator;
  if (!std::isfinite(factor))
    throw InvalidArgument("image", std::string("its ") + (n == PressureNormalization::Max   ? "largest pressure "
                                                          : n == PressureNormalization::Sum ? "total pressure "
                                                                                            : "pressure norm ") +
                                       format_value(denominator) +
                                       " is too small to normalise by (its reciprocal overflows); rescale the pressures");
  return factor;
}

/// The normalised grid (rows x cols), `image.pressures() * factor`. Allocates
/// the result; descriptors use `normalization_factor` instead.
inline Eigen::MatrixXd normalized(const TactileImage& image, PressureNormalization n,
                                  double full_scale = 4095.0) {
  return image.pressures() * normalization_factor(image, n, full_scale);
}

}  // namespace iclap

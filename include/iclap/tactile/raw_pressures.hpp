// SPDX-License-Identifier: MIT
#pragma once

#include <string>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"
#include "iclap/tactile/normalization.hpp"
#include "iclap/tactile/tactile_image.hpp"

namespace iclap {

/// The raw-readings descriptor (Schneider et al. 2009; Liu et al. 2012): the
/// normalised taxel pressures themselves, flattened row by row, so element
/// r * cols + c is taxel (r, c), the order of the dataset's `p<r>_<c>`
/// columns.
///
/// Default normalisation L2: the k-means codebook compares features by
/// Euclidean distance, and between unit vectors that distance is a function
/// of the cosine similarity only, so words group contact *patterns*
/// independently of how hard the pad was pressed. Use FullScale to keep the
/// force in the feature, Max or Sum for other invariants. A blank image gives
/// zeros.
///
/// `Rows` and `Cols` fix the grid at compile time (e.g. 14 and 6 for the
/// WTS 0614-34A): the feature is then an allocation-free fixed-size vector
/// and an image of another size is a DimensionMismatch. With Eigen::Dynamic
/// (the default) any grid is accepted and the length is rows * cols of the
/// image. compute() is const and thread-safe, O(rows * cols).
template <typename Scalar = float, int Rows = Eigen::Dynamic, int Cols = Eigen::Dynamic>
class RawPressures {
  static_assert(detail::is_supported_scalar_v<Scalar>, "iclap: RawPressures Scalar must be float or double");
  static_assert(Rows > 0 || Rows == Eigen::Dynamic, "iclap: RawPressures Rows must be positive or Eigen::Dynamic");
  static_assert(Cols > 0 || Cols == Eigen::Dynamic, "iclap: RawPressures Cols must be positive or Eigen::Dynamic");

 public:
  static constexpr int kLength = (Rows > 0 && Cols > 0) ? Rows * Cols : Eigen::Dynamic;
  using Feature = Eigen::Matrix<Scalar, kLength, 1>;

  struct Settings {
    PressureNormalization normalization = PressureNormalization::L2;
    /// Sensor full scale in raw units, used by FullScale (WTS: 12 bit).
    double full_scale = 4095.0;
  };

  /// Throws InvalidArgument naming "settings.full_scale" unless it is finite
  /// and positive.
  explicit RawPressures(const Settings& settings = {}) : settings_(settings) {
    check_full_scale(settings_.full_scale, "settings.full_scale");
  }

  const Settings& settings() const noexcept { return settings_; }

  /// The flattened, normalised pressures of `image`. Throws DimensionMismatch
  /// naming "image.rows" / "image.cols" when the grid differs from a
  /// compile-time Rows / Cols, and InvalidArgument naming "image" when a
  /// normalised pressure is beyond the range of `Scalar` (None or FullScale
  /// with huge pressures or a tiny full scale; the others are at most 1).
  Feature compute(const TactileImage& image) const {
    if constexpr (Rows > 0) check_dimension(image.rows(), Rows, "image.rows");
    if constexpr (Cols > 0) check_dimension(image.cols(), Cols, "image.cols");
    const double factor = normalization_factor(image, settings_.normalization, settings_.full_scale);
    Feature out;
    if constexpr (kLength == Eigen::Dynamic) out.resize(image.size());
    const Index cols = image.cols();
    for (Index r = 0; r < image.rows(); ++r)
      for (Index c = 0; c < cols; ++c) {
        const double v = image(r, c) * factor;
        detail::check_feature_value<Scalar>(
            v,
            [&] {
              return "the pressure of taxel (" + std::to_string(r) + ", " + std::to_string(c) + "), " +
                     format_value(image(r, c)) + ", normalised (" + to_string(settings_.normalization) + ") is";
            },
            "normalise it (l2, max, sum) or scale the pressures");
        out[r * cols + c] = static_cast<Scalar>(v);
      }
    return out;
  }

 private:
  Settings settings_;
};

}  // namespace iclap

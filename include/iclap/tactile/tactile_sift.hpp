// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <type_traits>

#include <Eigen/Core>

#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"
#include "iclap/tactile/normalization.hpp"
#include "iclap/tactile/tactile_image.hpp"

namespace iclap {

/// How Tactile-SIFT splits the image into its sp x sp overlapping sub-patches.
enum class SiftSpatialBinning {
  /// Tent (bilinear) weights, SIFT's own choice (Lowe 2004): cell centres sit
  /// on a regular sp x sp grid over the image and each pixel gives its
  /// gradient to the (up to 4) nearest cells with weights falling linearly to
  /// 0 at the neighbouring centres. Each cell's support is two cell widths,
  /// so neighbouring sub-patches overlap by half; pixels outside the outer
  /// centres go wholly to the outer cells, so no gradient is lost at the
  /// border of the pad.
  Soft,
  /// Overlapping boxes with weight 1: cell j covers the pixels whose centre
  /// lies within (1 + box_overlap) / 2 cell widths of the cell centre
  /// (computed in exact integer arithmetic, so a mirrored image gives the
  /// mirrored boxes).
  Box,
};

/// How the concatenated histograms are normalised.
enum class SiftNormalization {
  None,    ///< raw magnitude-weighted histograms (scale with the pressure)
  L2,      ///< unit Euclidean norm
  L2Clip,  ///< unit norm, entries clipped at `clip`, unit norm again (SIFT)
};

/// Tactile-SIFT (Luo, Mou, Althoefer, Liu, "Novel Tactile-SIFT Descriptor
/// for Object Shape Recognition", IEEE Sensors Journal 15(9), 2015), the
/// feature the iCLAP paper uses (Section VI): the tactile image is treated as
/// one SIFT keypoint covering the whole pad. Its gradient image is split
/// into sp x sp overlapping sub-patches, each sub-patch becomes a dn-bin
/// histogram of gradient orientations weighted by gradient magnitude, and the
/// histograms are concatenated (length sp * sp * dn) and normalised. The
/// paper's best setting, and the default, is dn = 8, sp = 3: length 72.
///
/// The paper leaves patching, interpolation and normalisation open; here they
/// are settings with these defaults, and these reasons:
///  - `upsample = 1` (no upsampling). Bilinear upsampling adds no
///    measurement: on the upsampled grid the gradient is the taxel difference
///    spread over more samples, and the cost grows with upsample^2. With soft
///    spatial binning the descriptor is already continuous in the contact
///    position. Upsampling (pixel-centre aligned bilinear, borders clamped)
///    is there for box binning on grids that do not divide by sp.
///  - `spatial = Soft`: on a 14 x 6 pad with sp = 3 a cell is 2 taxels wide;
///    with hard cells a contact moving by one taxel would jump between
///    histograms. Tent weights make the descriptor vary smoothly, as in SIFT.
///  - `soft_orientation = true`: each gradient is shared linearly between
///    the two nearest orientation bins, for the same reason (and as SIFT).
///  - `window_sigma = 0` (no Gaussian window): SIFT down-weights gradients
///    far from its keypoint, but a touch can put the edge anywhere on the pad
///    and every taxel is an equally good measurement.
///  - `normalization = L2Clip`, `clip = 0.2`: exactly SIFT's rule, which
///    makes the descriptor invariant to the pressing force (a uniform scaling
///    of the pressures) and limits the weight of a single strong edge.
///
/// Conventions (the test suite checks them): x = column, y = row; the
/// gradient is the central difference with replicated borders, gx along
/// columns, gy along rows; its orientation atan2(gy, gx) is binned with bin b
/// centred on 2 pi b / dn (bin 0 = pressure rising towards larger columns).
/// Output index = (cell_row * sp + cell_col) * dn + bin. Hence mirroring the
/// image left-right maps cell column j to sp-1-j and bin b to (dn/2 - b) mod
/// dn (for even dn); mirroring top-bottom maps cell row i to sp-1-i and bin b
/// to (dn - b) mod dn.
///
/// A blank or uniform image has no gradient and gives the zero vector (never
/// NaN). Internally computed in double, returned as Scalar (float by default:
/// half the memory for codebooks, no loss that matters after L2
/// normalisation). `Sp` and `Dn` are compile-time sizes, so the default type
/// returns an `Eigen::Matrix<float, 72, 1>` without touching the heap; use
/// `Eigen::Dynamic` for both (`DynamicTactileSift`) to choose them at run
/// time. compute() is const, allocation-free for fixed sizes and
/// thread-safe; cost O(rows * cols * upsample^2): about 3 microseconds for
/// a 14 x 6 frame, a third of it in atan2 (benchmarks/bench_tactile.cpp).
template <typename Scalar = float, int Sp = 3, int Dn = 8>
class TactileSift {
  static_assert(detail::is_supported_scalar_v<Scalar>, "iclap: TactileSift Scalar must be float or double");
  static_assert(Sp > 0 || Sp == Eigen::Dynamic, "iclap: TactileSift Sp must be positive or Eigen::Dynamic");
  static_assert(Dn > 0 || Dn == Eigen::Dynamic, "iclap: TactileSift Dn must be positive or Eigen::Dynamic");

 public:
  /// Feature length at compile time, or Eigen::Dynamic.
  static constexpr int kLength = (Sp > 0 && Dn > 0) ? Sp * Sp * Dn : Eigen::Dynamic;
  using Feature = Eigen::Matrix<Scalar, kLength, 1>;

  struct Settings {
    /// Sub-patches per side (>= 1); must equal Sp when Sp is fixed.
    int sp = Sp > 0 ? Sp : 3;
    /// Orientation bins (>= 1); must equal Dn when Dn is fixed.
    int dn = Dn > 0 ? Dn : 8;
    /// Integer bilinear upsampling factor, 1..16 (1 = none).
    int upsample = 1;
    SiftSpatialBinning spatial = SiftSpatialBinning::Soft;
    /// Box binning only: overlap of neighbouring boxes as a fraction of the
    /// cell width, in [0, 1). 0.5 = each box 1.5 cells wide.
    double box_overlap = 0.5;
    /// Share each gradient between the two nearest orientation bins. When
    /// false, each gradient goes to the nearest bin, or in equal halves to
    /// the two bins it lies exactly between.
    bool soft_orientation = true;
    /// Gaussian window sigma as a fraction of the image extent per axis
    /// (e.g. 0.5 = half the width along x, half the height along y);
    /// 0 disables the window. Otherwise at least kMinWindowSigma.
    double window_sigma = 0.0;
    SiftNormalization normalization = SiftNormalization::L2Clip;
    /// L2Clip only: entries are clipped at this value, in (0, 1].
    double clip = 0.2;
  };

  /// The narrowest window: at the pad's edge a window weighs
  /// exp(-0.5 (0.5 / window_sigma)^2) per axis, 2.6e-136 here; a narrower
  /// one underflows a double across most of the pad, and a contact off its
  /// centre became the zero vector.
  static constexpr double kMinWindowSigma = 0.02;
  /// The longest feature, sp * sp * dn (so that it and every index into it
  /// fit an int).
  static constexpr Index kMaxLength = std::numeric_limits<int>::max();

  /// Checks the settings: throws InvalidArgument naming the setting
  /// ("settings.sp", "settings.dn", ...) when it is out of range or differs
  /// from a compile-time size.
  explicit TactileSift(const Settings& settings = {}) : settings_(settings) {
    const auto fail = [](const char* name, const std::string& why) {
      throw InvalidArgument(std::string("settings.") + name, why);
    };
    if (settings_.sp < 1) fail("sp", "must be at least 1, got " + std::to_string(settings_.sp));
    if (settings_.dn < 1) fail("dn", "must be at least 1, got " + std::to_string(settings_.dn));
    // sp * sp fits an Index (sp <= 2^31); the product with dn is checked by
    // division, since it may not.
    const Index cells = Index(settings_.sp) * settings_.sp;
    if (cells > kMaxLength)
      fail("sp", std::to_string(settings_.sp) + " gives " + std::to_string(cells) + " cells, more than the longest feature (" +
                     std::to_string(kMaxLength) + " entries)");
    if (settings_.dn > kMaxLength / cells)
      fail("dn", "sp * sp * dn = " + std::to_string(cells) + " * " + std::to_string(settings_.dn) +
                     " is more than the longest feature (" + std::to_string(kMaxLength) + " entries)");
    if (Sp > 0 && settings_.sp != Sp)
      fail("sp", "is " + std::to_string(settings_.sp) + " but the type fixes it to " + std::to_string(Sp) +
                     " (use Eigen::Dynamic for a run-time value)");
    if (Dn > 0 && settings_.dn != Dn)
      fail("dn", "is " + std::to_string(settings_.dn) + " but the type fixes it to " + std::to_string(Dn) +
                     " (use Eigen::Dynamic for a run-time value)");
    if (settings_.upsample < 1 || settings_.upsample > 16)
      fail("upsample", "must be in 1..16, got " + std::to_string(settings_.upsample));
    if (!(settings_.box_overlap >= 0.0 && settings_.box_overlap < 1.0))
      fail("box_overlap", "must be in [0, 1), got " + format_exact(settings_.box_overlap));
    if (!(settings_.window_sigma >= 0.0) || !std::isfinite(settings_.window_sigma))
      fail("window_sigma", "must be finite and >= 0, got " + format_exact(settings_.window_sigma));
    if (settings_.window_sigma > 0.0 && settings_.window_sigma < kMinWindowSigma)
      fail("window_sigma", "must be 0 (no window) or at least " + format_exact(kMinWindowSigma) + ", got " +
                               format_exact(settings_.window_sigma) +
                               ": a narrower window's weights underflow across the pad");
    if (!(settings_.clip > 0.0 && settings_.clip <= 1.0))
      fail("clip", "must be in (0, 1], got " + format_exact(settings_.clip));
  }

  const Settings& settings() const noexcept { return settings_; }

  /// Feature length, sp * sp * dn.
  Index length() const noexcept { return Index(settings_.sp) * settings_.sp * settings_.dn; }

  /// The descriptor of `image` (see the class comment for the layout).
  /// Throws InvalidArgument naming "image" when raw histograms
  /// (SiftNormalization::None), which scale with the pressure, exceed the
  /// range of `Scalar`.
  Feature compute(const TactileImage& image) const {
    const int sp = settings_.sp;
    const int dn = settings_.dn;
    const int u = settings_.upsample;
    const Index h = image.rows() * u;  // upsampled grid
    const Index w = image.cols() * u;

    Accumulated acc;
    if constexpr (kLength == Eigen::Dynamic) acc.resize(length());
    acc.setZero();

    // With a normalised output the pressure scale cancels; dividing the
    // gradients by the peak keeps their squares clear of underflow for tiny
    // pressures and of overflow for huge ones. The raw histograms (None)
    // keep the pressure scale: their gradients are taken as they are, or,
    // for peaks whose squares would overflow or underflow, divided by the
    // peak and the histograms multiplied by it at the end. Blank image:
    // nothing to do.
    const double peak = image.max();
    if (!(peak > 0.0)) return Feature::Zero(length());
    const bool raw = settings_.normalization == SiftNormalization::None;
    const bool rescaled = !raw || !(peak >= 1e-150 && peak <= 1e150);
    const double divisor = rescaled ? peak : 1.0;
    const bool windowed = settings_.window_sigma > 0.0;
    const double sigma_x = settings_.window_sigma * static_cast<double>(w);
    const double sigma_y = settings_.window_sigma * static_cast<double>(h);
    constexpr double two_pi = 6.283185307179586476925286766559;
    const double bins_per_radian = static_cast<double>(dn) / two_pi;

    // Column weights are the same on every row: computed once (on the stack
    // for grids up to kStackColumns wide, the WTS needs 6).
    AxisWeights column_weights[kStackColumns];
    const bool cached_columns = w <= kStackColumns;
    if (cached_columns)
      for (Index l = 0; l < w; ++l) column_weights[l] = axis_weights(l, w, sp);

    // Central differences with replicated borders; without upsampling they
    // read the taxels directly (column-major storage).
    const double* taxels = image.pressures().data();
    const Index rows = image.rows();
    const auto value = [&](Index k, Index l) { return u == 1 ? taxels[l * rows + k] : sample(image, k, l); };

    for (Index k = 0; k < h; ++k) {
      const AxisWeights wy = axis_weights(k, h, sp);
      const double window_y = windowed ? gaussian(static_cast<double>(k) + 0.5, 0.5 * static_cast<double>(h), sigma_y) : 1.0;
      const Index up = std::max<Index>(k - 1, 0);
      const Index down = std::min(k + 1, h - 1);
      for (Index l = 0; l < w; ++l) {
        const double gx = 0.5 * ((value(k, std::min(l + 1, w - 1)) - value(k, std::max<Index>(l - 1, 0))) / divisor);
        const double gy = 0.5 * ((value(down, l) - value(up, l)) / divisor);
        double magnitude = std::sqrt(gx * gx + gy * gy);
        if (!(magnitude > 0.0)) continue;
        if (windowed)
          magnitude *= window_y * gaussian(static_cast<double>(l) + 0.5, 0.5 * static_cast<double>(w), sigma_x);

        // Orientation bin position t in [0, dn): bin b is centred on t = b.
        double t = std::atan2(gy, gx) * bins_per_radian;
        if (t < 0.0) t += dn;
        int b0 = static_cast<int>(t);  // t >= 0: truncation is floor
        double f = t - b0;
        if (!settings_.soft_orientation) {
          // The nearest bin; a gradient exactly between two bins (a vertical
          // one for dn = 2, a diagonal one for dn = 4) is shared equally, as
          // rounding it up would break the mirror rule above.
          if (f > 0.5) ++b0;
          if (f != 0.5) f = 0.0;
        }
        if (b0 >= dn) b0 -= dn;  // t rounded up to dn
        const int b1 = b0 + 1 == dn ? 0 : b0 + 1;

        const AxisWeights wx = cached_columns ? column_weights[l] : axis_weights(l, w, sp);
        for (int iy = 0; iy < wy.n; ++iy) {
          for (int ix = 0; ix < wx.n; ++ix) {
            const double m = magnitude * wy.weight[iy] * wx.weight[ix];
            const Index base = (Index(wy.cell[iy]) * sp + wx.cell[ix]) * dn;
            acc[base + b0] += m * (1.0 - f);
            if (f > 0.0) acc[base + b1] += m * f;
          }
        }
      }
    }
    normalize(acc);
    if (raw) {
      if (rescaled) acc *= peak;
      // Raw histograms scale with the pressure: beyond the feature type's
      // range they are refused, not passed on as infinities.
      detail::check_feature_value<Scalar>(
          acc.cwiseAbs().maxCoeff(),
          [peak] { return "the raw (SiftNormalization::None) histograms of pressures peaking at " + format_value(peak) + " reach"; },
          "normalise them (L2, L2Clip) or scale the pressures");
    }
    if constexpr (std::is_same_v<Scalar, double>) {
      return acc;
    } else {
      return acc.template cast<Scalar>();
    }
  }

 private:
  using Accumulated = Eigen::Matrix<double, kLength, 1>;
  static constexpr Index kStackColumns = 32;

  /// The (at most two) cells a pixel contributes to along one axis.
  struct AxisWeights {
    int cell[2] = {0, 0};
    double weight[2] = {0.0, 0.0};
    int n = 0;
  };

  /// Weights of pixel `i` (of `extent` pixels) along one axis with `sp` cells.
  AxisWeights axis_weights(Index i, Index extent, int sp) const noexcept {
    AxisWeights a;
    if (settings_.spatial == SiftSpatialBinning::Soft) {
      // Position in cell units with cell centres at 0, 1, ..., sp-1.
      double t = (static_cast<double>(i) + 0.5) * sp / static_cast<double>(extent) - 0.5;
      t = std::clamp(t, 0.0, static_cast<double>(sp - 1));
      const int c0 = static_cast<int>(std::floor(t));
      const double f = t - c0;
      a.cell[0] = c0;
      a.weight[0] = 1.0 - f;
      a.n = 1;
      if (f > 0.0 && c0 + 1 < sp) {
        a.cell[1] = c0 + 1;
        a.weight[1] = f;
        a.n = 2;
      }
    } else {
      // Scaled by 2 * sp: pixel centre (2i+1) sp, cell centre (2j+1) extent,
      // box half-width (1 + overlap) extent. Integers, so mirror-exact.
      const Index pixel = (2 * i + 1) * sp;
      const double half = (1.0 + settings_.box_overlap) * static_cast<double>(extent);
      for (int j = 0; j < sp && a.n < 2; ++j) {
        const Index distance = std::abs(pixel - (2 * Index(j) + 1) * extent);
        if (static_cast<double>(distance) <= half) {
          a.cell[a.n] = j;
          a.weight[a.n] = 1.0;
          ++a.n;
        }
      }
    }
    return a;
  }

  /// Pressure at pixel (k, l) of the upsampled grid: pixel-centre aligned
  /// bilinear interpolation with clamped borders (the taxel itself for
  /// upsample 1).
  double sample(const TactileImage& image, Index k, Index l) const noexcept {
    const int u = settings_.upsample;
    if (u == 1) return image(k, l);
    const double y = std::clamp((static_cast<double>(k) + 0.5) / u - 0.5, 0.0, static_cast<double>(image.rows() - 1));
    const double x = std::clamp((static_cast<double>(l) + 0.5) / u - 0.5, 0.0, static_cast<double>(image.cols() - 1));
    const Index y0 = static_cast<Index>(y);
    const Index x0 = static_cast<Index>(x);
    const Index y1 = std::min(y0 + 1, image.rows() - 1);
    const Index x1 = std::min(x0 + 1, image.cols() - 1);
    const double fy = y - static_cast<double>(y0);
    const double fx = x - static_cast<double>(x0);
    const double top = image(y0, x0) * (1.0 - fx) + image(y0, x1) * fx;
    const double bottom = image(y1, x0) * (1.0 - fx) + image(y1, x1) * fx;
    return top * (1.0 - fy) + bottom * fy;
  }

  static double gaussian(double x, double centre, double sigma) noexcept {
    const double z = (x - centre) / sigma;
    return std::exp(-0.5 * z * z);
  }

  /// Applies settings_.normalization in place; a zero vector stays zero.
  void normalize(Accumulated& v) const noexcept {
    if (settings_.normalization == SiftNormalization::None) return;
    const double peak = v.cwiseAbs().maxCoeff();
    if (!(peak > 0.0)) {
      v.setZero();
      return;
    }
    v /= peak;  // guards the squared norm against underflow
    v /= v.norm();
    if (settings_.normalization == SiftNormalization::L2Clip) {
      v = v.cwiseMin(settings_.clip);
      v /= v.norm();  // > 0: the largest entry is now min(its value, clip) > 0
    }
  }

  Settings settings_;
};

/// Tactile-SIFT with sp and dn chosen at run time (feature length
/// sp * sp * dn, Eigen::Dynamic at compile time).
template <typename Scalar = float>
using DynamicTactileSift = TactileSift<Scalar, Eigen::Dynamic, Eigen::Dynamic>;

}  // namespace iclap

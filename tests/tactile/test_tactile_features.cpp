// SPDX-License-Identifier: MIT
// Tactile images, contact test, normalisations and the shipped descriptors
// (Tactile-SIFT, raw pressures, image moments), plus the Descriptor concept.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "iclap/tactile/tactile.hpp"
#include "../support/enum_names.hpp"
#include "../support/errors.hpp"
#include "synthetic_contacts.hpp"

using namespace iclap;
using iclap::test::ContactShape;

// Every public class template, for float and double, so every member compiles.
template class iclap::TactileSift<float>;
template class iclap::TactileSift<double>;
template class iclap::TactileSift<float, Eigen::Dynamic, Eigen::Dynamic>;
template class iclap::TactileSift<double, 2, 4>;
template class iclap::RawPressures<float>;
template class iclap::RawPressures<double, 14, 6>;
template class iclap::MomentsDescriptor<float>;
template class iclap::MomentsDescriptor<double>;

namespace {

constexpr double kPi = 3.141592653589793238462643383279502884;

Eigen::MatrixXd mirror_columns(const Eigen::MatrixXd& m) { return m.rowwise().reverse(); }
Eigen::MatrixXd mirror_rows(const Eigen::MatrixXd& m) { return m.colwise().reverse(); }

/// 90-degree rotation of a square grid: B(r, c) = A(n-1-c, r).
Eigen::MatrixXd rotate90(const Eigen::MatrixXd& a) {
  const Index n = a.rows();
  Eigen::MatrixXd b(n, n);
  for (Index r = 0; r < n; ++r)
    for (Index c = 0; c < n; ++c) b(r, c) = a(n - 1 - c, r);
  return b;
}

template <typename Vec>
bool all_finite(const Vec& v) {
  for (Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(static_cast<double>(v[i]))) return false;
  return true;
}

Index sift_index(int sp, int dn, int cell_row, int cell_col, int bin) {
  return (Index(cell_row) * sp + cell_col) * dn + bin;
}

int wrap(int b, int dn) { return ((b % dn) + dn) % dn; }

/// A blank 14 x 6 pad pressed at one taxel: its only gradients are
/// value / 2 at the four taxels beside it (central differences).
Eigen::MatrixXd single_taxel(Index row, Index col, double value) {
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(14, 6);
  p(row, col) = value;
  return p;
}

}  // namespace

// ---------------------------------------------------------------------------
TEST_CASE("TactileImage validates its pressures and names the argument") {
  Eigen::MatrixXd p = Eigen::MatrixXd::Constant(14, 6, 10.0);
  const TactileImage image(p);
  CHECK(image.rows() == 14);
  CHECK(image.cols() == 6);
  CHECK(image.size() == 84);
  CHECK(image.max() == 10.0);
  CHECK(image.sum() == 840.0);

  p(3, 2) = std::numeric_limits<double>::quiet_NaN();
  try {
    TactileImage bad(p, "frames[7].pressures");
    FAIL("NaN accepted");
  } catch (const NonFiniteValue& e) {
    CHECK(e.argument() == "frames[7].pressures");
    CHECK(e.row() == 3);
    CHECK(e.column() == 2);
  }
  p(3, 2) = -1.0;
  try {
    TactileImage bad(p);
    FAIL("negative pressure accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "pressures");
    CHECK(std::string(e.what()).find("row 3, column 2") != std::string::npos);
  }
  CHECK_THROWS_AS(TactileImage(Eigen::MatrixXd(0, 6)), EmptyInput);
  CHECK_THROWS_AS(TactileImage(Eigen::MatrixXd(14, 0)), EmptyInput);

  // From any Eigen expression, e.g. integer readings.
  const Eigen::MatrixXi raw = Eigen::MatrixXi::Constant(2, 3, 4095);
  CHECK(TactileImage::from(raw).sum() == 6 * 4095.0);
}

TEST_CASE("contact: a frame passes when enough taxels are strictly above the threshold") {
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(14, 6);
  CHECK_FALSE(is_contact(TactileImage(p)));  // blank pad, threshold 0
  p(4, 4) = 30.0;
  const TactileImage one(p);
  CHECK(is_contact(one));
  CHECK(is_contact(one, 29.0));
  CHECK_FALSE(is_contact(one, 30.0));  // "at or below the threshold" is no contact
  CHECK_FALSE((ContactDetector{10.0, 2}(one)));
  p(5, 4) = 12.0;
  CHECK((ContactDetector{10.0, 2}(TactileImage(p))));
  CHECK_THROWS_AS(is_contact(one, -1.0), InvalidArgument);
  CHECK_THROWS_AS(is_contact(one, std::numeric_limits<double>::quiet_NaN()), InvalidArgument);
  CHECK_THROWS_AS((ContactDetector{0.0, 0}(one)), InvalidArgument);
}

TEST_CASE("pressure normalisations") {
  Eigen::MatrixXd p(2, 2);
  p << 1, 2, 3, 4;
  const TactileImage image(p);
  CHECK(normalized(image, PressureNormalization::None) == p);
  CHECK(normalized(image, PressureNormalization::FullScale, 8.0)(1, 1) == doctest::Approx(0.5));
  CHECK(normalized(image, PressureNormalization::Max).maxCoeff() == doctest::Approx(1.0));
  CHECK(normalized(image, PressureNormalization::Sum).sum() == doctest::Approx(1.0));
  CHECK(normalized(image, PressureNormalization::L2).norm() == doctest::Approx(1.0));
  CHECK_THROWS_AS(normalized(image, PressureNormalization::FullScale, 0.0), InvalidArgument);

  const TactileImage blank(Eigen::MatrixXd::Zero(14, 6));
  for (auto n : {PressureNormalization::Max, PressureNormalization::Sum, PressureNormalization::L2}) {
    CAPTURE(to_string(n));
    const Eigen::MatrixXd z = normalized(blank, n);
    CHECK(z.allFinite());
    CHECK(z.isZero(0.0));
  }

  // A sum beyond a double still normalises to 1 (the factor was 1 / inf = 0).
  Eigen::MatrixXd huge(1, 3);
  huge << 1e308, 1e308, 5e307;
  const Eigen::MatrixXd by_sum = normalized(TactileImage(huge), PressureNormalization::Sum);
  CHECK(by_sum.sum() == doctest::Approx(1.0));
  CHECK(by_sum(0, 2) == doctest::Approx(0.2));
  CHECK(normalized(TactileImage(huge), PressureNormalization::L2).norm() == doctest::Approx(1.0));
  // A norm beyond a double too: 84 taxels at 1e308 (the factor was 0).
  const TactileImage full_pad(Eigen::MatrixXd::Constant(14, 6, 1e308));
  CHECK(normalized(full_pad, PressureNormalization::L2).norm() == doctest::Approx(1.0));
  CHECK(normalized(full_pad, PressureNormalization::Sum).sum() == doctest::Approx(1.0));
  // A statistic whose reciprocal overflows is refused naming the image
  // (the factor was inf and the image inf and NaN).
  Eigen::MatrixXd tiny(2, 2);
  tiny << 1e-310, 0, 2e-310, 0;
  for (auto n : {PressureNormalization::Max, PressureNormalization::Sum, PressureNormalization::L2}) {
    CAPTURE(to_string(n));
    CHECK_THROWS_WITH_AS(normalization_factor(TactileImage(tiny), n), doctest::Contains("image: its "), InvalidArgument);
  }
  CHECK(normalization_factor(TactileImage(tiny * 1e10), PressureNormalization::Max) == doctest::Approx(0.5e300));
  CHECK_THROWS_WITH_AS(normalized(image, PressureNormalization::FullScale, 1e-310),
                       doctest::Contains("finite reciprocal"), InvalidArgument);
}

TEST_CASE("pressure normalisations: every one has its documented, distinct name") {
  const std::pair<PressureNormalization, std::string> names[] = {
      {PressureNormalization::None, "none"}, {PressureNormalization::FullScale, "full_scale"},
      {PressureNormalization::Max, "max"},   {PressureNormalization::Sum, "sum"},
      {PressureNormalization::L2, "l2"},
  };
  iclap::test::check_enum_names(names, static_cast<PressureNormalization>(99));
}

// ---------------------------------------------------------------------------
TEST_CASE("Tactile-SIFT: paper default is a fixed 72-element vector, other sp/dn give sp*sp*dn") {
  static_assert(TactileSift<>::kLength == 72, "paper setting dn = 8, sp = 3");
  static_assert(std::is_same_v<TactileSift<>::Feature, Eigen::Matrix<float, 72, 1>>);
  static_assert(TactileSift<double, 2, 4>::kLength == 16);
  static_assert(DynamicTactileSift<>::kLength == Eigen::Dynamic);

  Rng rng(1);
  const TactileImage image(test::synthetic_contact(ContactShape::Corner, rng));
  CHECK(TactileSift<>().compute(image).size() == 72);
  CHECK(TactileSift<double, 2, 4>().compute(image).size() == 16);
  for (int sp : {1, 2, 4, 5}) {
    for (int dn : {1, 4, 6, 12}) {
      DynamicTactileSift<float>::Settings s;
      s.sp = sp;
      s.dn = dn;
      const DynamicTactileSift<float> sift(s);
      const auto f = sift.compute(image);
      CHECK(f.size() == sp * sp * dn);
      CHECK(sift.length() == sp * sp * dn);
      CHECK(all_finite(f));
      CHECK(f.norm() == doctest::Approx(1.0).epsilon(1e-5));
    }
  }
}

TEST_CASE("Tactile-SIFT: settings are validated and name the setting") {
  const auto fails_on = [](auto settings, const std::string& name) {
    try {
      DynamicTactileSift<float> sift(settings);
      FAIL("accepted bad " << name);
    } catch (const InvalidArgument& e) {
      CHECK(e.argument() == name);
    }
  };
  DynamicTactileSift<float>::Settings s;
  s.sp = 0;
  fails_on(s, "settings.sp");
  s = {};
  s.dn = 0;
  fails_on(s, "settings.dn");
  s = {};
  s.upsample = 0;
  fails_on(s, "settings.upsample");
  s = {};
  s.box_overlap = 1.0;
  fails_on(s, "settings.box_overlap");
  s = {};
  s.window_sigma = -1.0;
  fails_on(s, "settings.window_sigma");
  s = {};
  s.clip = 0.0;
  fails_on(s, "settings.clip");
  // A value just outside its range is shown with every digit it needs, not
  // as std::to_string's six decimals ("1.000000", which looks inside (0, 1]).
  s = {};
  s.clip = 1.000000001;
  CHECK_THROWS_WITH_AS(DynamicTactileSift<float>{s}, "settings.clip: must be in (0, 1], got 1.000000001",
                       InvalidArgument);
  s = {};
  s.window_sigma = -1e-300;
  CHECK_THROWS_WITH_AS(DynamicTactileSift<float>{s}, "settings.window_sigma: must be finite and >= 0, got -1e-300",
                       InvalidArgument);

  TactileSift<>::Settings fixed;
  fixed.sp = 4;  // the type fixes sp = 3
  CHECK_THROWS_AS(TactileSift<>{fixed}, InvalidArgument);
}

TEST_CASE("Tactile-SIFT: gradient orientation convention") {
  // Pressure rising along columns: every gradient points along +x, bin 0.
  Eigen::MatrixXd ramp(14, 6);
  for (Index r = 0; r < 14; ++r)
    for (Index c = 0; c < 6; ++c) ramp(r, c) = 50.0 + 100.0 * static_cast<double>(c);
  const auto fx = TactileSift<double>().compute(TactileImage(ramp));
  // Pressure rising along rows: +y, bin dn/4 = 2.
  Eigen::MatrixXd ramp_y(14, 6);
  for (Index r = 0; r < 14; ++r)
    for (Index c = 0; c < 6; ++c) ramp_y(r, c) = 50.0 + 100.0 * static_cast<double>(r);
  const auto fy = TactileSift<double>().compute(TactileImage(ramp_y));
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int b = 0; b < 8; ++b) {
        CAPTURE(i);
        CAPTURE(j);
        CAPTURE(b);
        CHECK((fx[sift_index(3, 8, i, j, b)] > 0.0) == (b == 0));
        CHECK((fy[sift_index(3, 8, i, j, b)] > 0.0) == (b == 2));
      }
    }
  }
}

TEST_CASE("Tactile-SIFT: blank and uniform images give zeros, never NaN") {
  for (double level : {0.0, 1000.0, 4095.0}) {
    const TactileImage flat(Eigen::MatrixXd::Constant(14, 6, level));
    const auto f = TactileSift<>().compute(flat);
    CHECK(all_finite(f));
    CHECK(f.isZero(0.0f));
  }
  // Tiny pressures must not underflow into NaN either.
  Eigen::MatrixXd tiny = Eigen::MatrixXd::Zero(14, 6);
  for (double level : {1e-300, 4.9e-324, 1e300}) {  // 4.9e-324: the smallest subnormal
    tiny(3, 3) = level;
    const auto f = TactileSift<double>().compute(TactileImage(tiny));
    CHECK(all_finite(f));
    CHECK(f.norm() == doctest::Approx(1.0));
  }
}

TEST_CASE("Tactile-SIFT: a uniform pressure scaling leaves it unchanged") {
  Rng rng(2);
  for (auto spatial : {SiftSpatialBinning::Soft, SiftSpatialBinning::Box}) {
    for (int upsample : {1, 2}) {
      TactileSift<double>::Settings s;
      s.spatial = spatial;
      s.upsample = upsample;
      const TactileSift<double> sift(s);
      for (ContactShape shape : test::kAllShapes) {
        const Eigen::MatrixXd p = test::synthetic_contact(shape, rng);
        const auto a = sift.compute(TactileImage(p));
        for (double scale : {2.0, 0.37, 1000.0}) {
          const auto b = sift.compute(TactileImage(p * scale));
          CHECK((a - b).cwiseAbs().maxCoeff() < 1e-12);
        }
      }
    }
  }
}

TEST_CASE("Tactile-SIFT: L2Clip is L2, clip, L2 again") {
  Rng rng(3);
  TactileSift<double>::Settings l2;
  l2.normalization = SiftNormalization::L2;
  TactileSift<double>::Settings clipped;  // default: L2Clip at 0.2
  for (ContactShape shape : test::kAllShapes) {
    const TactileImage image(test::synthetic_contact(shape, rng));
    const Eigen::VectorXd v = TactileSift<double>(l2).compute(image);
    Eigen::VectorXd expected = v.cwiseMin(0.2);
    expected /= expected.norm();
    const Eigen::VectorXd got = TactileSift<double>(clipped).compute(image);
    CHECK((got - expected).cwiseAbs().maxCoeff() < 1e-12);
    // Without normalisation the histograms carry the pressure scale.
    TactileSift<double>::Settings raw;
    raw.normalization = SiftNormalization::None;
    const Eigen::VectorXd r = TactileSift<double>(raw).compute(image);
    CHECK((r / r.norm() - v).cwiseAbs().maxCoeff() < 1e-12);
  }
}

TEST_CASE("Tactile-SIFT: raw histograms keep the pressure scale at the extremes of a double, or are refused") {
  Rng rng(8);
  TactileSift<double>::Settings raw;
  raw.normalization = SiftNormalization::None;
  const TactileSift<double> sift(raw);
  for (ContactShape shape : test::kAllShapes) {
    const Eigen::MatrixXd p = test::synthetic_contact(shape, rng);
    const Eigen::VectorXd r = sift.compute(TactileImage(p));
    REQUIRE(r.maxCoeff() > 0);
    // Squared gradients of 1e300 overflowed (inf entries), of 1e-300
    // underflowed (zeros); now they scale with the pressure.
    for (const double scale : {1e300, 1e-300, 1e150, 1e-150}) {
      const Eigen::VectorXd got = sift.compute(TactileImage(p * scale));
      REQUIRE(got.allFinite());
      CHECK((got / scale - r).cwiseAbs().maxCoeff() <= 1e-12 * r.cwiseAbs().maxCoeff());
    }
    // Beyond the feature type: refused, naming the image.
    TactileSift<float>::Settings raw_float;
    raw_float.normalization = SiftNormalization::None;
    const TactileSift<float> narrow(raw_float);
    CHECK(narrow.compute(TactileImage(p * 1e20)).allFinite());
    CHECK_THROWS_WITH_AS(narrow.compute(TactileImage(p * 1e300)), doctest::Contains("image: the raw"), InvalidArgument);
  }
}

TEST_CASE("Tactile-SIFT: a mirrored image gives the permuted descriptor") {
  // Left-right mirror: x -> -x, so cell column j -> sp-1-j and the gradient
  // angle theta -> pi - theta, i.e. bin b (centred on 2 pi b / dn) -> dn/2 - b.
  // Top-bottom mirror: y -> -y, cell row i -> sp-1-i and theta -> -theta,
  // i.e. bin b -> -b (mod dn).
  // Hard orientation binning (soft = false) too: there a vertical gradient
  // (dn = 2) or a diagonal one (dn = 4) lies exactly between two bins, and
  // rounding it up broke the rule.
  struct Case {
    int sp, dn, upsample;
    SiftSpatialBinning spatial;
    double window_sigma;
    bool soft = true;
  };
  const Case cases[] = {{3, 8, 1, SiftSpatialBinning::Soft, 0.0},        {3, 8, 1, SiftSpatialBinning::Box, 0.0},
                        {3, 8, 2, SiftSpatialBinning::Soft, 0.0},        {2, 4, 1, SiftSpatialBinning::Soft, 0.5},
                        {4, 6, 3, SiftSpatialBinning::Box, 0.3},         {5, 12, 1, SiftSpatialBinning::Soft, 0.0},
                        {3, 2, 1, SiftSpatialBinning::Soft, 0.0, false}, {3, 4, 1, SiftSpatialBinning::Soft, 0.0, false},
                        {3, 8, 1, SiftSpatialBinning::Box, 0.0, false}};
  Rng rng(4);
  for (const Case& k : cases) {
    DynamicTactileSift<double>::Settings s;
    s.sp = k.sp;
    s.dn = k.dn;
    s.upsample = k.upsample;
    s.spatial = k.spatial;
    s.window_sigma = k.window_sigma;
    s.soft_orientation = k.soft;
    const DynamicTactileSift<double> sift(s);
    for (ContactShape shape : test::kAllShapes) {
      const Eigen::MatrixXd p = test::synthetic_contact(shape, rng);
      const Eigen::VectorXd f = sift.compute(TactileImage(p));
      const Eigen::VectorXd lr = sift.compute(TactileImage(mirror_columns(p)));
      const Eigen::VectorXd tb = sift.compute(TactileImage(mirror_rows(p)));
      double worst_lr = 0.0, worst_tb = 0.0;
      for (int i = 0; i < k.sp; ++i) {
        for (int j = 0; j < k.sp; ++j) {
          for (int b = 0; b < k.dn; ++b) {
            const double original = f[sift_index(k.sp, k.dn, i, j, b)];
            worst_lr = std::max(worst_lr, std::abs(lr[sift_index(k.sp, k.dn, i, k.sp - 1 - j, wrap(k.dn / 2 - b, k.dn))] - original));
            worst_tb = std::max(worst_tb, std::abs(tb[sift_index(k.sp, k.dn, k.sp - 1 - i, j, wrap(-b, k.dn))] - original));
          }
        }
      }
      CAPTURE(k.sp);
      CAPTURE(k.dn);
      CAPTURE(k.upsample);
      CAPTURE(k.soft);
      CHECK(worst_lr < 1e-9);
      CHECK(worst_tb < 1e-9);
      // ...and the mirror is not trivially equal to the original.
      if (shape == ContactShape::Corner) CHECK((lr - f).cwiseAbs().maxCoeff() > 1e-3);
    }
  }
}

TEST_CASE("Tactile-SIFT: soft binning varies smoothly as a contact moves") {
  // A blob moving by a tenth of a taxel changes the descriptor a little.
  Eigen::MatrixXd a(14, 6), b(14, 6);
  for (Index r = 0; r < 14; ++r) {
    for (Index c = 0; c < 6; ++c) {
      const double dy = static_cast<double>(r) - 6.0, dx = static_cast<double>(c) - 2.3;
      a(r, c) = 3000.0 * std::exp(-(dx * dx + dy * dy) / 2.0);
      b(r, c) = 3000.0 * std::exp(-((dx - 0.1) * (dx - 0.1) + dy * dy) / 2.0);
    }
  }
  const TactileSift<double> sift;
  CHECK((sift.compute(TactileImage(a)) - sift.compute(TactileImage(b))).norm() < 0.1);
}

// ---------------------------------------------------------------------------
TEST_CASE("raw pressures: row-major order, normalisation, fixed grid") {
  Eigen::MatrixXd p(2, 3);
  p << 0, 1, 2,  //
      3, 4, 5;
  RawPressures<double>::Settings none;
  none.normalization = PressureNormalization::None;
  const Eigen::VectorXd f = RawPressures<double>(none).compute(TactileImage(p));
  REQUIRE(f.size() == 6);
  for (Index i = 0; i < 6; ++i) CHECK(f[i] == static_cast<double>(i));
  const auto unit = RawPressures<float>().compute(TactileImage(p));
  CHECK(unit.norm() == doctest::Approx(1.0f));
  CHECK(RawPressures<float>().compute(TactileImage(2.0 * p)).isApprox(unit));

  static_assert(RawPressures<float, 14, 6>::kLength == 84);
  Rng rng(5);
  const TactileImage wts(test::synthetic_contact(ContactShape::Ridge, rng));
  CHECK(RawPressures<float, 14, 6>().compute(wts).size() == 84);
  CHECK_THROWS_AS((RawPressures<float, 14, 6>().compute(TactileImage(p))), DimensionMismatch);
  CHECK(RawPressures<float>().compute(TactileImage(Eigen::MatrixXd::Zero(14, 6))).isZero(0.0f));
  RawPressures<float>::Settings bad;
  bad.full_scale = -1;
  CHECK_THROWS_AS(RawPressures<float>{bad}, InvalidArgument);
}

// ---------------------------------------------------------------------------
TEST_CASE("moments: a single taxel") {
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(14, 6);
  p(3, 1) = 700.0;
  const ImageMoments m = compute_moments(TactileImage(p));
  CHECK(m.total == 700.0);
  CHECK(m.centroid.x() == doctest::Approx(1.0 - 2.5));
  CHECK(m.centroid.y() == doctest::Approx(3.0 - 6.5));
  CHECK(m.mu20 == 0.0);
  CHECK(m.mu02 == 0.0);
  CHECK(m.mu11 == 0.0);
  CHECK(m.orientation == 0.0);
  for (double h : m.hu) CHECK(h == 0.0);
}

TEST_CASE("moments: pressures at the ends of the double range keep the centroid and the invariants") {
  // Two taxels at 1e308 overflowed the total to inf and the centroid to NaN;
  // a single subnormal taxel rounded the centroid off by half a taxel.
  Eigen::MatrixXd bar = Eigen::MatrixXd::Zero(14, 6);
  bar(3, 1) = bar(3, 2) = bar(4, 1) = 1.0;
  const ImageMoments ref = compute_moments(TactileImage(bar));
  for (const double scale : {1e308, 1e-320}) {
    CAPTURE(scale);
    const ImageMoments m = compute_moments(TactileImage(bar * scale));
    CHECK(m.centroid.isApprox(ref.centroid, 1e-12));
    CHECK(m.mu20 == doctest::Approx(ref.mu20));
    CHECK(m.mu11 == doctest::Approx(ref.mu11));
    for (std::size_t k = 0; k < 7; ++k) CHECK(m.hu[k] == doctest::Approx(ref.hu[k]).epsilon(1e-9));
  }
  // The total is the sum where a double holds it, infinite only beyond.
  CHECK(compute_moments(TactileImage(bar * 1e307)).total == doctest::Approx(3e307));
  CHECK(std::isinf(compute_moments(TactileImage(bar * 1e308)).total));
  Eigen::MatrixXd tiny = Eigen::MatrixXd::Zero(14, 6);
  tiny(3, 1) = 5e-324;
  const ImageMoments t = compute_moments(TactileImage(tiny));
  CHECK(t.centroid.x() == 1.0 - 2.5);
  CHECK(t.centroid.y() == 3.0 - 6.5);
  CHECK(t.total == 5e-324);
  CHECK(t.mu20 == 0.0);
  // The descriptor's mean pressure is finite where the total is not (it
  // was inf, and extract_features then refused the feature).
  MomentsDescriptor<double> moments;
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(2, 2);
  full << 1e308, 1e308, 1e308, 0;
  CHECK(moments.compute(TactileImage(full))[0] == doctest::Approx(7.5e307 / 4095.0));
  // and non-zero where full_scale * size is beyond a double.
  MomentsDescriptor<double> wide({1e307});
  CHECK(wide.compute(TactileImage(bar))[0] == doctest::Approx(3.0 / 84.0 / 1e307));
}

TEST_CASE("moments: a contact with no preferred axis has orientation 0, whatever the rounding") {
  // Plus-shaped contacts are 4-fold symmetric; rounding left mu20 - mu02 or
  // mu11 a few ulps from 0 and the angle at +-pi/2 or -pi/4 for 20 of these.
  int checked = 0;
  for (Index r0 = 1; r0 < 13; ++r0)
    for (Index c0 = 1; c0 < 5; ++c0)
      for (const double v : {1.0, 3.0, 7.3, 0.1, 4095.0}) {
        Eigen::MatrixXd p = Eigen::MatrixXd::Zero(14, 6);
        p(r0, c0) = v;
        p(r0 - 1, c0) = p(r0 + 1, c0) = p(r0, c0 - 1) = p(r0, c0 + 1) = 0.3 * v;
        CAPTURE(r0);
        CAPTURE(c0);
        CAPTURE(v);
        CHECK(compute_moments(TactileImage(p)).orientation == 0.0);
        ++checked;
      }
  CHECK(checked == 240);
  // A slightly longer arm has an axis again.
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(14, 6);
  p(5, 2) = 1;
  p(4, 2) = p(6, 2) = 0.31;
  p(5, 1) = p(5, 3) = 0.3;
  CHECK(compute_moments(TactileImage(p)).orientation == doctest::Approx(kPi / 2));
}

TEST_CASE("moments: bars give the expected centroid and orientation") {
  Eigen::MatrixXd row_bar = Eigen::MatrixXd::Zero(14, 6);
  row_bar.row(5).setConstant(1000.0);
  const ImageMoments h = compute_moments(TactileImage(row_bar));
  CHECK(h.centroid.x() == doctest::Approx(0.0));
  CHECK(h.centroid.y() == doctest::Approx(5.0 - 6.5));
  CHECK(h.mu20 == doctest::Approx(35.0 / 12.0));  // variance of -2.5..2.5
  CHECK(h.mu02 == doctest::Approx(0.0));
  CHECK(h.orientation == doctest::Approx(0.0));

  Eigen::MatrixXd col_bar = Eigen::MatrixXd::Zero(14, 6);
  col_bar.col(2).setConstant(1000.0);
  const ImageMoments v = compute_moments(TactileImage(col_bar));
  CHECK(v.centroid.x() == doctest::Approx(2.0 - 2.5));
  CHECK(v.centroid.y() == doctest::Approx(0.0));
  CHECK(v.mu02 == doctest::Approx((14.0 * 14.0 - 1.0) / 12.0));
  CHECK(v.orientation == doctest::Approx(kPi / 2));  // (-pi/2, pi/2]: +pi/2, not -pi/2

  Eigen::MatrixXd diagonal = Eigen::MatrixXd::Zero(6, 6);
  Eigen::MatrixXd anti = Eigen::MatrixXd::Zero(6, 6);
  for (Index i = 0; i < 6; ++i) {
    diagonal(i, i) = 500.0;
    anti(i, 5 - i) = 500.0;
  }
  CHECK(compute_moments(TactileImage(diagonal)).orientation == doctest::Approx(kPi / 4));
  CHECK(compute_moments(TactileImage(anti)).orientation == doctest::Approx(-kPi / 4));
}

TEST_CASE("moments: Hu invariants survive a 90-degree rotation and a pressure scaling") {
  Rng rng(6);
  for (ContactShape shape : test::kAllShapes) {
    const Eigen::MatrixXd p = test::synthetic_contact(shape, rng, 8, 8);
    const ImageMoments a = compute_moments(TactileImage(p));
    const ImageMoments b = compute_moments(TactileImage(rotate90(p)));
    const ImageMoments c = compute_moments(TactileImage(p * 3.5));
    for (std::size_t i = 0; i < 7; ++i) {
      CAPTURE(i);
      const double tol = 1e-9 * std::max(1.0, std::abs(a.hu[i]));
      CHECK(std::abs(a.hu[i] - b.hu[i]) <= tol);
      CHECK(std::abs(a.hu[i] - c.hu[i]) <= tol);
    }
    // Rotation swaps the variances and turns the orientation by 90 degrees.
    CHECK(b.mu20 == doctest::Approx(a.mu02));
    CHECK(b.mu02 == doctest::Approx(a.mu20));
  }
  // A non-trivial invariant is not constant: a bar and a blob differ.
  Eigen::MatrixXd bar = Eigen::MatrixXd::Zero(8, 8);
  bar.row(2).setConstant(100.0);
  Eigen::MatrixXd blob = Eigen::MatrixXd::Zero(8, 8);
  blob.block(3, 3, 2, 2).setConstant(100.0);
  CHECK(compute_moments(TactileImage(bar)).hu[1] > compute_moments(TactileImage(blob)).hu[1] + 0.1);
}

TEST_CASE("moments descriptor: layout, blank image, invariance") {
  static_assert(MomentsDescriptor<float>::kLength == 15);
  const MomentsDescriptor<double> moments;
  CHECK(moments.compute(TactileImage(Eigen::MatrixXd::Zero(14, 6))).isZero(0.0));

  Eigen::MatrixXd bar = Eigen::MatrixXd::Zero(14, 6);
  bar.col(1).setConstant(4095.0);
  const auto f = moments.compute(TactileImage(bar));
  CHECK(f[0] == doctest::Approx(14.0 / 84.0));      // mean pressure / full scale
  CHECK(f[1] == doctest::Approx((1.0 - 2.5) / 14.0));  // centroid x / longer side
  CHECK(f[6] == doctest::Approx(-1.0));             // a line along y: anisotropy (-1, 0)
  CHECK(f[7] == doctest::Approx(0.0));

  Rng rng(7);
  for (ContactShape shape : test::kAllShapes) {
    const Eigen::MatrixXd p = test::synthetic_contact(shape, rng);
    const auto a = moments.compute(TactileImage(p));
    const auto b = moments.compute(TactileImage(p * 0.25));
    CHECK(all_finite(a));
    CHECK(b[0] == doctest::Approx(a[0] * 0.25));
    CHECK((a.tail(14) - b.tail(14)).cwiseAbs().maxCoeff() < 1e-9);
  }
}

// The compressed entries are sign(h) * log(1 + |h|^(1/d)) of the raw
// invariants, d = 1, 2, 2, 2, 4, 3, 4, so they keep the invariants' order and
// signs: entry 14 (hu[6]) changes sign under mirroring, the others stay.
TEST_CASE("moments descriptor: the Hu entries are the invariants compressed by their degree") {
  const MomentsDescriptor<double> moments;
  const int degree[7] = {1, 2, 2, 2, 4, 3, 4};
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(14, 6);
  p(2, 1) = 4000.0;
  p(3, 1) = 2500.0;
  p(3, 2) = 1200.0;
  p(9, 4) = 700.0;
  p(12, 0) = 300.0;
  const ImageMoments m = compute_moments(TactileImage(p));
  const auto f = moments.compute(TactileImage(p));
  const auto mirrored = moments.compute(TactileImage(Eigen::MatrixXd(p.rowwise().reverse())));
  for (int i = 0; i < 7; ++i) {
    const double h = m.hu[static_cast<std::size_t>(i)];
    const double expected = std::copysign(std::log1p(std::pow(std::abs(h), 1.0 / degree[i])), h);
    INFO("hu[" << i << "] = " << h);
    CHECK(f[8 + i] == doctest::Approx(expected).epsilon(1e-12));
    if (i < 6) CHECK(mirrored[8 + i] == doctest::Approx(f[8 + i]).epsilon(1e-9));
  }
  CHECK(std::abs(m.hu[6]) > 1e-6);  // the case is chiral, so the sign test below means something
  CHECK(mirrored[14] == doctest::Approx(-f[14]).epsilon(1e-9));
}

// ---------------------------------------------------------------------------
namespace {

/// A user descriptor: where the peak is and how spread the contact is.
struct PeakDescriptor {
  Eigen::Matrix<float, 3, 1> compute(const TactileImage& image) const {
    Index r = 0, c = 0;
    const double peak = image.pressures().maxCoeff(&r, &c);
    const double spread = peak > 0 ? static_cast<double>(image.count_above(0.5 * peak)) / static_cast<double>(image.size()) : 0.0;
    return {static_cast<float>(r) / static_cast<float>(image.rows()),
            static_cast<float>(c) / static_cast<float>(image.cols()), static_cast<float>(spread)};
  }
};
struct NoCompute {};
struct ReturnsStdVector {
  std::vector<float> compute(const TactileImage&) const { return {}; }
};
struct ReturnsIntVector {
  Eigen::VectorXi compute(const TactileImage&) const { return {}; }
};
struct NonConstCompute {
  Eigen::VectorXf compute(const TactileImage&) { return {}; }
};
struct NaNDescriptor {
  Eigen::Vector2d compute(const TactileImage& image) const {
    return {image.max() > 100 ? std::numeric_limits<double>::quiet_NaN() : 0.0, 1.0};
  }
};
struct VaryingLength {
  Eigen::VectorXd compute(const TactileImage& image) const { return Eigen::VectorXd::Zero(image.rows()); }
};

// Refuses images of 8 rows with a derived error about its "image".
struct RefusesEightRows {
  Eigen::VectorXd compute(const TactileImage& image) const {
    if (image.rows() == 8) throw EmptyInput("image", "has eight rows");
    return Eigen::VectorXd::Zero(2);
  }
};

}  // namespace

TEST_CASE("descriptor concept: shipped and user types model it, others do not") {
  static_assert(is_descriptor_v<TactileSift<>>);
  static_assert(is_descriptor_v<DynamicTactileSift<double>>);
  static_assert(is_descriptor_v<RawPressures<float, 14, 6>>);
  static_assert(is_descriptor_v<MomentsDescriptor<double>>);
  static_assert(is_descriptor_v<PeakDescriptor>);
  static_assert(!is_descriptor_v<NoCompute>);
  static_assert(!is_descriptor_v<ReturnsStdVector>);
  static_assert(!is_descriptor_v<ReturnsIntVector>);
  static_assert(!is_descriptor_v<NonConstCompute>);
  static_assert(!is_descriptor_v<int>);
  static_assert(DescriptorTraits<PeakDescriptor>::length == 3);
  static_assert(std::is_same_v<FeaturesOf<TactileSift<>>, Cloud<float, 72>>);
  static_assert(std::is_same_v<FeaturesOf<DynamicTactileSift<double>>, Cloud<double, Eigen::Dynamic>>);
  CHECK(true);  // the checks above are compile-time
}

TEST_CASE("extract_features: one column per image, in order, with typed errors") {
  Rng rng(8);
  std::vector<TactileImage> images;
  for (int i = 0; i < 10; ++i) images.emplace_back(test::synthetic_contact(test::kAllShapes[i % 5], rng));
  const Cloud<float, 72> sift = extract_features(TactileSift<>(), images);
  REQUIRE(sift.cols() == 10);
  for (Index j = 0; j < 10; ++j) CHECK(sift.col(j) == TactileSift<>().compute(images[static_cast<std::size_t>(j)]));
  const auto peaks = extract_features(PeakDescriptor(), images);
  CHECK(peaks.rows() == 3);

  CHECK_THROWS_AS(extract_features(TactileSift<>(), std::vector<TactileImage>()), EmptyInput);
  try {
    extract_features(NaNDescriptor(), images);
    FAIL("NaN feature accepted");
  } catch (const NonFiniteValue& e) {
    CHECK(e.argument() == "features");
    CHECK(e.row() == 0);
    CHECK(e.column() == 0);
  }
  std::vector<TactileImage> mixed{TactileImage(Eigen::MatrixXd::Zero(14, 6)), TactileImage(Eigen::MatrixXd::Zero(8, 8))};
  CHECK_THROWS_AS(extract_features(VaryingLength(), mixed), DimensionMismatch);

  // A descriptor's refusal of one image names that image's index.
  TactileSift<>::Settings raw;
  raw.normalization = SiftNormalization::None;
  std::vector<TactileImage> huge = images;
  huge[7] = TactileImage(images[7].pressures() * 1e300);
  try {
    extract_features(TactileSift<>(raw), huge);
    FAIL("float histograms beyond the range of float accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "images[7]");
    CHECK(std::string(e.what()).find("images[7]: the raw (SiftNormalization::None) histograms") == 0);
  }
  // Derived errors of a descriptor keep their type and reason, and name the
  // image too.
  CHECK_THROWS_WITH_AS(extract_features(RefusesEightRows(), mixed), "images[1]: has eight rows", EmptyInput);
}

// ---------------------------------------------------------------------------
TEST_CASE("Tactile-SIFT: each setting is accepted at the ends of its documented range and refused past them") {
  using Settings = DynamicTactileSift<float>::Settings;
  const auto refusal = [](const Settings& s) { return test::argument_of([&] { (void)DynamicTactileSift<float>(s); }); };
  Settings s;
  s.upsample = 16;
  CHECK(refusal(s) == "(no error)");
  s.upsample = 17;
  CHECK(refusal(s) == "settings.upsample");
  s = {};
  s.box_overlap = 0.0;
  CHECK(refusal(s) == "(no error)");
  s.box_overlap = -0.01;
  CHECK(refusal(s) == "settings.box_overlap");
  s = {};
  s.clip = 1.0;
  CHECK(refusal(s) == "(no error)");
  s = {};
  s.window_sigma = std::numeric_limits<double>::infinity();
  CHECK(refusal(s) == "settings.window_sigma");
  // A type that fixes dn = 8 refuses another dn, as it refuses another sp.
  TactileSift<>::Settings fixed;
  fixed.dn = 4;
  CHECK(test::argument_of([&] { (void)TactileSift<>(fixed); }) == "settings.dn");
}

TEST_CASE("Tactile-SIFT: without soft orientation each gradient goes wholly to its nearest bin, 2 pi to bin 0") {
  // Ramps rising at 44 and -10 degrees. Every gradient, also where a
  // replicated border halves one component (62.6 or 25.8 degrees; -19.4 or
  // -5), is nearest bin 1 (45 degrees), resp. bin 0 (wrapped from 2 pi).
  struct Ramp {
    double degrees;
    int bin;
  };
  TactileSift<double>::Settings hard;
  hard.soft_orientation = false;
  const TactileSift<double> sift(hard);
  for (const Ramp& ramp : {Ramp{44.0, 1}, Ramp{-10.0, 0}}) {
    const double angle = ramp.degrees * kPi / 180.0;
    Eigen::MatrixXd p(14, 6);
    for (Index r = 0; r < 14; ++r)
      for (Index c = 0; c < 6; ++c)
        p(r, c) = 2000.0 + 100.0 * (std::cos(angle) * static_cast<double>(c) + std::sin(angle) * static_cast<double>(r));
    const auto f = sift.compute(TactileImage(p));
    CAPTURE(ramp.degrees);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int b = 0; b < 8; ++b) CHECK((f[sift_index(3, 8, i, j, b)] > 0.0) == (b == ramp.bin));
  }
}

TEST_CASE("Tactile-SIFT: box binning with overlap 0.5 gives a box 1.5 cells, 3 taxels, including its border taxels") {
  // Pressure rising down column 2 only: the gradients there point along +y
  // (bin 2); columns 1 and 3 have only +-x gradients. On 6 columns with
  // sp = 3 a cell is 2 taxels wide; column 2's centre (2.5) is 0.75 cell
  // widths from cell 0's centre (1), exactly on the border of its box
  // with overlap 0.5 and outside it with overlap 0.
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(14, 6);
  for (Index r = 0; r < 14; ++r) p(r, 2) = 100.0 * static_cast<double>(r + 1);
  const auto bin2_in_column = [](const Eigen::VectorXd& f, int j) {
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) sum += f[sift_index(3, 8, i, j, 2)];
    return sum;
  };
  TactileSift<double>::Settings box;
  box.spatial = SiftSpatialBinning::Box;
  const Eigen::VectorXd half = TactileSift<double>(box).compute(TactileImage(p));
  CHECK(bin2_in_column(half, 0) > 0.0);
  CHECK(bin2_in_column(half, 1) > 0.0);
  CHECK(bin2_in_column(half, 2) == 0.0);
  box.box_overlap = 0.0;  // boxes 1 cell wide: column 2 is cell 1's only
  const Eigen::VectorXd none = TactileSift<double>(box).compute(TactileImage(p));
  CHECK(bin2_in_column(none, 0) == 0.0);
  CHECK(bin2_in_column(none, 1) > 0.0);
  CHECK(bin2_in_column(none, 2) == 0.0);
}

TEST_CASE("Tactile-SIFT: raw histograms add up the central-difference gradient magnitudes, times the window") {
  // Soft spatial and orientation weights of a gradient add up to 1, so the
  // raw histograms sum to the sum of the gradient magnitudes.
  TactileSift<double>::Settings raw;
  raw.normalization = SiftNormalization::None;
  // Ramp of 100 per column: 100 inside, 50 at the two replicated borders.
  Eigen::MatrixXd ramp(14, 6);
  for (Index r = 0; r < 14; ++r)
    for (Index c = 0; c < 6; ++c) ramp(r, c) = 50.0 + 100.0 * static_cast<double>(c);
  CHECK(TactileSift<double>(raw).compute(TactileImage(ramp)).sum() == doctest::Approx(14.0 * (4 * 100.0 + 2 * 50.0)));
  // One pressed taxel at (3, 1): four gradients of 500 beside it, each
  // weighted by the window, a Gaussian per axis centred on the pad with
  // sigma = window_sigma times the pad's extent on that axis (6 and 14).
  raw.window_sigma = 0.3;
  const auto weight = [](double centre_offset, double sigma) { return std::exp(-0.5 * std::pow(centre_offset / sigma, 2)); };
  const auto window = [&](Index row, Index col) {
    return weight(static_cast<double>(col) + 0.5 - 3.0, 0.3 * 6.0) * weight(static_cast<double>(row) + 0.5 - 7.0, 0.3 * 14.0);
  };
  const double expected = 500.0 * (window(3, 0) + window(3, 2) + window(2, 1) + window(4, 1));
  CHECK(TactileSift<double>(raw).compute(TactileImage(single_taxel(3, 1, 1000.0))).sum() == doctest::Approx(expected));
}

TEST_CASE("Tactile-SIFT: L2Clip clips at settings.clip; clip = 1 is plain L2") {
  const TactileImage image(single_taxel(5, 2, 3000.0));
  TactileSift<double>::Settings l2;
  l2.normalization = SiftNormalization::L2;
  const Eigen::VectorXd v = TactileSift<double>(l2).compute(image);
  REQUIRE(v.maxCoeff() > 0.35);  // so every clip below changes it
  for (const double clip : {0.1, 0.35, 1.0}) {
    CAPTURE(clip);
    TactileSift<double>::Settings clipped;
    clipped.clip = clip;
    Eigen::VectorXd expected = v.cwiseMin(clip);
    expected /= expected.norm();
    CHECK((TactileSift<double>(clipped).compute(image) - expected).cwiseAbs().maxCoeff() < 1e-12);
  }
}

TEST_CASE("moments: a contact along one row has Hu invariants worked out by hand") {
  // Taxels 2, 0, 1 at x = -1, 0, 1; scaled to a peak of 1: m00 = 1.5,
  // centroid -1/3, mu20 = 4/3, mu30 = 8/9, nothing along y. With
  // eta20 = mu20 / m00^2 and eta30 = mu30 / m00^2.5, Hu's invariants reduce
  // to eta20, eta20^2, eta30^2, eta30^2, eta30^4, eta20 eta30^2 and 0.
  Eigen::MatrixXd p(1, 3);
  p << 2.0, 0.0, 1.0;
  const ImageMoments m = compute_moments(TactileImage(p));
  const double eta20 = (4.0 / 3.0) / std::pow(1.5, 2.0);
  const double eta30 = (8.0 / 9.0) / std::pow(1.5, 2.5);
  const double expected[7] = {eta20, eta20 * eta20, eta30 * eta30, eta30 * eta30, std::pow(eta30, 4), eta20 * eta30 * eta30, 0.0};
  for (std::size_t i = 0; i < 7; ++i) {
    CAPTURE(i);
    CHECK(m.hu[i] == doctest::Approx(expected[i]).epsilon(1e-12));
  }
}

TEST_CASE("moments: the descriptor's second-moment entries and the first two Hu invariants from the moments") {
  // A diagonal line: mu20 = mu11 = mu02, anisotropy (0, 1) (a line, at 45
  // degrees), the moments divided by the area of the 6 x 6 grid.
  Eigen::MatrixXd diagonal = Eigen::MatrixXd::Zero(6, 6);
  for (Index i = 0; i < 6; ++i) diagonal(i, i) = 500.0;
  const ImageMoments d = compute_moments(TactileImage(diagonal));
  const auto f = MomentsDescriptor<double>().compute(TactileImage(diagonal));
  CHECK(f[3] == doctest::Approx(d.mu20 / 36.0));
  CHECK(f[4] == doctest::Approx(d.mu11 / 36.0));
  CHECK(f[5] == doctest::Approx(d.mu02 / 36.0));
  CHECK(f[6] == doctest::Approx(0.0));
  CHECK(f[7] == doctest::Approx(1.0));
  // hu[0] and hu[1] of any contact from its moments (eta_pq = mu_pq / m00^2
  // for the image scaled to a peak of 1, whose m00 is total / peak).
  Rng rng(10);
  for (ContactShape shape : test::kAllShapes) {
    const Eigen::MatrixXd p = test::synthetic_contact(shape, rng);
    const ImageMoments m = compute_moments(TactileImage(p));
    const double m00 = m.total / p.maxCoeff();
    CHECK(m.hu[0] == doctest::Approx((m.mu20 + m.mu02) / m00).epsilon(1e-12));
    CHECK(m.hu[1] == doctest::Approx((std::pow(m.mu20 - m.mu02, 2) + 4.0 * m.mu11 * m.mu11) / (m00 * m00)).epsilon(1e-12));
  }
}

namespace {
struct EmptyFeature {
  Eigen::VectorXf compute(const TactileImage&) const { return {}; }
};
}  // namespace

TEST_CASE("bad input names the argument: pressures, threshold, a fixed raw-pressures grid, an empty feature") {
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(14, 6);
  p(2, 4) = -0.5;
  CHECK(test::argument_of([&] { TactileImage bad(p, "frames[3].pressures"); }) == "frames[3].pressures");
  p(2, 4) = 40.0;
  const TactileImage image(p);
  CHECK(test::argument_of([&] { (void)is_contact(image, std::numeric_limits<double>::infinity()); }) == "threshold");
  const RawPressures<float, 14, 6> wts;
  CHECK(test::argument_of([&] { (void)wts.compute(TactileImage(Eigen::MatrixXd::Zero(14, 5))); }) == "image.cols");
  CHECK(test::argument_of([&] { (void)wts.compute(TactileImage(Eigen::MatrixXd::Zero(13, 6))); }) == "image.rows");
  CHECK_THROWS_WITH_AS(extract_features(EmptyFeature(), std::vector<TactileImage>{image}),
                       "features: descriptor returned an empty feature for images[0]", EmptyInput);
}

// ---------------------------------------------------------------------------
// Audit (session 50): defects found from a user's side, fixed since.

namespace {
/// True when `f` threw an InvalidArgument naming "image" (a refusal of the
/// image, as Tactile-SIFT's raw histograms beyond the feature type), false
/// when it returned `out`.
template <typename Feature, typename F>
bool refused_image(F&& f, Feature& out) {
  try {
    out = f();
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "image");
    return true;
  }
  return false;
}
}  // namespace

TEST_CASE("raw pressures: a feature beyond the range of the feature type is refused naming the image, never inf") {
  // raw_pressures.hpp compute(): image(r, c) * factor is cast to Scalar with
  // no check, so pressures the feature type cannot hold came out as inf
  // (Tactile-SIFT refuses its raw histograms there, naming "image").
  RawPressures<float>::Settings none;
  none.normalization = PressureNormalization::None;
  const TactileImage huge(Eigen::MatrixXd::Constant(2, 3, 1e39));  // finite double, beyond float
  Eigen::VectorXf f;
  const bool refused_float = refused_image([&] { return RawPressures<float>(none).compute(huge); }, f);
  CHECK((refused_float || all_finite(f)));
  // FullScale with a small (valid: finite reciprocal) full scale: 1e20 / 1e-300
  // is beyond a double.
  RawPressures<double>::Settings scaled;
  scaled.normalization = PressureNormalization::FullScale;
  scaled.full_scale = 1e-300;
  Eigen::VectorXd g;
  const bool refused_double =
      refused_image([&] { return RawPressures<double>(scaled).compute(TactileImage(Eigen::MatrixXd::Constant(2, 3, 1e20))); }, g);
  CHECK((refused_double || all_finite(g)));
}

TEST_CASE("moments descriptor: a mean pressure beyond the range of the feature type is refused naming the image, never inf") {
  // moments.hpp compute(): f[0] = total / (full_scale * size) is finite in
  // double but cast to float it became inf; and with a small full_scale it
  // overflows in double too (mean_over_full_scale says its result "is
  // finite").
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(14, 6);
  p(3, 2) = 1e300;
  Eigen::Matrix<float, 15, 1> f;
  const bool refused_float = refused_image([&] { return MomentsDescriptor<float>().compute(TactileImage(p)); }, f);
  CHECK((refused_float || all_finite(f)));
  MomentsDescriptor<double>::Settings small;
  small.full_scale = 1e-300;
  p(3, 2) = 1e20;
  Eigen::Matrix<double, 15, 1> g;
  const bool refused_double = refused_image([&] { return MomentsDescriptor<double>(small).compute(TactileImage(p)); }, g);
  CHECK((refused_double || all_finite(g)));
}

TEST_CASE("Tactile-SIFT: a narrow Gaussian window does not turn a contact into the zero vector") {
  // tactile_sift.hpp: window_sigma = 0.001 is accepted (finite, >= 0), but
  // every weight exp(-z^2 / 2) underflows to 0 (z >= 0.5 / (0.001 * 6) = 83
  // on a 6-column pad), so a pressed pad gave the zero vector, which the
  // class promises only for a blank or uniform image. Either the setting is
  // refused, or the normalised descriptor is that of the gradients nearest
  // the centre.
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(14, 6);
  p.block(5, 2, 3, 2).setConstant(1000.0);
  TactileSift<double>::Settings narrow;
  narrow.window_sigma = 0.001;
  std::string refused = "(no error)";
  Eigen::Matrix<double, 72, 1> f = Eigen::Matrix<double, 72, 1>::Zero();
  try {
    f = TactileSift<double>(narrow).compute(TactileImage(p));
  } catch (const InvalidArgument& e) {
    refused = e.argument();
  }
  CAPTURE(refused);
  CHECK((refused == "settings.window_sigma" || f.norm() == doctest::Approx(1.0)));
  // The narrowest window allowed keeps the contact (the gradients are there).
  narrow.window_sigma = TactileSift<double>::kMinWindowSigma;
  CHECK(TactileSift<double>(narrow).compute(TactileImage(p)).norm() == doctest::Approx(1.0));
}

TEST_CASE("Tactile-SIFT: settings whose length sp * sp * dn overflows an Index are refused naming the setting") {
  // tactile_sift.hpp: the constructor checks sp >= 1 and dn >= 1 only, and
  // length() computes Index(sp) * sp * dn, which for sp = dn = INT_MAX is
  // about 2^93: signed overflow (UB; UBSan: "signed integer overflow"), a
  // garbage length, then a failed allocation in compute().
  DynamicTactileSift<float>::Settings s;
  s.sp = std::numeric_limits<int>::max();
  s.dn = std::numeric_limits<int>::max();
  const std::string refused = test::argument_of([&] { (void)DynamicTactileSift<float>(s); });
  CHECK((refused == "settings.sp" || refused == "settings.dn"));
}

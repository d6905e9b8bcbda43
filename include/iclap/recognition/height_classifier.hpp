// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/recognition/classifier.hpp"
#include "iclap/search/adaptive.hpp"

namespace iclap {

/// The two coordinates of a pad pose that no planar motion of the object
/// changes (beyond the paper): the pad centre's height z, and the tilt of
/// the pad normal n from straight down, theta = atan2(|n_xy|, -n_z) in
/// [0, pi] (0: pressing a top face, pi/2: a vertical side). An object lying
/// on a table and put down again with a shift and a turn about the vertical
/// (the scene of the `Planar` model) keeps both for every touch.
inline Eigen::Vector2d height_and_tilt(const Eigen::Vector3d& position, const Eigen::Vector3d& normal) {
  return {position.z(), std::atan2(normal.head<2>().norm(), -normal.z())};
}

/// The size of a touch's contact patch (beyond the paper): the standard
/// deviations of `points` (metres) along their two principal axes, largest
/// first; (0, 0) for fewer than two points. The contact points of a touch
/// are the pressed taxels placed by the pad's pose (TouchSet), so they lie in
/// the pad plane and the two axes are the patch's length and width: a full
/// flat contact, a line along an edge or a thin handle, a partial patch where
/// the pad overhangs. Any rigid motion of the points leaves them unchanged.
///
/// Points beyond 1e300 in magnitude are measured scaled to unit magnitude,
/// and points spread beyond 1e100 or within 1e-100 (whose covariance would
/// overflow to NaN or underflow to 0) are scaled to unit spread first; the
/// extents are scaled back. Others are computed as they are. Needs finite
/// points (NonFiniteValue naming "points").
inline Eigen::Vector2d contact_extents(const Eigen::Ref<const Eigen::Matrix3Xd>& points) {
  check_finite(points, "points");
  if (points.cols() < 2) return Eigen::Vector2d::Zero();
  // Points of any finite magnitude: near the largest double both their sum
  // and a point's distance from their mean can overflow, so such points are
  // measured at unit magnitude and their extents (at most that magnitude)
  // scaled back.
  const double magnitude = points.cwiseAbs().maxCoeff();
  if (magnitude > 1e300) return Eigen::Vector2d(contact_extents(points / magnitude) * magnitude);
  Eigen::Matrix3Xd centred = points.colwise() - Eigen::Vector3d(points.rowwise().mean());
  const double spread = centred.cwiseAbs().maxCoeff();
  if (spread == 0) return Eigen::Vector2d::Zero();
  const bool rescale = spread > 1e100 || spread < 1e-100;
  if (rescale) centred /= spread;
  const Eigen::Matrix3d covariance = centred * centred.transpose() / static_cast<double>(points.cols());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d& v = eigen.eigenvalues();  // ascending
  const Eigen::Vector2d extents(std::sqrt(std::max(0.0, v(2))), std::sqrt(std::max(0.0, v(1))));
  return rescale ? Eigen::Vector2d(extents * spread) : extents;
}

/// Registration-free kinesthetic recognition (beyond the paper): each touch
/// is the point (z, s theta) of its pose invariants (`height_and_tilt`, s =
/// `tilt_scale` metres per radian), and the distance from a test set to an
/// object is the sum over test touches of the squared distance to the
/// object's closest training touch:
///
///   E_height = sum_i min_q [ (z_i - z_q)^2 + s^2 (theta_i - theta_q)^2 ].
///
/// This is the paper's point-to-point error (Section IV, E_ICP) restricted to
/// the coordinates a planar motion cannot change, so it needs no
/// registration and no overlap between the test touches and the training
/// touches along the table: a sparse exploration that slid over surface the
/// references never saw still lands at heights and tilts they did see. It
/// cannot tell apart objects with the same heights and slopes, and it
/// assumes the planar scene (the table plane fixed in the rig frame between
/// training and test). Each object's invariants sit in a search structure
/// (AdaptiveSearch: brute force up to 2048 coordinates, i.e. 1024 touches
/// without the contact patch and 512 with it, a kd-tree above) built once
/// per fit, so a distance costs one nearest-point query
/// per test touch and object.
///
/// With `contact_scale` c > 0 each touch also carries the size of its
/// contact patch, (l_1, l_2) = `contact_extents` of its contact points, which
/// no motion of the object changes either; the point is then
/// (z, s theta, c l_1, c l_2), and the distance
///
///   E_height_contact = sum_i min_q [ (z_i - z_q)^2 + s^2 (theta_i - theta_q)^2
///                                    + c^2 ((l1_i - l1_q)^2 + (l2_i - l2_q)^2) ]
///
/// tells a thin handle from a broad face at the same height and slope, and
/// a pad overhanging a small face from one resting on a large face. With
/// c = 1 a millimetre of patch size counts as much as a millimetre of
/// height. c = 0 (the default) leaves the contact patch out, and the
/// distances are those of the two-coordinate form to the last bit.
///
/// Needs `TouchSet::normals` (the pad orientation of every touch: dataset
/// columns qw..qz), and with c > 0 `TouchSet::contact_points` (a touch
/// without contact points has extents (0, 0)).
class HeightClassifier final : public Classifier {
 public:
  /// Metres of height that one radian of tilt weighs (1 cm by default, the
  /// library's convention for a unit of a non-spatial axis, as
  /// `DescriptorEmbedding::descriptor_scale`).
  double tilt_scale = 0.01;
  /// Metres of height that one metre of contact-patch extent weighs; 0 (the
  /// default): the contact patch is not used.
  double contact_scale = 0;
  /// The classifier's name in a Recognizer; empty (the default): "height",
  /// or "height_contact" with contact_scale > 0.
  std::string label;

  std::string name() const override {
    if (!label.empty()) return label;
    return contact_scale > 0 ? "height_contact" : "height";
  }

  /// Throws InvalidArgument for a `tilt_scale` that is not finite and > 0 or
  /// a `contact_scale` that is not finite and >= 0, EmptyInput naming
  /// "objects", "objects[j].normals" or "objects[j].contact_points" for no
  /// object or an object without what the classifier needs, and what
  /// TouchSet::validate throws.
  void fit(const std::vector<TouchSet>& objects, Index /*vocabulary*/) override {
    validate();
    if (objects.empty()) throw EmptyInput("objects", "no object to recognise");
    const Scales scales{tilt_scale, contact_scale};
    std::vector<FullSearch> full;
    std::vector<PlaneSearch> plane;
    for (std::size_t j = 0; j < objects.size(); ++j) {
      const Points p = embed(objects[j], "objects[" + std::to_string(j) + "]", scales);
      if (scales.contact > 0)
        full.emplace_back(p);
      else
        plane.emplace_back(p.topRows<2>());
    }
    full_ = std::move(full);
    plane_ = std::move(plane);
    fitted_ = scales;
  }

  /// Uses the scales of the last fit(), whatever they are now. Throws
  /// EmptyInput naming "test.normals" (or "test.contact_points") for a test
  /// without what the classifier needs.
  void distances(const TouchSet& test, Eigen::Ref<Eigen::VectorXd> out) const override {
    check_dimension(out.size(), objects(), "out");
    const Points p = embed(test, "test", fitted_);
    if (fitted_.contact > 0)
      sum_nearest(full_, p, out);
    else
      sum_nearest(plane_, p.topRows<2>(), out);  // each column's first two rows are contiguous
  }

  Index objects() const override { return static_cast<Index>(full_.size() + plane_.size()); }

  void validate() const {
    check_positive(tilt_scale, "tilt_scale");
    check_non_negative(contact_scale, "contact_scale");
  }

  /// The points (z, s theta, c l_1, c l_2) of `touches`, one column per
  /// touch; the last two rows are 0 when contact_scale is 0.
  Eigen::Matrix4Xd embed(const TouchSet& touches, const std::string& argument) const {
    return embed(touches, argument, Scales{tilt_scale, contact_scale});
  }

 private:
  struct Scales {
    double tilt = 0.01, contact = 0;
  };

  Eigen::Matrix4Xd embed(const TouchSet& touches, const std::string& argument, const Scales& scales) const {
    touches.validate(argument);
    if (!touches.has_normals())
      throw EmptyInput(argument + ".normals", "the " + name() +
                                                  " classifier needs the pad orientation of every touch (dataset "
                                                  "columns qw, qx, qy, qz)");
    const bool contacts = scales.contact > 0;
    if (contacts && !touches.has_contacts())
      throw EmptyInput(argument + ".contact_points",
                       "the " + name() + " classifier needs the contact points of the touches (the pressed taxels "
                                         "placed by the pad orientation)");
    Points p = Points::Zero(4, touches.size());
    for (Index i = 0; i < touches.size(); ++i) {
      p.col(i).head<2>() = height_and_tilt(touches.positions.col(i), touches.normals.col(i));
      p(1, i) *= scales.tilt;
      if (contacts) {
        const Index begin = touches.contact_offsets[static_cast<std::size_t>(i)];
        p.col(i).tail<2>() = scales.contact * contact_extents(touches.contact_points.middleCols(begin, touches.contacts_of(i)));
      }
    }
    // The squared distances of the search stay finite (the Classifier
    // contract) only for coordinates within largest_coordinate: a height of
    // 1e160 m, or a scale that blows a tilt or a patch up as far, is refused
    // here, naming the touch and what made the coordinate.
    const auto [row, touch] = find_beyond_range<double>(p);
    if (row >= 0) {
      static const char* const what[] = {".positions (the height z)", ".normals (the tilt times tilt_scale)",
                                         ".contact_points (the patch length times contact_scale)",
                                         ".contact_points (the patch width times contact_scale)"};
      throw InvalidArgument(argument + what[row], "touch " + std::to_string(touch) + " gives " + format_value(p(row, touch)) +
                                                      ", beyond the range of distances (|v| <= " +
                                                      format_value(largest_coordinate<double>()) + ", tilt_scale " +
                                                      format_value(scales.tilt) + ", contact_scale " +
                                                      format_value(scales.contact) + "): squared distances would overflow");
    }
    return p;
  }

  /// out(j) = sum over the columns of `p` of the squared distance to the
  /// nearest point of object j: E_height or E_height_contact above.
  template <typename Search, typename Matrix>
  static void sum_nearest(const std::vector<Search>& searches, const Matrix& p, Eigen::Ref<Eigen::VectorXd> out) {
    for (std::size_t j = 0; j < searches.size(); ++j) {
      double e = 0;
      for (Index i = 0; i < p.cols(); ++i) e += searches[j].nearest(p.col(i).data()).squared_distance;
      out(static_cast<Index>(j)) = e;
    }
  }

  using Points = Eigen::Matrix4Xd;
  // Brute force up to 512 touches per object (2048 coordinates), a kd-tree
  // above. Without the contact patch the points are (z, s theta) only: the
  // 4-D scan with two zero coordinates gives the same sums to the last bit
  // (each adds + 0 twice) but takes 1.24-1.26x as long (bench_recognition,
  // BM_HeightSearch, two runs).
  using FullSearch = AdaptiveSearch<double, 4>;
  using PlaneSearch = AdaptiveSearch<double, 2>;
  std::vector<FullSearch> full_;    // contact_scale > 0 at fit
  std::vector<PlaneSearch> plane_;  // contact_scale == 0 at fit
  Scales fitted_;
};

}  // namespace iclap

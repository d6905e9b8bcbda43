// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

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
/// training and test). Each object's invariants sit in a 2-D search
/// structure (AdaptiveSearch: brute force up to 1024 touches, a kd-tree
/// above) built once per fit, so a distance costs one nearest-point query
/// per test touch and object.
///
/// Needs `TouchSet::normals` (the pad orientation of every touch: dataset
/// columns qw..qz).
class HeightClassifier final : public Classifier {
 public:
  /// Metres of height that one radian of tilt weighs (1 cm by default, the
  /// library's convention for a unit of a non-spatial axis, as
  /// `DescriptorEmbedding::descriptor_scale`).
  double tilt_scale = 0.01;

  std::string name() const override { return "height"; }

  /// Throws InvalidArgument for a `tilt_scale` that is not finite and > 0,
  /// EmptyInput naming "objects" or "objects[j].normals" for no object or an
  /// object without normals, and what TouchSet::validate throws.
  void fit(const std::vector<TouchSet>& objects, Index /*vocabulary*/) override {
    validate();
    if (objects.empty()) throw EmptyInput("objects", "no object to recognise");
    std::vector<AdaptiveSearch<double, 2>> trees;
    trees.reserve(objects.size());
    for (std::size_t j = 0; j < objects.size(); ++j) {
      const std::string name = "objects[" + std::to_string(j) + "]";
      trees.emplace_back(embed(objects[j], name));
    }
    trees_ = std::move(trees);
  }

  /// Throws EmptyInput naming "test.normals" for a test without normals.
  void distances(const TouchSet& test, Eigen::Ref<Eigen::VectorXd> out) const override {
    check_dimension(out.size(), objects(), "out");
    const Eigen::Matrix2Xd p = embed(test, "test");
    for (std::size_t j = 0; j < trees_.size(); ++j) {
      double e = 0;
      for (Index i = 0; i < p.cols(); ++i) e += trees_[j].nearest(p.col(i).data()).squared_distance;
      out(static_cast<Index>(j)) = e;
    }
  }

  Index objects() const override { return static_cast<Index>(trees_.size()); }

  void validate() const {
    if (!(tilt_scale > 0) || !std::isfinite(tilt_scale))
      throw InvalidArgument("tilt_scale", "must be finite and > 0, got " + std::to_string(tilt_scale));
  }

  /// The points (z, s theta) of `touches`, one column per touch.
  Eigen::Matrix2Xd embed(const TouchSet& touches, const std::string& argument) const {
    touches.validate(argument);
    if (!touches.has_normals())
      throw EmptyInput(argument + ".normals",
                       "the height classifier needs the pad orientation of every touch (dataset columns qw, qx, qy, qz)");
    Eigen::Matrix2Xd p(2, touches.size());
    for (Index i = 0; i < touches.size(); ++i) {
      p.col(i) = height_and_tilt(touches.positions.col(i), touches.normals.col(i));
      p(1, i) *= tilt_scale;
    }
    return p;
  }

 private:
  std::vector<AdaptiveSearch<double, 2>> trees_;  // brute force for a few hundred touches, a kd-tree above
};

}  // namespace iclap

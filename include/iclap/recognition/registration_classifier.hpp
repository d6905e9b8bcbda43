// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/recognition/classifier.hpp"
#include "iclap/registration/registration.hpp"

namespace iclap {

/// How the kinesthetic ICP sees a touch: its position (x, y, z). Paper,
/// Section IV, "Kinesthetics based object recognition".
struct PositionEmbedding {
  static constexpr int dimension = 3;
  static constexpr const char* default_name = "icp";
  Index dim(const TouchSet& /*touches*/) const noexcept { return 3; }
  void validate() const {}
  template <typename Scalar, int Dim>
  void weights(Point<Scalar, Dim>& w, Index d) const {
    w = Point<Scalar, Dim>::Ones(d);
  }
  template <typename Scalar, int Dim>
  void embed(const TouchSet& s, Cloud<Scalar, Dim>& out) const {
    out = s.positions.cast<Scalar>();
  }
};

/// How iCLAP sees a touch: the 4-D labeled point (x, y, z, word) of paper
/// Section III. `label_scale` is the weight of the label axis in metres per
/// word step: the paper's rig reported millimetres and integer labels, so
/// one label step weighed one millimetre; with positions in metres that is
/// 0.001, the default.
struct LabeledEmbedding {
  static constexpr int dimension = 4;
  static constexpr const char* default_name = "iclap";
  double label_scale = 0.001;
  Index dim(const TouchSet& /*touches*/) const noexcept { return 4; }
  void validate() const {
    if (!(label_scale > 0) || !std::isfinite(label_scale))
      throw InvalidArgument("label_scale", "must be finite and > 0, got " + std::to_string(label_scale));
  }
  template <typename Scalar, int Dim>
  void weights(Point<Scalar, Dim>& w, Index d) const {
    w = Point<Scalar, Dim>::Ones(d);
    w(3) = static_cast<Scalar>(label_scale);
  }
  template <typename Scalar, int Dim>
  void embed(const TouchSet& s, Cloud<Scalar, Dim>& out) const {
    if (s.words.size() != s.size()) throw DimensionMismatch("touches.words", s.size(), s.words.size());
    out.resize(4, s.size());
    out.template topRows<3>() = s.positions.cast<Scalar>();
    out.row(3) = s.words.transpose().cast<Scalar>();
  }
};

/// How iCLAP-N sees a touch (the paper's Discussion, beyond the paper): the
/// position followed by the whole descriptor, a (3 + D)-D point, so that no
/// information is lost to quantisation. `descriptor_scale` weighs the
/// descriptor axes in metres per descriptor unit (a unit-norm Tactile-SIFT
/// difference of 1 counts as 1 cm by default).
struct DescriptorEmbedding {
  static constexpr int dimension = Eigen::Dynamic;
  static constexpr const char* default_name = "iclapn";
  double descriptor_scale = 0.01;
  Index dim(const TouchSet& touches) const noexcept { return 3 + touches.features.rows(); }
  void validate() const {
    if (!(descriptor_scale > 0) || !std::isfinite(descriptor_scale))
      throw InvalidArgument("descriptor_scale", "must be finite and > 0, got " + std::to_string(descriptor_scale));
  }
  template <typename Scalar, int Dim>
  void weights(Point<Scalar, Dim>& w, Index d) const {
    w = Point<Scalar, Dim>::Constant(d, static_cast<Scalar>(descriptor_scale));
    w.template head<3>().setOnes();
  }
  template <typename Scalar, int Dim>
  void embed(const TouchSet& s, Cloud<Scalar, Dim>& out) const {
    if (s.features.cols() != s.size()) throw DimensionMismatch("touches.features", s.size(), s.features.cols());
    out.resize(3 + s.features.rows(), s.size());
    out.template topRows<3>() = s.positions.cast<Scalar>();
    out.bottomRows(s.features.rows()) = s.features.cast<Scalar>();
  }
};

/// A classifier whose distance is the ICP error E between the test touches
/// and each object's reference cloud (paper: E_ICP, E_iCLAP): the test is
/// registered against every object and E = sum of squared distances of the
/// matched pairs after convergence. `Embedding` turns touches into points
/// (PositionEmbedding: 3-D ICP; LabeledEmbedding: 4-D iCLAP;
/// DescriptorEmbedding: (3+D)-D iCLAP-N), `Model` is the motion allowed
/// between a test and a reference (default Planar: the objects lie on a
/// table and are re-placed between explorations; FullRigid is the paper's).
///
/// Configure through the public members (`icp.termination.max_iterations`,
/// `embedding.label_scale`, ...) before `fit`. The references (kd-trees
/// included) are built once in `fit` and shared by every `distances` call;
/// `distances` is const and thread-safe (per-thread buffers).
template <typename Embedding, typename Scalar = float, int Dim = Embedding::dimension, typename Model = Planar,
          typename Search = KdTreeSearch<Scalar, Dim>>
class RegistrationClassifier final : public Classifier {
 public:
  using Reference = ReferenceCloud<Scalar, Dim, Search>;
  using IcpType = Icp<Scalar, Dim, Model>;

  IcpType icp;
  Embedding embedding;
  /// The name in fusion expressions and results (default: the embedding's).
  std::string label = Embedding::default_name;

  std::string name() const override { return label; }

  /// Throws EmptyInput naming "objects" / "objects[j]" for no object or an
  /// object without touches, plus whatever the embedding rejects.
  void fit(const std::vector<TouchSet>& objects, Index /*vocabulary*/) override {
    embedding.validate();
    if (objects.empty()) throw EmptyInput("objects", "no object to recognise");
    std::vector<Reference> refs;
    refs.reserve(objects.size());
    Cloud<Scalar, Dim> points;
    Point<Scalar, Dim> w;
    for (std::size_t j = 0; j < objects.size(); ++j) {
      const std::string arg = "objects[" + std::to_string(j) + "]";
      objects[j].validate(arg);
      check_embedded_dimension(objects[j], arg);
      embedding.template embed<Scalar, Dim>(objects[j], points);
      embedding.template weights<Scalar, Dim>(w, points.rows());
      refs.emplace_back(points, w);
    }
    references_ = std::move(refs);
  }

  void distances(const TouchSet& test, Eigen::Ref<Eigen::VectorXd> out) const override {
    check_dimension(out.size(), objects(), "out");
    test.validate("test");
    check_embedded_dimension(test, "test");
    thread_local Cloud<Scalar, Dim> points;
    thread_local IcpWorkspace<Scalar, Dim> workspace;
    embedding.template embed<Scalar, Dim>(test, points);
    for (std::size_t j = 0; j < references_.size(); ++j) {
      const auto r = icp.align(references_[j], points, nullptr, workspace);
      out(static_cast<Index>(j)) = static_cast<double>(r.error);
    }
  }

  /// One registration, for inspection (e.g. the transform that matched).
  typename IcpType::Result register_against(const TouchSet& test, Index object) const {
    if (object < 0 || object >= objects())
      throw InvalidArgument("object", std::to_string(object) + " is outside [0, " + std::to_string(objects()) + ")");
    Cloud<Scalar, Dim> points;
    embedding.template embed<Scalar, Dim>(test, points);
    return icp.align(references_[static_cast<std::size_t>(object)], points);
  }

  Index objects() const override { return static_cast<Index>(references_.size()); }
  const std::vector<Reference>& references() const noexcept { return references_; }

 private:
  void check_embedded_dimension(const TouchSet& s, const std::string& arg) const {
    if (Dim > 0) check_dimension(embedding.dim(s), Dim, arg + " (embedded point dimension)");
    if (!references_.empty() && Dim == Eigen::Dynamic)
      check_dimension(embedding.dim(s), references_.front().dim(), arg + " (embedded point dimension)");
  }

  std::vector<Reference> references_;
};

/// 3-D ICP on positions (the paper's kinesthetic pipeline, "icp").
template <typename Scalar = float, typename Model = Planar, typename Search = KdTreeSearch<Scalar, 3>>
using IcpClassifier = RegistrationClassifier<PositionEmbedding, Scalar, 3, Model, Search>;

/// 4-D iCLAP on (x, y, z, word) ("iclap").
template <typename Scalar = float, typename Model = Planar, typename Search = KdTreeSearch<Scalar, 4>>
using IclapClassifier = RegistrationClassifier<LabeledEmbedding, Scalar, 4, Model, Search>;

/// (3 + Length)-D iCLAP on (x, y, z, descriptor) ("iclapn"); Length is the
/// descriptor length (72 for Tactile-SIFT 3x3x8) or Eigen::Dynamic.
template <int Length = Eigen::Dynamic, typename Scalar = float, typename Model = Planar,
          typename Search = KdTreeSearch<Scalar, (Length == Eigen::Dynamic ? Eigen::Dynamic : 3 + Length)>>
using IclapNClassifier =
    RegistrationClassifier<DescriptorEmbedding, Scalar, (Length == Eigen::Dynamic ? Eigen::Dynamic : 3 + Length),
                           Model, Search>;

}  // namespace iclap

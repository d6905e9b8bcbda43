// SPDX-License-Identifier: MIT
// The registration classifiers (icp, iclap, iclapn) on tiny hand-made
// clouds whose registration errors are known exactly: the settings they
// refuse, how each embedding weighs its axes, which object wins a tie, the
// pivot of a yaw start and which points a bounded reference keeps.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "iclap/recognition/fusion.hpp"
#include "iclap/recognition/registration_classifier.hpp"
#include "../support/errors.hpp"

using namespace iclap;
using iclap::test::argument_of;

namespace {

/// One touch per column of `xyz`, with words 0, 1, 2, ... and 2-D features
/// (i, -i).
TouchSet touches(const Eigen::Matrix3Xd& xyz) {
  TouchSet s;
  s.positions = xyz;
  s.words.resize(xyz.cols());
  s.features.resize(2, xyz.cols());
  for (Index i = 0; i < xyz.cols(); ++i) {
    s.words(i) = i;
    s.features.col(i) << static_cast<float>(i), static_cast<float>(-i);
  }
  return s;
}

/// `value` within a relative 1e-9 (doctest::Approx alone also accepts any
/// difference below about 1e-5, more than these errors).
doctest::Approx near(double value) { return doctest::Approx(value).scale(0).epsilon(1e-9); }

/// The corners of a 10 cm square on the table.
TouchSet square() {
  Eigen::Matrix3Xd xyz(3, 4);
  xyz << 0, 0.1, 0, 0.1,  //
      0, 0, 0.1, 0.1,     //
      0, 0, 0, 0;
  return touches(xyz);
}

}  // namespace

TEST_CASE("registration classifiers refuse bad settings and inputs, naming them") {
  const TouchSet s = square();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const double bad : {0.0, -1.0, nan}) {
    CAPTURE(bad);
    IclapClassifier<double> iclap;
    iclap.embedding.label_scale = bad;
    CHECK(argument_of([&] { iclap.fit({s}, 4); }) == "label_scale");
    IclapNClassifier<> iclapn;
    iclapn.embedding.descriptor_scale = bad;
    CHECK(argument_of([&] { iclapn.fit({s}, 4); }) == "descriptor_scale");
  }
  // A scale that is 0 or subnormal as the classifier's scalar (1e-50 as a
  // float; 1e-310 as a double) was refused deep in fit as "weights".
  for (const double tiny : {1e-50, 1e-40}) {
    CAPTURE(tiny);
    IclapClassifier<float> iclap;
    iclap.embedding.label_scale = tiny;
    CHECK(argument_of([&] { iclap.fit({s}, 4); }) == "label_scale");
    IclapNClassifier<Eigen::Dynamic, float> iclapn;
    iclapn.embedding.descriptor_scale = tiny;
    CHECK(argument_of([&] { iclapn.fit({s}, 4); }) == "descriptor_scale");
    IclapClassifier<double> fine;  // a double holds it
    fine.embedding.label_scale = tiny;
    CHECK_NOTHROW(fine.fit({s}, 4));
  }
  IclapClassifier<double> subnormal;
  subnormal.embedding.label_scale = 1e-310;
  CHECK_THROWS_WITH_AS(subnormal.fit({s}, 4),
                       "label_scale: 1e-310 is outside the range of a double weight [2.22507e-308, 1.79769e+308]; "
                       "use a scale within it",
                       InvalidArgument);
  // No object; an object without the words or descriptors the embedding reads.
  IcpClassifier<double> icp;
  CHECK_THROWS_WITH_AS(icp.fit({}, 4), "objects: no object to recognise", EmptyInput);
  TouchSet unlabeled = s;
  unlabeled.words.resize(0);
  CHECK(argument_of([&] { IclapClassifier<double>().fit({unlabeled}, 4); }) == "touches.words");
  TouchSet undescribed = s;
  undescribed.features.resize(0, 0);
  CHECK(argument_of([&] { IclapNClassifier<>().fit({undescribed}, 4); }) == "touches.features");
  // A reference descriptor beyond the float cloud's range names the object.
  TouchSet loud = s;
  loud.features(1, 2) = 3e38f;
  CHECK(argument_of([&] { IclapNClassifier<Eigen::Dynamic, float>().fit({s, loud}, 4); }) == "objects[1]");
  // A test whose descriptors are of another length than the references'.
  IclapNClassifier<> iclapn;
  iclapn.fit({s}, 4);
  TouchSet longer = s;
  longer.features = Eigen::MatrixXf::Zero(3, 4);
  Eigen::VectorXd d(1);
  CHECK(argument_of([&] { iclapn.distances(longer, d); }) == "test (embedded point dimension)");
  // An object index outside [0, objects()).
  icp.fit({s}, 4);
  CHECK_THROWS_WITH_AS(icp.register_against(s, 1), "object: 1 is outside [0, 1)", InvalidArgument);
  CHECK(argument_of([&] { icp.register_against(s, -1); }) == "object");
  CHECK(icp.register_against(s, 0).error < 1e-20);
  // A yaw start that is not a finite angle.
  for (const double bad : {nan, std::numeric_limits<double>::infinity()}) {
    icp.yaw_starts_deg = {0.0, bad};
    CHECK_THROWS_WITH_AS(icp.distances(s, d), "yaw_starts_deg: holds a non-finite angle", InvalidArgument);
    CHECK(argument_of([&] { (void)icp.decide(s); }) == "yaw_starts_deg");
  }
}

TEST_CASE("iclapn: every object of a fit has descriptors of one length, which a refit may change") {
  const TouchSet s = square();
  TouchSet longer = s;
  longer.features = Eigen::MatrixXf::Zero(3, 4);
  IclapNClassifier<> iclapn;
  CHECK(iclapn.descriptor_length() == 0);  // before a fit
  // Objects whose descriptors differ in length: they were accepted, and a
  // test was then checked against objects[0]'s references only.
  CHECK_THROWS_WITH_AS(iclapn.fit({s, longer}, 4),
                       "objects[1] (embedded point dimension, as objects[0]'s): has dimension 6, expected 5",
                       DimensionMismatch);
  CHECK(iclapn.objects() == 0);
  iclapn.fit({s, s}, 4);
  CHECK(iclapn.descriptor_length() == 2);
  // A refit replaces the references: it was checked against the old ones.
  REQUIRE_NOTHROW(iclapn.fit({longer, longer}, 4));
  CHECK(iclapn.descriptor_length() == 3);
  Eigen::VectorXd d(2);
  CHECK(argument_of([&] { iclapn.distances(s, d); }) == "test (embedded point dimension)");
  iclapn.distances(longer, d);
  CHECK(d(0) < 1e-20);
  // The classifiers that read no descriptor need none.
  IcpClassifier<double> icp;
  IclapClassifier<double> iclap;
  icp.fit({s}, 4);
  iclap.fit({s}, 4);
  CHECK(icp.descriptor_length() == 0);
  CHECK(iclap.descriptor_length() == 0);
}

TEST_CASE("embeddings: positions in metres, a word step weighs label_scale, a descriptor unit descriptor_scale") {
  // The test is the reference raised by 1 mm, with every word one step and
  // every first descriptor value one unit off: no planar motion helps, each
  // point keeps its own reference point, and E sums the squared offsets.
  const TouchSet ref = square();
  TouchSet test = ref;
  test.positions.row(2).array() += 0.001;
  test.words.array() += 1;
  test.features.row(0).array() += 1;
  Eigen::VectorXd d(1);
  IcpClassifier<double> icp;
  icp.fit({ref}, 4);
  icp.distances(test, d);
  CHECK(d(0) == near(4 * 1e-6));
  IclapClassifier<double> iclap;  // the paper's weight: a word step is a millimetre
  iclap.fit({ref}, 4);
  iclap.distances(test, d);
  CHECK(d(0) == near(4 * (1e-6 + 1e-6)));
  iclap.embedding.label_scale = 0.003;
  iclap.fit({ref}, 4);
  iclap.distances(test, d);
  CHECK(d(0) == near(4 * (1e-6 + 9e-6)));
  IclapNClassifier<Eigen::Dynamic, double> iclapn;
  iclapn.embedding.descriptor_scale = 0.02;
  iclapn.fit({ref}, 4);
  iclapn.distances(test, d);
  CHECK(d(0) == near(4 * (1e-6 + 4e-4)));
  // All of it in the coordinates a planar motion never moves: the bound is the error.
  CHECK(iclapn.lower_bounds(test)(0) == near(d(0)));
}

TEST_CASE("equal final errors go to the smaller object index, whatever order the bounds register them in") {
  // Two test touches 1 m apart, word 0. Object 0 has them with word 1 (E =
  // 2 x 0.25^2, all of it in the label: bound 0.125); object 1 has word 0
  // but 1.5 m apart (E = 2 x 0.25^2 in x, bound 0), so the bound registers
  // object 1 first.
  Eigen::Matrix3Xd xyz(3, 2);
  xyz << 0, 1, 0, 0, 0, 0;
  TouchSet test = touches(xyz);
  test.words.setZero();
  TouchSet relabeled = test;
  relabeled.words.setOnes();
  Eigen::Matrix3Xd wider = xyz;
  wider.row(0) << -0.25, 1.25;
  TouchSet stretched = touches(wider);
  stretched.words.setZero();
  IclapClassifier<double, Planar> c;
  c.embedding.label_scale = 0.25;
  c.fit({relabeled, stretched}, 4);
  Eigen::VectorXd d(2);
  c.distances(test, d);
  REQUIRE(d(0) == 0.125);
  REQUIRE(d(1) == 0.125);
  const Eigen::VectorXd lb = c.lower_bounds(test);
  REQUIRE(lb(0) == 0.125);
  REQUIRE(lb(1) == 0.0);
  for (const auto schedule :
       {PruningSettings::Schedule::None, PruningSettings::Schedule::Bound, PruningSettings::Schedule::Halving}) {
    CAPTURE(static_cast<int>(schedule));
    const PrunedDecision r = c.decide(test, {schedule});
    CHECK(r.object == 0);
    CHECK(r.error == 0.125);
    CHECK(r.completed == 2);  // a bound equal to the best error does not prune
    CHECK(r.pruned == 0);
  }
}

TEST_CASE("a yaw start turns the test about its own centroid, wherever the object lies") {
  // An L of touches half a metre from the origin, and a test of its touches
  // turned by 90 degrees about their centroid: the -90 start undoes it.
  Eigen::Matrix3Xd xyz(3, 7);
  xyz << 0, 0.02, 0.04, 0.06, 0.08, 0, 0,  //
      0, 0, 0, 0, 0, 0.02, 0.04,           //
      0, 0, 0, 0, 0, 0, 0;
  xyz.row(0).array() += 0.5;
  xyz.row(1).array() += 0.3;
  TouchSet ref = touches(xyz);
  const Eigen::Vector3d c = xyz.rowwise().mean();
  TouchSet test = ref;
  for (Index i = 0; i < xyz.cols(); ++i)
    test.positions.col(i) << c.x() - (xyz(1, i) - c.y()), c.y() + (xyz(0, i) - c.x()), xyz(2, i);
  IcpClassifier<double, Planar> turned;
  turned.yaw_starts_deg = {-90};
  turned.fit({ref}, 4);
  Eigen::VectorXd d(1);
  turned.distances(test, d);
  CHECK(d(0) < 1e-20);
  IcpClassifier<double, Planar> straight;  // the paper's single start is far from it
  straight.fit({ref}, 4);
  Eigen::VectorXd e(1);
  straight.distances(test, e);
  CHECK(e(0) > 1e-4);
}

TEST_CASE("max_reference_points keeps points evenly spaced in touch order") {
  Eigen::Matrix3Xd xyz = Eigen::Matrix3Xd::Zero(3, 10);
  for (Index i = 0; i < 10; ++i) xyz.col(i) << 0.01 * static_cast<double>(i), 0.001 * static_cast<double>(i * i), 0;
  IcpClassifier<double> c;
  c.max_reference_points = 4;
  c.fit({touches(xyz)}, 4);
  const auto& r = c.references().front();
  REQUIRE(r.size() == 4);
  const std::vector<Index> kept = {0, 2, 5, 7};  // k * 10 / 4
  for (Index k = 0; k < 4; ++k) {
    CAPTURE(k);
    const Eigen::Vector3d p = r.working_points().col(k) + r.centroid();
    CHECK((p - xyz.col(kept[static_cast<std::size_t>(k)])).norm() < 1e-15);
  }
}

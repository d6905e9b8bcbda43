// SPDX-License-Identifier: MIT
// The C++ snippets of README.md ("Using the library"), verbatim, on small
// data built here in place of the README's `...`, with checks of what the
// README says each one does. readme_snippets_sync (readme_snippets_sync.cmake)
// fails when a snippet line of the README is not a line of this file, so
// edit both together.

#include <doctest/doctest.h>

#include <cmath>
#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <iclap/registration/registration.hpp>
#include <iclap/recognition/recognition.hpp>
#include <iclap/mesh/mesh.hpp>
#include <iclap/recognition/occupancy_classifier.hpp>

#include "../support/errors.hpp"

using iclap::test::argument_of;
using iclap::test::what_of;

namespace {

constexpr double kPi = 3.14159265358979323846;

// 48 points on a wavy surface 60 x 40 mm, spread irregularly (golden-ratio
// steps), words 0..4 by region: no symmetry lets a planar motion map the
// cloud onto itself other than the identity.
iclap::Cloud<double, 4> small_model() {
  iclap::Cloud<double, 4> m(4, 48);
  for (iclap::Index i = 0; i < m.cols(); ++i) {
    const double u = std::fmod(0.618033988749895 * static_cast<double>(i), 1.0);
    const double v = std::fmod(0.414213562373095 * static_cast<double>(i), 1.0);
    const double x = -0.03 + 0.06 * u, y = -0.02 + 0.04 * v;
    m(0, i) = x;
    m(1, i) = y;
    m(2, i) = 0.01 + 0.004 * std::sin(x / 0.01) + 0.003 * std::cos(y / 0.013);
    m(3, i) = std::floor(5 * u);
  }
  return m;
}

// The planar motion the ICP snippet must recover: 3 degrees about z and
// (2, -1.5) mm.
const double kYaw = 3.0 * kPi / 180;
const Eigen::Vector2d kShift(0.002, -0.0015);

// The model seen after the object moved: test = M^-1 model, so that
// x_model = R x_test + t with R, t the motion above (labels unchanged), plus
// up to 20 um of deterministic noise on x, y, z, as a sensor gives (a real
// touch is never exact; test_icp_policies registers exact copies).
iclap::Cloud<double, 4> moved(const iclap::Cloud<double, 4>& model) {
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(kYaw).toRotationMatrix();
  iclap::Cloud<double, 4> test = model;
  test.topRows<2>() = R.transpose() * (model.topRows<2>().colwise() - kShift);
  for (iclap::Index i = 0; i < test.cols(); ++i)
    for (iclap::Index k = 0; k < 3; ++k) test(k, i) += 2e-5 * std::sin(1.7 * static_cast<double>(3 * i + k) + 0.3);
  return test;
}

}  // namespace

TEST_CASE("README: N-D labeled ICP recovers a known planar motion") {
  // Reference: 4-D iCLAP points (x, y, z in metres, word label), one per column.
  iclap::Cloud<double, 4> model = small_model();
  iclap::Cloud<double, 4> test = moved(model);
  // One word step weighs as much as 1 mm; the search (kd-tree or brute force) is built here, once.
  const iclap::ReferenceCloud<double, 4> reference(model, Eigen::Vector4d(1, 1, 1, 0.001));

  iclap::Icp<double, 4, iclap::Planar> icp;   // FullRigid (the paper), SpatialRigid, Planar, Translation
  icp.termination.max_iterations = 30;         // the paper's three rules, see termination.hpp
  icp.rejection.trim_fraction = 0.9;           // optional: max_distance, trimming
  const auto r = icp.align(reference, test);   // or align(reference, test, initial_guess): R a rotation
  // r.T_model_test (R, t, matrix()), r.error (E), r.rmse, r.iterations,
  // r.converged, r.stop_reason, r.pairs, r.degenerate

  CHECK(r.converged);
  CHECK_FALSE(r.degenerate);
  CHECK(r.iterations >= 1);
  CHECK(r.iterations <= 30);
  // Trimming keeps the closest ceil(0.9 n) pairs.
  CHECK(r.pairs == static_cast<iclap::Index>(std::ceil(0.9 * static_cast<double>(model.cols()))));
  // The motion: a turn about z by kYaw and the shift kShift, within what 20 um
  // of noise on 48 points allows (found: 1e-4 rad, 2 um); z and the label
  // axis untouched (Planar), exactly.
  Eigen::Matrix4d R_expected = Eigen::Matrix4d::Identity();
  R_expected.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(kYaw).toRotationMatrix();
  Eigen::Vector4d t_expected = Eigen::Vector4d::Zero();
  t_expected.head<2>() = kShift;
  CHECK((r.T_model_test.R - R_expected).cwiseAbs().maxCoeff() < 1e-3);
  CHECK((r.T_model_test.t - t_expected).cwiseAbs().maxCoeff() < 2e-5);
  CHECK((r.T_model_test.R.bottomRightCorner<2, 2>() == Eigen::Matrix2d::Identity()));
  CHECK((r.T_model_test.t.tail<2>() == Eigen::Vector2d::Zero()));
  CHECK((r.T_model_test.matrix().topRightCorner<4, 1>() == r.T_model_test.t));
  // Only the noise is left: at the true motion every pair is within
  // sqrt(3) 20 um, so the fitted error is at most pairs x 3 (20 um)^2.
  CHECK(r.error < static_cast<double>(r.pairs) * 3 * 4e-10);
  CHECK(r.rmse == doctest::Approx(std::sqrt(r.error / static_cast<double>(r.pairs))));
  // The initial guess is used: starting at the answer, the answer stays.
  const auto again = icp.align(reference, test, r.T_model_test);
  CHECK(again.converged);
  CHECK((again.T_model_test.t - r.T_model_test.t).cwiseAbs().maxCoeff() < 1e-7);
  CHECK(again.iterations < r.iterations);
}

namespace {
struct Touch { double x, y, z; int word; };           // your record of a touch

// A cloud as records (words are whole numbers in small_model()).
std::vector<Touch> touches_of(const iclap::Cloud<double, 4>& c) {
  std::vector<Touch> out;
  for (iclap::Index i = 0; i < c.cols(); ++i) out.push_back({c(0, i), c(1, i), c(2, i), static_cast<int>(c(3, i))});
  return out;
}
}  // namespace

template <> struct iclap::PointCloudTraits<std::vector<Touch>> {
  static iclap::Index size(const std::vector<Touch>& c) { return static_cast<iclap::Index>(c.size()); }
  static iclap::Index dimension(const std::vector<Touch>&) { return 4; }
  static double coordinate(const std::vector<Touch>& c, iclap::Index i, iclap::Index k) {
    const Touch& t = c[static_cast<std::size_t>(i)];
    return k == 0 ? t.x : k == 1 ? t.y : k == 2 ? t.z : t.word;
  }
};

TEST_CASE("README: PointCloudTraits registers records exactly as the matrix of their values") {
  const iclap::Cloud<double, 4> model = small_model(), test = moved(model);
  const std::vector<Touch> my_model_touches = touches_of(model), my_test_touches = touches_of(test);
  REQUIRE(my_model_touches.size() == static_cast<std::size_t>(model.cols()));
  iclap::Icp<double, 4, iclap::Planar> icp;   // FullRigid (the paper), SpatialRigid, Planar, Translation
  icp.termination.max_iterations = 30;         // the paper's three rules, see termination.hpp
  icp.rejection.trim_fraction = 0.9;           // optional: max_distance, trimming
  const iclap::ReferenceCloud<double, 4> matrix_reference(model, Eigen::Vector4d(1, 1, 1, 0.001));
  const auto from_matrix = icp.align(matrix_reference, test);

  const iclap::ReferenceCloud<double, 4> reference(my_model_touches, Eigen::Vector4d(1, 1, 1, 0.001));
  const auto r = icp.align(reference, my_test_touches);  // as for a matrix of the same values, bit for bit

  // Bit for bit: == on doubles, not a tolerance.
  CHECK((reference.working_points() == matrix_reference.working_points()));
  CHECK((reference.centroid() == matrix_reference.centroid()));
  CHECK((r.T_model_test.R == from_matrix.T_model_test.R));
  CHECK((r.T_model_test.t == from_matrix.T_model_test.t));
  CHECK(r.error == from_matrix.error);
  CHECK(r.rmse == from_matrix.rmse);
  CHECK(r.iterations == from_matrix.iterations);
  CHECK(r.pairs == from_matrix.pairs);
  CHECK(r.converged == from_matrix.converged);
  CHECK((r.stop_reason == from_matrix.stop_reason));
  // And it is a registration, not two equal failures.
  CHECK(r.converged);
  CHECK((r.T_model_test.t.head<2>() - kShift).cwiseAbs().maxCoeff() < 2e-5);
}

namespace {

// Three objects, 12 touches each, at different heights (a planar motion
// cannot change z) and of different shapes, each feeling its own kind of
// feature (2-D, small deterministic variation): a bar, a ring, a 4 x 3 grid.
std::vector<iclap::TouchSet> small_training_set() {
  std::vector<iclap::TouchSet> objects(3);
  for (std::size_t o = 0; o < objects.size(); ++o) {
    iclap::TouchSet& s = objects[o];
    s.positions.resize(3, 12);
    s.features.resize(2, 12);
    for (iclap::Index i = 0; i < 12; ++i) {
      const double a = 2 * kPi * static_cast<double>(i) / 12;
      const double z = 0.01 * static_cast<double>(o + 1);
      if (o == 0) s.positions.col(i) << -0.05 + 0.1 * static_cast<double>(i) / 11, 0.002 * std::sin(7.0 * static_cast<double>(i)), z;
      if (o == 1) s.positions.col(i) << 0.03 * std::cos(a), 0.03 * std::sin(a), z;
      if (o == 2) s.positions.col(i) << 0.01 * static_cast<double>(i % 4), 0.01 * static_cast<double>(i / 4), z;
      // Feature (1, 0), (0, 1) or (1, 1) by object, plus a little spread;
      // written by coefficient: g++ 12 -O3 warned (-Warray-bounds, a false
      // positive) on a fixed 2-vector expression assigned to a column.
      const float fx = o == 1 ? 0.0f : 1.0f, fy = o == 0 ? 0.0f : 1.0f;
      s.features(0, i) = fx + 0.02f * std::sin(static_cast<float>(i));
      s.features(1, i) = fy + 0.02f * std::cos(static_cast<float>(i));
    }
  }
  return objects;
}

}  // namespace

TEST_CASE("README: recognition and fusion decide the object a test was drawn from") {
  std::vector<iclap::TouchSet> training_touch_sets_per_object = small_training_set();
  // The codebook of the README's previous section: k-means over every
  // training feature, one word per kind of feature.
  Eigen::MatrixXf all_features(2, 36);
  for (iclap::Index o = 0; o < 3; ++o)
    all_features.middleCols(12 * o, 12) = training_touch_sets_per_object[static_cast<std::size_t>(o)].features;
  iclap::KMeansQuantizer<float> codebook;
  codebook.settings.k = 3;
  codebook.fit(all_features);
  for (auto& s : training_touch_sets_per_object) s.words = iclap::assign_words(codebook, s.features);

  std::vector<std::unique_ptr<iclap::Classifier>> cs;
  cs.push_back(std::make_unique<iclap::BowClassifier>());
  cs.push_back(std::make_unique<iclap::IcpClassifier<float, iclap::Planar>>());
  cs.push_back(std::make_unique<iclap::IclapClassifier<float, iclap::Planar>>());
  iclap::Recognizer recognizer(std::move(cs));            // L2 normalisation (the paper's)
  recognizer.fit(training_touch_sets_per_object, codebook.size());   // references built once
  CHECK(recognizer.objects() == 3);
  CHECK(recognizer.normalization() == iclap::Normalization::L2);

  const iclap::Fusion icp = iclap::Fusion::classifier("icp"), bow = iclap::Fusion::classifier("bow"),
                      iclap_ = iclap::Fusion::classifier("iclap");
  const iclap::Fusion best = 0.2 * icp + 0.2 * bow + 0.6 * iclap_;   // weights checked: >= 0, sum 1

  // A test drawn from each object's own training touches (4 of its 12).
  for (iclap::Index truth = 0; truth < 3; ++truth) {
    CAPTURE(truth);
    const iclap::TouchSet test_touches =
        iclap::select_touches(training_touch_sets_per_object[static_cast<std::size_t>(truth)], std::vector<iclap::Index>{0, 3, 6, 9});
    const iclap::DistanceTable d = recognizer.distances(test_touches); // each classifier once
    const iclap::Index object = iclap::decide(best.evaluate(d));      // ties -> smaller index
    const double confidence = iclap::decision_confidence(best.evaluate(d));

    CHECK(object == truth);
    CHECK(confidence > 0.5);
    CHECK(confidence <= 1.0);
    // Every classifier's distances are in the table, each deciding alone for
    // the right object too, and the fusion is their weighted sum.
    for (const char* name : {"icp", "bow", "iclap"}) {
      CAPTURE(name);
      REQUIRE(d.has(name));
      CHECK(iclap::decide(d.get(name)) == truth);
    }
    const Eigen::VectorXd sum = 0.2 * d.get("icp") + 0.2 * d.get("bow") + 0.6 * d.get("iclap");
    CHECK((best.evaluate(d) - sum).cwiseAbs().maxCoeff() < 1e-15);
  }

  // "weights checked": a composition whose weights do not sum to 1 or are
  // negative is refused when it becomes a Fusion.
  CHECK(argument_of([&] { const iclap::Fusion f = 0.5 * icp + 0.6 * bow; }) == "weights");
  CHECK(what_of([&] { const iclap::Fusion f = 0.5 * icp + 0.6 * bow; }).find("sum to 1.1, not 1") != std::string::npos);
  CHECK(what_of([&] { const iclap::Fusion f = -0.2 * icp + 1.2 * iclap_; }).find("negative weight -0.2") != std::string::npos);
  CHECK(argument_of([&] { const iclap::Fusion f = 0.3 * icp + 0.7 * bow; }) == "(no error)");
}

namespace {

// One touch of a pad of `cols` x `rows` taxels at `pitch`, lying flat at
// height z with its centre at (x, y): the taxels for which `on_object`
// holds are pressed (contact points), the others free.
template <typename OnObject>
iclap::TouchSet flat_touch(double x, double y, double z, int cols, int rows, double pitch, OnObject on_object) {
  iclap::TouchSet s;
  s.positions = Eigen::Vector3d(x, y, z);
  std::vector<Eigen::Vector3d> pressed, unpressed;
  for (int i = 0; i < cols; ++i)
    for (int j = 0; j < rows; ++j) {
      const Eigen::Vector3d p(x + pitch * (i - (cols - 1) / 2.0), y + pitch * (j - (rows - 1) / 2.0), z);
      (on_object(p) ? pressed : unpressed).push_back(p);
    }
  s.contact_points.resize(3, static_cast<iclap::Index>(pressed.size()));
  for (std::size_t k = 0; k < pressed.size(); ++k) s.contact_points.col(static_cast<iclap::Index>(k)) = pressed[k];
  s.free_points.resize(3, static_cast<iclap::Index>(unpressed.size()));
  for (std::size_t k = 0; k < unpressed.size(); ++k) s.free_points.col(static_cast<iclap::Index>(k)) = unpressed[k];
  s.contact_offsets = {0, s.contact_points.cols()};
  s.free_offsets = {0, s.free_points.cols()};
  return s;
}

}  // namespace

TEST_CASE("README: occupancy from CAD models tells which model a touch lies on") {
  // Two solids on the table (x = y = 0 at their centres), small so that the
  // fields are built quickly: a box 12 x 12 mm, 6 mm tall, and a cylinder of
  // radius 5 mm, 10 mm tall.
  const std::vector<iclap::TriangleMesh> meshes = {
      iclap::center_on_table(iclap::make_box(Eigen::Vector3d(0.012, 0.012, 0.006))).mesh,
      iclap::center_on_table(iclap::make_cylinder(0.005, 0.01)).mesh};
  // On the box: a 4 x 4 pad of 3.4 mm pitch on the top face, its last
  // column overhanging the edge by 2.5 mm (free: more than the free radius
  // from the box). On the cylinder: a 3 x 3 pad of the same pitch, all of it
  // on the top disc (a touch may have no free point).
  const std::vector<iclap::TouchSet> touches_on = {
      flat_touch(0.0034, 0, 0.006, 4, 4, 3.4e-3, [](const Eigen::Vector3d& p) { return p.x() < 0.006; }),
      flat_touch(0, 0, 0.01, 3, 3, 3.4e-3, [](const Eigen::Vector3d& p) { return p.head<2>().norm() < 0.005; })};
  REQUIRE(touches_on[0].free_points.cols() == 4);
  REQUIRE(touches_on[1].contact_points.cols() == 9);

  iclap::OccupancyClassifier c;          // c.placements.max_shift = 0.02; ...
  std::vector<iclap::OccupancyEvidence> models(meshes.size());
  for (std::size_t j = 0; j < meshes.size(); ++j) {
    models[j].occupied = iclap::sample_surface(meshes[j], 0.5e-3);  // metres, table frame
    models[j].turn_centre = Eigen::Vector2d::Zero();                 // placements turn about x = y = 0
  }
  c.fit_evidence(models);                // or c.fit(training_touch_sets_per_object, 0)
  REQUIRE(c.objects() == 2);

  const double tau2 = c.truncation * c.truncation;
  for (std::size_t truth = 0; truth < touches_on.size(); ++truth) {
    CAPTURE(truth);
    const iclap::TouchSet& test_touches = touches_on[truth];
    Eigen::VectorXd d(c.objects());
    c.distances(test_touches, d);          // needs test_touches.contact_points and .free_points
    CHECK(iclap::decide(d) == static_cast<iclap::Index>(truth));
    // On its own model every pressed taxel lies on the surface sampled at
    // 0.5 mm: within about that spacing of it on average (no overhanging
    // taxel is charged); the other model costs several truncated misses.
    const double own = d(static_cast<iclap::Index>(truth)), other = d(static_cast<iclap::Index>(1 - truth));
    CHECK(own < static_cast<double>(test_touches.contact_points.cols()) * 0.5e-3 * 0.5e-3);
    CHECK(other > 2 * tau2);
  }

  // Without free points the classifier refuses the test, naming what it needs.
  iclap::TouchSet no_free = touches_on[0];
  no_free.free_points.resize(3, 0);
  no_free.free_offsets.clear();
  Eigen::VectorXd d(c.objects());
  CHECK(what_of<iclap::EmptyInput>([&] { c.distances(no_free, d); }).find("test.free_points") != std::string::npos);
}

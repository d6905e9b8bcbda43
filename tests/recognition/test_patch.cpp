// SPDX-License-Identifier: MIT
// Contact points of touches and the contact-patch classifiers.
#include <doctest/doctest.h>

#include <cmath>

#include "iclap/core/random.hpp"
#include "iclap/recognition/recognition.hpp"
#include "iclap/tactile/raw_pressures.hpp"
#include "../support/wts_dataset.hpp"

using namespace iclap;

namespace {

Frame frame(const std::string& object, std::int64_t exploration, Eigen::Vector3d position, double yaw) {
  Frame f;
  f.object = object;
  f.exploration = exploration;
  f.position = position;
  // Pad facing down: z into the object is world -z; x along the rows turned by `yaw`.
  const Eigen::Matrix3d down = Eigen::AngleAxisd(3.141592653589793, Eigen::Vector3d::UnitX()).toRotationMatrix();
  f.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * down);
  f.pressures = Eigen::MatrixXd::Zero(14, 6);
  return f;
}

}  // namespace

TEST_CASE("contact points: pressed taxels placed by the pad pose and pitch") {
  Dataset ds = test::wts_dataset();
  ds.comments = {"sensor: WTS 0614-34A rows=14 cols=6 pitch_m=0.004"};
  CHECK(taxel_pitch_of(ds) == 0.004);
  Frame a = frame("a", 0, Eigen::Vector3d(1.0, 2.0, 0.5), 0.0);
  a.pressures(0, 0) = 100;   // a corner taxel
  a.pressures(13, 5) = 100;  // the opposite corner
  a.pressures(6, 2) = 10;    // below the threshold: not a contact point
  Frame b = frame("a", 1, Eigen::Vector3d(0.0, 0.0, 0.1), 3.141592653589793 / 2);
  b.pressures(13, 2) = 50;
  Frame idle = frame("a", 0, Eigen::Vector3d::Zero(), 0.0);  // no contact at all
  ds.frames = {a, b, idle};
  const TouchTable t = make_touch_table(ds, RawPressures<float>{}, 20.0);
  REQUIRE(t.size() == 2);
  REQUIRE(t.touches.has_contacts());
  CHECK(t.touches.contacts_of(0) == 2);
  CHECK(t.touches.contacts_of(1) == 1);
  // Taxel (0, 0) is at (-6.5, -2.5) pitches in the pad frame; the pad faces
  // down (pad y = world -y).
  CHECK((t.touches.contact_points.col(0) - Eigen::Vector3d(1.0 - 6.5 * 0.004, 2.0 + 2.5 * 0.004, 0.5)).norm() < 1e-12);
  CHECK((t.touches.contact_points.col(1) - Eigen::Vector3d(1.0 + 6.5 * 0.004, 2.0 - 2.5 * 0.004, 0.5)).norm() < 1e-12);
  // Turned by 90 degrees: pad x (rows) is world y, pad y is world x; taxel
  // (13, 2) is at (6.5, -0.5) pitches.
  CHECK((t.touches.contact_points.col(2) - Eigen::Vector3d(-0.5 * 0.004, 6.5 * 0.004, 0.1)).norm() < 1e-12);
  // Selection keeps each touch's points.
  const TouchSet second = select_touches(t.touches, std::vector<Index>{1});
  CHECK(second.contact_offsets == std::vector<Index>{0, 1});
  CHECK(second.contact_points.col(0) == t.touches.contact_points.col(2));
  CHECK_NOTHROW(second.validate("s"));
  TouchSet broken = second;
  broken.contact_offsets = {0, 2};
  CHECK_THROWS_AS(broken.validate("s"), InvalidArgument);
  // Without orientation there are no contact points.
  for (auto& f : ds.frames) f.orientation.reset();
  CHECK(!make_touch_table(ds, RawPressures<float>{}, 20.0).touches.has_contacts());
  CHECK(taxel_pitch_of(Dataset{}) == 0.0034);
}

TEST_CASE("taxel pitch: a pitch_m= that is not a plausible pitch is refused, quoting the comment") {
  Dataset ds = test::wts_dataset();
  Frame f = frame("a", 0, Eigen::Vector3d(0.0, 0.0, 0.01), 0.0);
  f.pressures(3, 3) = 100;
  ds.frames = {f};
  for (const std::string value : {"1e308", "0", "-0.003", "1.5", "abc", "inf", "nan", "1e999", ",0034"}) {
    CAPTURE(value);
    ds.comments = {"sensor: x pitch_m=" + value};
    // Before, 0, "abc", inf and nan fell back to 3.4 mm silently and 1e308
    // placed the contact points at infinity.
    try {
      (void)taxel_pitch_of(ds);
      FAIL("accepted");
    } catch (const InvalidArgument& e) {
      CHECK(e.argument() == "dataset");
      CHECK(e.reason().find("'sensor: x pitch_m=" + value + "'") != std::string::npos);
    }
    CHECK_THROWS_AS(make_touch_table(ds, RawPressures<float>{}, 20.0), InvalidArgument);
    // A dataset without orientations places no contact point: the pitch is
    // not read.
    Dataset plain = ds;
    plain.frames[0].orientation.reset();
    CHECK(make_touch_table(plain, RawPressures<float>{}, 20.0).size() == 1);
  }
  ds.comments = {"sensor: x pitch_m=1"};  // the largest pitch allowed
  CHECK(taxel_pitch_of(ds) == 1.0);
  ds.comments = {"sensor: x pitch_m=1e999"};
  CHECK_THROWS_WITH(taxel_pitch_of(ds), doctest::Contains("is beyond the range of a double"));
}

TEST_CASE("contact embedding: test subsampling and reference voxels") {
  TouchSet s;
  s.positions = Eigen::Matrix3Xd::Zero(3, 2);
  s.words = WordIds::Constant(2, 7);
  s.words(1) = 3;
  s.contact_points.resize(3, 12);
  for (Index k = 0; k < 12; ++k) s.contact_points.col(k) << 0.001 * static_cast<double>(k), 0.0, 0.0;
  s.contact_offsets = {0, 10, 12};
  ContactEmbedding<true> e;
  e.test_points_per_touch = 5;
  Cloud<float, 4> test;
  e.embed<float, 4>(s, test);
  REQUIRE(test.cols() == 7);  // 5 of the first touch's 10, both of the second's
  CHECK(test(0, 1) == doctest::Approx(0.002));  // every other point
  CHECK(test(3, 0) == 7.0f);
  CHECK(test(3, 6) == 3.0f);
  e.reference_voxel = 0.004;
  Cloud<float, 4> ref;
  e.embed_reference<float, 4>(s, ref);
  // Points 0..9 (word 7) fall in voxels [0,4), [4,8), [8,12) mm; 10, 11 (word 3) in [8,12) but another word.
  CHECK(ref.cols() == 4);
  e.reference_voxel = 0;
  e.embed_reference<float, 4>(s, ref);
  CHECK(ref.cols() == 12);
  e.test_points_per_touch = 0;
  CHECK_THROWS_AS(e.validate(), InvalidArgument);
  TouchSet none;
  none.positions = Eigen::Matrix3Xd::Zero(3, 1);
  PatchClassifier<float> p;
  CHECK_THROWS_WITH_AS(p.fit({none}, 4),
                       "touches.contact_points: the patch classifiers need contact points (a dataset with the pad "
                       "orientation qw,qx,qy,qz)",
                       InvalidArgument);
}

TEST_CASE("patch classifiers recognise tests drawn from their own training data") {
  // Three flat objects of different outlines touched from above: each touch
  // presses a 3 x 3 block of taxels around its pad centre.
  Rng rng(3);
  std::vector<TouchSet> objects;
  for (int o = 0; o < 3; ++o) {
    TouchSet s;
    const int n = 40;
    s.positions.resize(3, n);
    s.words.resize(n);
    s.contact_offsets = {0};
    std::vector<Eigen::Vector3d> pts;
    for (int i = 0; i < n; ++i) {
      const double u = rng.uniform(-1, 1), v = rng.uniform(-1, 1);
      const Eigen::Vector3d c(0.05 * (1 + o) * u, 0.02 * v, 0.01 * (1 + o));
      s.positions.col(i) = c;
      s.words(i) = (i + o) % 4;
      for (int a = -1; a <= 1; ++a)
        for (int b = -1; b <= 1; ++b) pts.push_back(c + Eigen::Vector3d(0.0034 * a, 0.0034 * b, 0));
      s.contact_offsets.push_back(static_cast<Index>(pts.size()));
    }
    s.contact_points.resize(3, static_cast<Index>(pts.size()));
    for (std::size_t k = 0; k < pts.size(); ++k) s.contact_points.col(static_cast<Index>(k)) = pts[k];
    objects.push_back(std::move(s));
  }
  PatchClassifier<float> patch;
  IclapPatchClassifier<double> labeled;
  patch.fit(objects, 4);
  labeled.fit(objects, 4);
  for (Index o = 0; o < 3; ++o) {
    const TouchSet test = select_touches(objects[static_cast<std::size_t>(o)], std::vector<Index>{1, 5, 9, 13, 17});
    Eigen::VectorXd d(3);
    patch.distances(test, d);
    CHECK(decide(d) == o);
    labeled.distances(test, d);
    CHECK(decide(d) == o);
    CHECK(patch.decide(test, {PruningSettings::Schedule::Bound}).object == o);
  }
  // First matches prepared for a pool (8 points per touch here) leave every
  // subset's distances as they are, bit for bit.
  const TouchSet& pool = objects[2];
  for (const Classifier* c : {static_cast<const Classifier*>(&patch), static_cast<const Classifier*>(&labeled)}) {
    const auto prepared = c->prepare_pool(pool);
    REQUIRE(prepared != nullptr);
    for (const auto& subset : {std::vector<Index>{4}, std::vector<Index>{3, 0, 7, 7, 12},
                               std::vector<Index>{39, 1, 22, 8, 30, 16, 5}}) {
      Eigen::VectorXd a(3), b(3);
      c->pool_distances(pool, prepared.get(), subset, a);
      c->distances(select_touches(pool, subset), b);
      CHECK(a == b);
    }
  }
  // A contact point beyond the float registration's range is refused naming
  // its touch (it was inf in the cloud), in a test and in a reference.
  TouchSet far = select_touches(objects[1], std::vector<Index>{2, 4, 6});
  far.contact_points(1, far.contact_offsets[1] + 4) = 1e20;
  Eigen::VectorXd d(3);
  try {
    patch.distances(far, d);
    FAIL("accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "test.contact_points");
    CHECK_MESSAGE(std::string(e.what()).find("touch 1: coordinate 1e+20 is beyond the float") != std::string::npos,
                  e.what());
  }
  labeled.distances(far, d);  // double holds it
  CHECK(d.allFinite());
  auto refs = objects;
  refs[2] = far;
  try {
    patch.fit(refs, 4);
    FAIL("accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "objects[2].contact_points");
  }
  // In double range, but 5e22 voxels from the origin: the cell index would
  // overflow (its cast was undefined behaviour).
  try {
    labeled.fit(refs, 4);
    FAIL("accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "reference_voxel");
    CHECK_MESSAGE(std::string(e.what()).find("coordinate 1e+20 is 5e+22 voxels of 0.002") != std::string::npos,
                  e.what());
  }
}

TEST_CASE("contact embedding: a touch without contact points is its pad centre; reference voxels are means, cut at 0") {
  // Touch 0 pressed four taxels along x, on both sides of x = 0; touch 1
  // none; touch 2 one.
  TouchSet s;
  s.positions.resize(3, 3);
  s.positions << 0, 0.5, 0.2,  //
      0, 0.5, 0,               //
      0, 0.1, 0;
  s.words.resize(3);
  s.words << 2, 5, 7;
  s.contact_points.resize(3, 5);
  s.contact_points << -0.003, -0.001, 0.001, 0.003, 0.2,  //
      0, 0, 0, 0, 0,                                      //
      0, 0, 0, 0, 0;
  s.contact_offsets = {0, 4, 4, 5};
  ContactEmbedding<true> e;
  e.reference_voxel = 0.004;
  Cloud<double, 4> test;
  e.embed<double, 4>(s, test);
  REQUIRE(test.cols() == 6);
  CHECK(test.col(4) == Eigen::Vector4d(0.5, 0.5, 0.1, 5));  // the pad centre, with the touch's word
  // Reference: the cells [-4, 0) and [0, 4) mm of touch 0 hold two points
  // each, their means; touch 1 is its pad centre.
  Cloud<double, 4> ref;
  e.embed_reference<double, 4>(s, ref);
  REQUIRE(ref.cols() == 4);
  const Eigen::Vector4d expected[] = {{-0.002, 0, 0, 2}, {0.002, 0, 0, 2}, {0.2, 0, 0, 7}, {0.5, 0.5, 0.1, 5}};
  for (Index k = 0; k < 4; ++k) {
    CAPTURE(k);
    CHECK((ref.col(k) - expected[k]).norm() < 1e-15);
  }
  // A classifier's references are those voxel means, not the test points.
  IclapPatchClassifier<double> labeled;
  labeled.embedding.reference_voxel = 0.004;
  labeled.fit({s}, 8);
  CHECK(labeled.references().front().size() == 4);
  // A contact point beyond the float range names its own touch, also after
  // a touch without contact points.
  PatchClassifier<float> patch;
  patch.fit({s}, 8);
  TouchSet far = s;
  far.contact_points(0, 4) = 1e20;  // touch 2's only point
  Eigen::VectorXd d(1);
  CHECK_THROWS_WITH_AS(patch.distances(far, d), doctest::Contains("test.contact_points: touch 2: coordinate 1e+20"),
                       InvalidArgument);
  // Settings are refused naming them.
  auto refused = [&](auto classifier) {
    try {
      classifier.fit({s}, 8);
    } catch (const InvalidArgument& error) {
      return error.argument();
    }
    return std::string("(no error)");
  };
  PatchClassifier<float> no_points, negative_voxel;
  no_points.embedding.test_points_per_touch = 0;
  negative_voxel.embedding.reference_voxel = -0.001;
  CHECK(refused(no_points) == "test_points_per_touch");
  CHECK(refused(negative_voxel) == "reference_voxel");
  IclapPatchClassifier<float> unweighted;
  unweighted.embedding.label_scale = 0;
  CHECK(refused(unweighted) == "label_scale");
}

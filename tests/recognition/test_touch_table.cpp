// SPDX-License-Identifier: MIT
// Touch tables: which frames of a dataset become touches, what each touch
// records (object, exploration, frame), the taxel pitch, and where the
// contact and free points of a pad go.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "iclap/recognition/touch_table.hpp"
#include "iclap/tactile/raw_pressures.hpp"
#include "../support/errors.hpp"
#include "../support/wts_dataset.hpp"

using namespace iclap;

namespace {

using test::wts_dataset;

/// A 14 x 6 frame of `object`; `peak` on taxel (3, 2) (0: an idle frame).
Frame frame(const std::string& object, std::int64_t exploration, std::int64_t index, double peak) {
  Frame f;
  f.object = object;
  f.exploration = exploration;
  f.frame = index;
  f.position = Eigen::Vector3d(0.01 * static_cast<double>(index), 0.0, 0.02);
  f.pressures = Eigen::MatrixXd::Zero(14, 6);
  f.pressures(3, 2) = peak;
  return f;
}

/// Pad facing straight down (pad z, into the object, is world -z).
const Eigen::Quaterniond kDown(Eigen::AngleAxisd(3.141592653589793, Eigen::Vector3d::UnitX()));

}  // namespace

TEST_CASE("touch table: each contact frame is a touch with its object, exploration and frame; idle frames are counted") {
  // Object "b" appears first, in an idle frame; explorations out of order.
  const Dataset ds = wts_dataset({frame("b", 5, 0, 0.0), frame("a", 7, 3, 90.0), frame("b", 2, 9, 50.0),
                                  frame("a", 7, 4, 10.0), frame("a", 1, 11, 30.0)});
  std::vector<std::pair<std::size_t, std::size_t>> calls;
  const TouchTable t = make_touch_table(ds, RawPressures<float>{}, 20.0,
                                        [&](std::size_t done, std::size_t total) { calls.emplace_back(done, total); });
  CHECK(t.objects == std::vector<std::string>{"b", "a"});
  REQUIRE(t.size() == 3);
  CHECK(t.object == std::vector<Index>{1, 0, 1});
  CHECK(t.exploration == std::vector<std::int64_t>{7, 2, 1});
  CHECK(t.frame == std::vector<std::int64_t>{3, 9, 11});
  CHECK(t.idle_frames == 2);
  CHECK(t.touches.positions.col(2) == Eigen::Vector3d(0.11, 0.0, 0.02));
  REQUIRE(!calls.empty());
  CHECK(calls.back() == std::make_pair(std::size_t{3}, std::size_t{3}));  // every contact frame done
  CHECK_NOTHROW(t.validate());
  // Sorted, each id once.
  CHECK(t.explorations_of(1) == std::vector<std::int64_t>{1, 7});
  CHECK(t.explorations_of(0) == std::vector<std::int64_t>{2});
  // A selection is a table of its own: no idle frames.
  CHECK(t.select({2, 0}).idle_frames == 0);
}

TEST_CASE("touch table: a NaN, infinite or negative contact threshold is refused under its own name") {
  // A NaN made no frame a contact, a negative one every blank frame
  // (is_contact now refuses both as "threshold"; the caller's name is
  // contact_threshold).
  const Dataset ds = wts_dataset({frame("a", 0, 0, 90.0), frame("a", 0, 1, 0.0)});
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), -1.0, std::numeric_limits<double>::infinity()}) {
    CAPTURE(bad);
    CHECK(test::argument_of([&] { (void)make_touch_table(ds, RawPressures<float>{}, bad); }) == "contact_threshold");
  }
  // 0 is a threshold: every frame with a pressed taxel is a contact.
  CHECK(make_touch_table(ds, RawPressures<float>{}, 0.0).size() == 1);
}

TEST_CASE("touch table: a NaN or infinite pressure is refused, naming the frame, wherever it sits") {
  // A NaN beside a taxel above the threshold: Eigen's maxCoeff answered by
  // where the NaN sat, so the frame was dropped as idle or kept, silently.
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()})
    for (const Index row : {0, 13}) {
      CAPTURE(bad);
      CAPTURE(row);
      Frame f = frame("a", 0, 1, 90.0);
      f.pressures(row, 5) = bad;
      const Dataset ds = wts_dataset({frame("a", 0, 0, 90.0), f});
      CHECK(test::argument_of([&] { (void)make_touch_table(ds, RawPressures<float>{}, 20.0); }) ==
            "dataset.frames[1].pressures");
      CHECK_THROWS_AS((void)make_touch_table(ds, RawPressures<float>{}, 20.0), NonFiniteValue);
    }
}

TEST_CASE("touch table: validate names a bad object index and a part of the wrong length") {
  const TouchTable t =
      make_touch_table(wts_dataset({frame("a", 0, 0, 90.0), frame("b", 0, 1, 90.0)}), RawPressures<float>{}, 20.0);
  REQUIRE(t.size() == 2);
  TouchTable bad = t;
  bad.object[1] = -1;
  CHECK_THROWS_WITH_AS(bad.validate(), "table.object: touch 1 has object index -1, outside [0, 2) (the object names)",
                       InvalidArgument);
  bad = t;
  bad.exploration.pop_back();
  CHECK(test::argument_of([&] { bad.validate(); }) == "table.exploration (touches)");
  bad = t;
  bad.frame.push_back(2);
  CHECK(test::argument_of([&] { bad.validate("x"); }) == "x.frame (touches)");
}

TEST_CASE("taxel pitch: the comment that has a pitch_m= gives it, else the caller's fallback; a non-number says so") {
  Dataset ds = wts_dataset();
  ds.comments = {"recorded by iclap record", "sensor: x rows=14 cols=6 pitch_m=0.005"};
  CHECK(taxel_pitch_of(ds) == 0.005);
  CHECK(taxel_pitch_of(wts_dataset(), 0.002) == 0.002);
  ds.comments = {"sensor: x pitch_m=abc"};
  CHECK_THROWS_WITH_AS(taxel_pitch_of(ds), "dataset: the pitch_m= of comment 'sensor: x pitch_m=abc' is not a number",
                       InvalidArgument);
}

TEST_CASE("contact and free points: a taxel at the threshold is free; a fully pressed pad has no free point, but free offsets") {
  Frame f = frame("a", 0, 0, 0.0);
  f.orientation = kDown;
  f.pressures(0, 0) = 20.0;  // at the threshold: free
  f.pressures(1, 1) = 10.0;  // below it: free
  f.pressures(2, 2) = 21.0;  // above it: pressed
  std::vector<Eigen::Vector3d> pressed, free;
  CHECK(append_contact_points(f, 20.0, 0.004, pressed) == 1);
  CHECK(append_free_points(f, 20.0, 0.004, free) == 83);
  // Taxel (2, 2) is at (-4.5, -0.5) pitches in the pad frame; facing down, pad y is world -y.
  CHECK((pressed[0] - Eigen::Vector3d(-4.5 * 0.004, 0.5 * 0.004, 0.02)).norm() < 1e-12);
  const TouchTable t = make_touch_table(wts_dataset({f}), RawPressures<float>{}, 20.0);
  CHECK(t.touches.contacts_of(0) == 1);
  CHECK(t.touches.free_of(0) == 83);
  // The orientation turns the pad frame into the world (not back): turned
  // by 90 degrees about world z, pad x is world y and pad y is world -x.
  Frame turned = f;
  turned.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(3.141592653589793 / 2, Eigen::Vector3d::UnitZ()));
  pressed.clear();
  append_contact_points(turned, 20.0, 0.004, pressed);
  REQUIRE(pressed.size() == 1);
  CHECK((pressed[0] - Eigen::Vector3d(0.5 * 0.004, -4.5 * 0.004, 0.02)).norm() < 1e-12);

  // Every taxel pressed: the touch has its (empty) share of free points, so
  // a classifier that needs free points does not take it for a dataset
  // without orientations.
  f.pressures.setConstant(100.0);
  const TouchTable full = make_touch_table(wts_dataset({f}), RawPressures<float>{}, 20.0);
  CHECK(full.touches.contacts_of(0) == 84);
  CHECK(full.touches.has_free());
  CHECK(full.touches.free_offsets == std::vector<Index>{0, 0});
  CHECK_NOTHROW(full.touches.validate("full"));
}

TEST_CASE("touch table: a descriptor whose length changes between frames is refused, naming the frame") {
  Frame small = frame("a", 0, 2, 90.0);
  small.pressures = Eigen::MatrixXd::Constant(4, 4, 90.0);
  const Dataset ds = wts_dataset({frame("a", 0, 0, 0.0), frame("a", 0, 1, 90.0), small});
  CHECK(test::argument_of([&] { (void)make_touch_table(ds, RawPressures<float>{}, 20.0); }) ==
        "features of dataset.frames[2]");
}

// A hand-built dataset's contact frame with a quaternion that is not a unit
// one was refused by append_contact_points as "frame.orientation", which did
// not say which frame (the reader refuses such a row naming its line).
TEST_CASE("touch table: a contact frame whose orientation is not a unit quaternion is refused, naming the frame") {
  std::vector<Frame> frames{frame("a", 0, 0, 90.0), frame("a", 0, 1, 0.0), frame("a", 0, 2, 90.0)};
  for (Frame& f : frames) f.orientation = kDown;
  REQUIRE_NOTHROW(make_touch_table(wts_dataset(frames), RawPressures<float>{}, 20.0));
  for (const Eigen::Quaterniond& bad : {Eigen::Quaterniond(0, 0, 0, 0), Eigen::Quaterniond(2, 0, 0, 0)}) {
    frames[2].orientation = bad;
    CHECK(test::argument_of([&] { (void)make_touch_table(wts_dataset(frames), RawPressures<float>{}, 20.0); }) ==
          "dataset.frames[2].orientation");
  }
  // An idle frame's orientation places nothing: it is not read.
  frames[2].orientation = kDown;
  frames[1].orientation = Eigen::Quaterniond(0, 0, 0, 0);
  CHECK(make_touch_table(wts_dataset(frames), RawPressures<float>{}, 20.0).size() == 2);
}

// A descriptor that returns an empty feature breaks the Descriptor concept
// (tactile/descriptor.hpp: N positive); extract_features refuses it naming
// "features", but make_touch_table built a table with 0 x n features, which
// TouchSet::validate reads as "no features", so the error came much later
// (k-means: "features: has dimension 0"). Found by an audit from a user's side.
TEST_CASE("touch table: a descriptor that returns an empty feature is refused, as extract_features refuses it") {
  struct EmptyDescriptor {
    Eigen::VectorXf compute(const TactileImage&) const { return Eigen::VectorXf(); }
  };
  const Dataset ds = wts_dataset({frame("a", 0, 0, 90.0), frame("a", 0, 1, 90.0)});
  CHECK_THROWS_AS((void)make_touch_table(ds, EmptyDescriptor{}, 20.0), EmptyInput);
  CHECK(test::what_of([&] { (void)make_touch_table(ds, EmptyDescriptor{}, 20.0); }) ==
        "features: descriptor returned an empty feature for dataset.frames[0]");
}

// Found by the same audit: a double feature was cast to float before its
// check, so 1e300 read as "non-finite value inf", and a descriptor's own
// InvalidArgument about its "image" did not say which frame.
TEST_CASE("touch table: what the descriptor returns or throws is refused naming the frame") {
  struct ScaledDescriptor {  // raw pressures times `scale`; frames below 5 N refused
    double scale;
    Eigen::VectorXd compute(const TactileImage& image) const {
      if (image.pressures().maxCoeff() < 50.0) throw InvalidArgument("image", "too light to describe");
      return scale * image.pressures().reshaped();
    }
  };
  const Dataset ds = wts_dataset({frame("a", 0, 0, 0.0), frame("a", 0, 1, 90.0), frame("a", 0, 2, 30.0)});
  CHECK(test::what_of([&] { (void)make_touch_table(ds, ScaledDescriptor{1.0}, 20.0); }) ==
        "dataset.frames[2]: too light to describe");
  const Dataset heavy = wts_dataset({frame("a", 0, 0, 0.0), frame("a", 0, 1, 90.0), frame("a", 0, 2, 60.0)});
  CHECK(make_touch_table(heavy, ScaledDescriptor{1e30}, 20.0).touches.features.maxCoeff() == doctest::Approx(9e31f));
  CHECK(test::what_of([&] { (void)make_touch_table(heavy, ScaledDescriptor{1e300}, 20.0); })
            .find("features of dataset.frames[1]: coordinate 31 is 9e+301, beyond the range of float") == 0);
  try {
    (void)make_touch_table(heavy, ScaledDescriptor{std::numeric_limits<double>::infinity()}, 20.0);
    FAIL("an infinite feature was kept");
  } catch (const NonFiniteValue& e) {
    CHECK(e.argument() == "features");
    CHECK(e.column() == 0);
  }
}

TEST_CASE("touch sets: offsets start at 0, normals are unit vectors either way, one word per touch") {
  TouchSet s;
  s.positions = Eigen::Matrix3Xd::Zero(3, 2);
  s.contact_points = Eigen::Matrix3Xd::Zero(3, 2);
  s.contact_offsets = {0, 1, 2};
  CHECK_NOTHROW(s.validate("s"));
  TouchSet bad = s;
  bad.contact_offsets = {1, 1, 2};
  CHECK_THROWS_WITH_AS(bad.validate("s"), "s.contact_offsets: must rise from 0 to the number of contact points (2)",
                       InvalidArgument);
  bad = s;
  bad.normals = Eigen::Matrix3Xd::Zero(3, 2);
  bad.normals.col(0) = Eigen::Vector3d(0, 0, -1);
  bad.normals.col(1) = Eigen::Vector3d(0, 0, -0.5);  // too short
  CHECK_THROWS_WITH_AS(bad.validate("s"), "s.normals: column 1 is not a unit vector (norm 0.5)", InvalidArgument);
  bad = s;
  bad.words = WordIds::Zero(1);
  CHECK(test::argument_of([&] { bad.validate("s"); }) == "s.words (touches)");
}

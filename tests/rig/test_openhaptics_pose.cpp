// SPDX-License-Identifier: MIT
// OpenHapticsPoseSource against a scripted fake of the HD API
// (fake_hd/HD/hd.h, first on this target's include path): how it reads the
// arm's transform (column-major, millimetres, tool_to_pad on the right), its
// name, its errors, and that it hands the device back (scheduler stopped,
// device disabled). OpenHaptics itself is not in Debian; this checks the
// header's own logic, not the vendor library or the arm.

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <HD/hd.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iclap/rig/openhaptics_pose.hpp"
#include "../support/errors.hpp"

using iclap::rig::OpenHapticsPoseSource;
using iclap::rig::Pose;
using iclap::rig::TransportError;

#ifndef ICLAP_FAKE_HD
#error "test_openhaptics_pose must be built against tests/rig/fake_hd/HD/hd.h, not a real OpenHaptics"
#endif

namespace {

// Reports `R` and `t_mm` as the arm would: a 4x4 homogeneous matrix stored
// column-major (element (row r, column c) at index 4 c + r).
void arm_reports(const Eigen::Matrix3d& R, const Eigen::Vector3d& t_mm) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      double v = 0;
      if (r < 3 && c < 3) v = R(r, c);
      else if (r < 3) v = t_mm[r];
      else v = c == 3 ? 1.0 : 0.0;
      fake_hd::state.transform[4 * c + r] = v;
    }
}

// A rotation whose nine entries all differ, so a transposed or shuffled
// reading cannot give it back.
Eigen::Matrix3d generic_rotation() {
  return Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

bool called(const std::string& call) {
  for (const auto& c : fake_hd::state.calls)
    if (c == call) return true;
  return false;
}

// The message of the TransportError that `f` throws ("(no error)" if none).
template <typename F>
std::string transport_error(F&& f) {
  return iclap::test::what_of<TransportError>(std::forward<F>(f));
}

}  // namespace

TEST_CASE("OpenHapticsPoseSource: starts the arm, reads the transform in a scheduler frame, hands the arm back") {
  fake_hd::reset();
  {
    OpenHapticsPoseSource src;
    CHECK(fake_hd::state.calls == std::vector<std::string>{"hdInitDevice(default)", "hdStartScheduler"});
    CHECK(fake_hd::state.scheduler_running);
    CHECK(src.has_orientation());
    CHECK(src.description() == "openhaptics:default");

    fake_hd::state.calls.clear();
    REQUIRE(src.next().has_value());
    // The read runs as a synchronous scheduler callback (the fake pushes an
    // error for a frame or read outside one), on the handle hdInitDevice
    // returned (7), not a default HHD{}.
    CHECK(fake_hd::state.calls ==
          std::vector<std::string>{"hdScheduleSynchronous(" + std::to_string(HD_DEFAULT_SCHEDULER_PRIORITY) + ")",
                                   "hdBeginFrame(7)", "hdGetDoublev(HD_CURRENT_TRANSFORM)", "hdEndFrame(7)"});
    CHECK(fake_hd::state.errors.empty());
    fake_hd::state.calls.clear();
  }
  // Destruction: the scheduler stops before the device is disabled (the
  // servo loop must not run on a disabled device).
  CHECK(fake_hd::state.calls == std::vector<std::string>{"hdStopScheduler", "hdDisableDevice(7)"});
  CHECK_FALSE(fake_hd::state.scheduler_running);
  CHECK(fake_hd::state.enabled.empty());
  CHECK(fake_hd::state.errors.empty());
}

TEST_CASE("OpenHapticsPoseSource: a named device is opened by that name and named in the description") {
  fake_hd::reset();
  OpenHapticsPoseSource src("Right Omni");
  CHECK(fake_hd::state.calls.front() == "hdInitDevice(Right Omni)");
  CHECK(src.description() == "openhaptics:Right Omni");
}

TEST_CASE("OpenHapticsPoseSource: the transform is column-major, in millimetres") {
  fake_hd::reset();
  OpenHapticsPoseSource src;

  SUBCASE("written out: 90 degrees about z, translation (10, 20, 30) mm") {
    // Column 0 is the image of x: (0, 1, 0). Column 3 is the translation.
    const HDdouble m[16] = {0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 10, 20, 30, 1};
    fake_hd::set_transform(m);
    const std::optional<Pose> p = src.next();
    REQUIRE(p.has_value());
    CHECK(p->position.isApprox(Eigen::Vector3d(0.010, 0.020, 0.030), 1e-12));
    REQUIRE(p->orientation.has_value());
    CHECK(std::abs(p->orientation->norm() - 1.0) < 1e-12);
    // Rz(+90): x -> y. Read row-major it would be Rz(-90) and the
    // translation would come from the bottom row (0, 0, 0).
    CHECK((*p->orientation * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
    CHECK((*p->orientation * Eigen::Vector3d::UnitY()).isApprox(-Eigen::Vector3d::UnitX(), 1e-12));
  }

  SUBCASE("a rotation with nine distinct entries and a translation") {
    const Eigen::Matrix3d R = generic_rotation();
    arm_reports(R, Eigen::Vector3d(125.5, -250.25, 37.75));
    const std::optional<Pose> p = src.next();
    REQUIRE(p.has_value());
    CHECK(p->position.isApprox(Eigen::Vector3d(0.1255, -0.25025, 0.03775), 1e-12));
    REQUIRE(p->orientation.has_value());
    CHECK(std::abs(p->orientation->norm() - 1.0) < 1e-12);
    CHECK(p->orientation->toRotationMatrix().isApprox(R, 1e-12));
  }

  SUBCASE("a rotation rounded to single precision still gives a unit quaternion") {
    // The arm's kinematics may be computed in float: the rotation is then
    // orthonormal only to about 1e-7, and so would be a quaternion taken
    // from it without normalising (check_pose wants 1e-6; poses promise unit).
    const Eigen::Matrix3d R = generic_rotation().cast<float>().cast<double>();
    REQUIRE_FALSE((R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-12));
    arm_reports(R, Eigen::Vector3d(0, 0, 0));
    const std::optional<Pose> p = src.next();
    REQUIRE(p.has_value());
    REQUIRE(p->orientation.has_value());
    CHECK(std::abs(p->orientation->norm() - 1.0) < 1e-12);
    CHECK(p->orientation->toRotationMatrix().isApprox(R, 1e-6));
  }

  SUBCASE("every call reads the arm again") {
    arm_reports(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1, 2, 3));
    const std::optional<Pose> a = src.next();
    arm_reports(Eigen::Matrix3d::Identity(), Eigen::Vector3d(4, 5, 6));
    const std::optional<Pose> b = src.next();
    REQUIRE(a.has_value());
    REQUIRE(b.has_value());
    CHECK(a->position.isApprox(Eigen::Vector3d(0.001, 0.002, 0.003), 1e-12));
    CHECK(b->position.isApprox(Eigen::Vector3d(0.004, 0.005, 0.006), 1e-12));
  }
}

TEST_CASE("OpenHapticsPoseSource: tool_to_pad is applied in the tool frame (T_base_tool * tool_to_pad)") {
  fake_hd::reset();
  // Pad about 5 cm along the tool's z and turned 1.2 rad about the tool's x.
  Eigen::Isometry3d tool_to_pad = Eigen::Isometry3d::Identity();
  const Eigen::Matrix3d R_pad = Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  tool_to_pad.linear() = R_pad;
  tool_to_pad.translation() = Eigen::Vector3d(0.01, -0.02, 0.05);
  OpenHapticsPoseSource src("", tool_to_pad);

  const Eigen::Matrix3d R = generic_rotation();
  const Eigen::Vector3d t(0.2, 0.1, -0.05);  // metres
  arm_reports(R, t * 1000.0);
  const std::optional<Pose> p = src.next();
  REQUIRE(p.has_value());
  // The pad's offset is turned by the tool's rotation (tool frame), then
  // added to the tool's position; its rotation follows the tool's. On the
  // left (tool_to_pad * T_base_tool) both would differ.
  CHECK(p->position.isApprox(t + R * Eigen::Vector3d(0.01, -0.02, 0.05), 1e-12));
  CHECK_FALSE(p->position.isApprox(R_pad * t + Eigen::Vector3d(0.01, -0.02, 0.05), 1e-3));
  REQUIRE(p->orientation.has_value());
  CHECK(std::abs(p->orientation->norm() - 1.0) < 1e-12);
  CHECK(p->orientation->toRotationMatrix().isApprox(R * R_pad, 1e-12));
  CHECK_FALSE(p->orientation->toRotationMatrix().isApprox(R_pad * R, 1e-3));
}

TEST_CASE("OpenHapticsPoseSource: an arm that cannot start is a TransportError naming the source") {
  fake_hd::reset();

  SUBCASE("init fails: nothing else is called, no device left enabled") {
    fake_hd::state.init_error = HD_COMM_ERROR;
    const std::string what = transport_error([] { OpenHapticsPoseSource src("Left Omni"); });
    CHECK(contains(what, "openhaptics:Left Omni"));
    CHECK(contains(what, "cannot initialise the arm"));
    CHECK(contains(what, "communication error"));  // hdGetErrorString of the code
    bool threw = false;
    try {
      OpenHapticsPoseSource src2;
    } catch (const TransportError& e) {
      threw = true;
      CHECK(e.path() == "openhaptics:default");
    }
    CHECK(threw);
    // No scheduler and no hdDisableDevice on HD_INVALID_HANDLE.
    CHECK(fake_hd::state.calls == std::vector<std::string>{"hdInitDevice(Left Omni)", "hdInitDevice(default)"});
    CHECK(fake_hd::state.enabled.empty());
    CHECK(fake_hd::state.errors.empty());
  }

  SUBCASE("the scheduler does not start: the device is disabled") {
    fake_hd::state.start_error = HD_TIMER_ERROR;
    const std::string what = transport_error([] { OpenHapticsPoseSource src; });
    CHECK(contains(what, "openhaptics:default"));
    CHECK(contains(what, "cannot start the servo scheduler"));
    CHECK(called("hdDisableDevice(7)"));
    CHECK(fake_hd::state.enabled.empty());
    CHECK(fake_hd::state.errors.empty());
  }
}

TEST_CASE("OpenHapticsPoseSource: a failed read is a TransportError naming the source; the next read works") {
  fake_hd::reset();
  OpenHapticsPoseSource src("Omni");
  arm_reports(Eigen::Matrix3d::Identity(), Eigen::Vector3d(10, 0, 0));
  fake_hd::state.read_error = HD_DEVICE_FAULT;
  fake_hd::state.calls.clear();
  const std::string what = transport_error([&src] { (void)src.next(); });
  CHECK(contains(what, "openhaptics:Omni"));
  CHECK(contains(what, "cannot read the arm's transform"));
  CHECK(contains(what, "device fault"));
  // The frame is closed even though the read failed.
  CHECK(called("hdEndFrame(7)"));
  CHECK(fake_hd::state.errors.empty());

  fake_hd::state.read_error = HD_SUCCESS;
  const std::optional<Pose> p = src.next();
  REQUIRE(p.has_value());
  CHECK(p->position.isApprox(Eigen::Vector3d(0.010, 0, 0), 1e-12));
}

// --- Defects found by probing the header with the fake (session 50), fixed
// since; each case says what was expected and what used to happen.

TEST_CASE("OpenHapticsPoseSource: a NaN in the arm's transform is not passed on as a pose") {
  // The library's quality bar: no NaN passed on. FixedPoseSource and
  // ReplayPoseSource refuse non-finite poses (check_pose); SensorFrameSource
  // pairs whatever next() returns with the frame, unchecked. Expected: a
  // TransportError naming the source (a device error, like a failed read).
  // Happened: a pose with a NaN position (translation) or a NaN quaternion
  // (rotation) is returned.
  fake_hd::reset();
  OpenHapticsPoseSource src;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  SUBCASE("in the translation") {
    arm_reports(Eigen::Matrix3d::Identity(), Eigen::Vector3d(10, nan, 30));
  }
  SUBCASE("in the rotation") {
    Eigen::Matrix3d R = generic_rotation();
    R(1, 2) = nan;
    arm_reports(R, Eigen::Vector3d(10, 20, 30));
  }
  SUBCASE("infinite translation") {
    arm_reports(Eigen::Matrix3d::Identity(), Eigen::Vector3d(std::numeric_limits<double>::infinity(), 0, 0));
  }
  const std::string what = transport_error([&src] { (void)src.next(); });
  CHECK(contains(what, "openhaptics:default"));
  CHECK(contains(what, "the arm reported a transform that is not a pose: it holds a NaN or an infinity"));
}

TEST_CASE("OpenHapticsPoseSource: a rotation that is not a rotation is not passed on as a pose") {
  // Expected: a TransportError naming the source when the 3x3 block is far
  // from orthonormal with determinant +1 (float rounding, about 1e-7, must
  // still pass: see the single-precision case above). Happened: the block is
  // taken as is. Its quaternion is normalised, so the pose looks valid
  // (check_pose passes) but does not match the block, and the block also
  // scales or collapses tool_to_pad's offset in the position.
  // - all zeros (what a read that wrote nothing leaves in next()'s
  //   zero-initialised buffer): the pad offset vanishes and the orientation
  //   is 180 degrees about x, a valid-looking pose;
  // - twice a rotation R: the pad offset doubled, and the orientation is
  //   not R either (about 8 degrees off here: w and xyz scale differently);
  // - a reflection (det -1): a proper rotation's quaternion is returned.
  fake_hd::reset();
  Eigen::Isometry3d tool_to_pad = Eigen::Isometry3d::Identity();
  tool_to_pad.translation() = Eigen::Vector3d(0, 0, 0.05);
  OpenHapticsPoseSource src("", tool_to_pad);
  std::string why = "its rotation block is not orthogonal: the largest entry of |R^T R - I| is ";
  SUBCASE("all zeros") { arm_reports(Eigen::Matrix3d::Zero(), Eigen::Vector3d(10, 20, 30)); }
  SUBCASE("scaled by 2") { arm_reports(2.0 * generic_rotation(), Eigen::Vector3d(10, 20, 30)); }
  SUBCASE("a reflection") {
    arm_reports(generic_rotation() * Eigen::Vector3d(1, 1, -1).asDiagonal(), Eigen::Vector3d(10, 20, 30));
    why = "its rotation block is orthogonal with det -1 (a reflection)";
  }
  SUBCASE("nothing written: all 16 entries zero") {
    for (double& v : fake_hd::state.transform) v = 0;
    why = "its bottom row is not 0 0 0 1";
  }
  const std::string what = transport_error([&src] { (void)src.next(); });
  CHECK(contains(what, "openhaptics:default"));
  CHECK(contains(what, "the arm reported a transform that is not a pose: " + why));
}

TEST_CASE("OpenHapticsPoseSource: all the errors of a failed read are consumed, so the next read works") {
  // HD keeps an error stack: every failing call pushes one error and
  // hdGetError pops one. A faulting device fails more than one call of a
  // frame (here hdBeginFrame and hdEndFrame). Expected: next() throws for
  // that read, and once the arm is healthy again the next read returns its
  // pose. Happened: next() pops only one error; the other is left pending and
  // the next, healthy, read throws it ("cannot read the arm's transform:
  // device fault"), one stale failure per error left.
  fake_hd::reset();
  OpenHapticsPoseSource src;
  arm_reports(Eigen::Matrix3d::Identity(), Eigen::Vector3d(10, 0, 0));
  fake_hd::state.begin_frame_error = HD_DEVICE_FAULT;
  fake_hd::state.end_frame_error = HD_COMM_ERROR;
  const std::string what = transport_error([&src] { (void)src.next(); });
  CHECK(contains(what, "cannot read the arm's transform: "));
  CHECK(contains(what, " more error"));  // the newest named, the others counted
  CHECK(fake_hd::state.errors.empty());
  fake_hd::state.begin_frame_error = HD_SUCCESS;
  fake_hd::state.end_frame_error = HD_SUCCESS;
  std::optional<Pose> p;
  CHECK_NOTHROW(p = src.next());
  REQUIRE(p.has_value());
  CHECK(p->position.isApprox(Eigen::Vector3d(0.010, 0, 0), 1e-12));
}

TEST_CASE("OpenHapticsPoseSource: an error left pending before construction neither fails it nor leaks the arm") {
  // An HD error left on the stack by an earlier HD user in the process
  // (another library, or an earlier failed read whose other errors stayed,
  // see above). Expected: the source starts (the stale error is not this
  // arm's), or at least, if it throws, it disables the device it
  // initialised. Happened: the check after hdInitDevice pops the stale error
  // and throws "cannot initialise the arm" although init succeeded, and the
  // initialised device is never disabled (the destructor does not run for a
  // throwing constructor).
  fake_hd::reset();
  fake_hd::push_error(HD_COMM_ERROR, HD_INVALID_HANDLE);
  std::optional<OpenHapticsPoseSource> src;
  CHECK_NOTHROW(src.emplace());
  if (!src) CHECK(fake_hd::state.enabled.empty());
}

TEST_CASE("OpenHapticsPoseSource: a non-finite or non-rigid tool_to_pad is refused before the arm starts") {
  // Expected: InvalidArgument naming "tool_to_pad" from the constructor,
  // before hdInitDevice (as FixedPoseSource refuses a bad pose). Happened:
  // accepted; every pose then has a NaN position and quaternion (NaN), or a
  // scaled offset and a quaternion that does not match the rotation (scaled).
  fake_hd::reset();
  Eigen::Isometry3d tool_to_pad = Eigen::Isometry3d::Identity();
  SUBCASE("NaN") { tool_to_pad.translation().x() = std::numeric_limits<double>::quiet_NaN(); }
  SUBCASE("scaled") { tool_to_pad.linear() *= 2.0; }
  bool refused = false;
  try {
    OpenHapticsPoseSource src("", tool_to_pad);
  } catch (const iclap::InvalidArgument& e) {
    refused = true;
    CHECK(e.argument() == "tool_to_pad");
  }
  CHECK(refused);
  CHECK(fake_hd::state.calls.empty());
}

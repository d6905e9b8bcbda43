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
#include <vector>

#include <HD/hd.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iclap/rig/openhaptics_pose.hpp"

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

// The message of the TransportError that `f` throws ("" if none).
template <typename F>
std::string transport_error(F&& f) {
  try {
    f();
  } catch (const TransportError& e) {
    return e.what();
  }
  return "";
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

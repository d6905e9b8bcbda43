// SPDX-License-Identifier: MIT
#pragma once

// Pose of a Phantom Omni (or Geomagic Touch) arm through the OpenHaptics HD
// API. Including this header is the opt-in: it needs OpenHaptics (<HD/hd.h>,
// link libHD), which is not in Debian and which no other iclap header
// includes. The examples build it only when CMake finds HD/hd.h
// (compile definition ICLAP_HAVE_OPENHAPTICS).
//
// Tested against a scripted fake of the HD API (tests/rig/fake_hd), not
// against OpenHaptics or an arm: none was available. It follows the HD API's
// documented pattern (init device, start the scheduler, read the transform
// inside a synchronous scheduler callback, errors from HD's error stack).
// Whether HD reports an error raised in the servo thread's callback to
// hdGetError on the calling thread, as the fake does, is not known; a read
// that wrote nothing leaves a zero transform, which next() refuses as not
// rigid. Check it on the rig before relying on it.

#include <HD/hd.h>

#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iclap/core/error.hpp"
#include "iclap/core/rotation.hpp"
#include "iclap/rig/byte_stream.hpp"
#include "iclap/rig/pose_source.hpp"

namespace iclap::rig {

/// Pad poses from the arm's current end-effector transform. OpenHaptics
/// reports millimetres in the arm's base frame; poses are returned in metres,
/// with `tool_to_pad` (metres, tool frame) applied to place the pad centre.
/// One instance per process (HD owns a global scheduler).
class OpenHapticsPoseSource final : public PoseSource {
 public:
  /// `device`: the OpenHaptics configuration name ("" = default device).
  /// Throws InvalidArgument naming "tool_to_pad" unless it is finite and
  /// rigid (its linear part a rotation within kRotationTolerance), before
  /// touching the arm; TransportError ("openhaptics:DEVICE") if the arm
  /// cannot start. Errors left on HD's error stack by an earlier HD user are
  /// discarded first, so they are not taken for this arm's.
  explicit OpenHapticsPoseSource(const std::string& device = "",
                                 const Eigen::Isometry3d& tool_to_pad = Eigen::Isometry3d::Identity())
      : name_("openhaptics:" + (device.empty() ? std::string("default") : device)), tool_to_pad_(tool_to_pad) {
    if (const std::string why = rigid_fault(tool_to_pad_.matrix()); !why.empty())
      throw InvalidArgument("tool_to_pad", why);
    drain_errors();
    handle_ = hdInitDevice(device.empty() ? HD_DEFAULT_DEVICE : device.c_str());
    if (const std::string error = pending_errors(); !error.empty()) {
      if (handle_ != HD_INVALID_HANDLE) hdDisableDevice(handle_);
      drain_errors();
      throw TransportError(name_, "cannot initialise the arm: " + error);
    }
    hdStartScheduler();
    if (const std::string error = pending_errors(); !error.empty()) {
      hdDisableDevice(handle_);
      drain_errors();
      throw TransportError(name_, "cannot start the servo scheduler: " + error);
    }
  }
  ~OpenHapticsPoseSource() override {
    hdStopScheduler();
    hdDisableDevice(handle_);
  }
  OpenHapticsPoseSource(const OpenHapticsPoseSource&) = delete;
  OpenHapticsPoseSource& operator=(const OpenHapticsPoseSource&) = delete;

  /// The pad's pose now. Throws TransportError naming the source if HD
  /// reports an error for the read (every error it reports is consumed), or
  /// if the transform it read is not finite or not rigid (its rotation block
  /// off a rotation by more than kRotationTolerance): no NaN and no made-up
  /// orientation is passed on.
  std::optional<Pose> next() override {
    Sample s{handle_, {}};
    hdScheduleSynchronous(&OpenHapticsPoseSource::read_transform, &s, HD_DEFAULT_SCHEDULER_PRIORITY);
    if (const std::string error = pending_errors(); !error.empty())
      throw TransportError(name_, "cannot read the arm's transform: " + error);
    Eigen::Matrix4d m;
    for (int i = 0; i < 16; ++i) m(i % 4, i / 4) = s.transform[i];  // column-major
    if (const std::string why = rigid_fault(m); !why.empty())
      throw TransportError(name_, "the arm reported a transform that is not a pose: " + why);
    Eigen::Isometry3d T_base_tool = Eigen::Isometry3d::Identity();
    T_base_tool.linear() = m.topLeftCorner<3, 3>();
    T_base_tool.translation() = m.topRightCorner<3, 1>() * 1e-3;  // mm -> m
    const Eigen::Isometry3d T_base_pad = T_base_tool * tool_to_pad_;
    Pose p;
    p.position = T_base_pad.translation();
    p.orientation = Eigen::Quaterniond(T_base_pad.linear()).normalized();
    return p;
  }
  bool has_orientation() const override { return true; }
  std::string description() const override { return name_; }

 private:
  struct Sample {
    HHD handle;
    HDdouble transform[16];
  };
  static HDCallbackCode HDCALLBACK read_transform(void* data) {
    auto* s = static_cast<Sample*>(data);
    hdBeginFrame(s->handle);
    hdGetDoublev(HD_CURRENT_TRANSFORM, s->transform);
    hdEndFrame(s->handle);
    return HD_CALLBACK_DONE;
  }
  /// Pops every error on HD's stack; "" if there was none, else the newest
  /// one's text, with how many more there were (a faulting device fails
  /// several calls of one frame, and one left behind would fail the next
  /// healthy read). At most kMaxErrors are popped, in case the stack never
  /// empties.
  static std::string pending_errors() {
    std::string first;
    int more = 0;
    for (int i = 0; i < kMaxErrors; ++i) {
      const HDErrorInfo e = hdGetError();
      if (!HD_DEVICE_ERROR(e)) break;
      if (first.empty()) first = hdGetErrorString(e.errorCode);
      else ++more;
    }
    if (more > 0) first += " (and " + std::to_string(more) + " more error" + (more > 1 ? "s" : "") + ")";
    return first;
  }
  static void drain_errors() { (void)pending_errors(); }

  /// "" if `m` is a finite rigid transform (bottom row 0 0 0 1, rotation
  /// block a rotation within kRotationTolerance: see rotation_fault, which
  /// RigidTransform::check_rotation shares), else what is wrong.
  static std::string rigid_fault(const Eigen::Matrix4d& m) {
    if (!m.allFinite()) return "it holds a NaN or an infinity";
    if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > kRotationTolerance)
      return "its bottom row is not 0 0 0 1";
    if (const std::string why = rotation_fault(m.topLeftCorner<3, 3>(), kRotationTolerance); !why.empty())
      return "its rotation block " + why;
    return {};
  }

  /// How far from orthonormal a rotation block may be (entries of
  /// |R^T R - I|): a rotation rounded to float is off by about 1e-7.
  static constexpr double kRotationTolerance = 1e-3;
  static constexpr int kMaxErrors = 64;

  std::string name_;
  Eigen::Isometry3d tool_to_pad_;
  HHD handle_{};
};

}  // namespace iclap::rig

// SPDX-License-Identifier: MIT
#pragma once

// Pose of a Phantom Omni (or Geomagic Touch) arm through the OpenHaptics HD
// API. Including this header is the opt-in: it needs OpenHaptics (<HD/hd.h>,
// link libHD), which is not in Debian and which no other iclap header
// includes. The examples build it only when CMake finds HD/hd.h
// (compile definition ICLAP_HAVE_OPENHAPTICS).
//
// UNTESTED: no OpenHaptics installation or arm was available when this was
// written. It follows the HD API's documented pattern (init device, start
// the scheduler, read the transform inside a synchronous scheduler
// callback). Check it on the rig before relying on it.

#include <HD/hd.h>

#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

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
  /// Throws TransportError ("openhaptics:DEVICE") if the arm cannot start.
  explicit OpenHapticsPoseSource(const std::string& device = "",
                                 const Eigen::Isometry3d& tool_to_pad = Eigen::Isometry3d::Identity())
      : name_("openhaptics:" + (device.empty() ? std::string("default") : device)), tool_to_pad_(tool_to_pad) {
    handle_ = hdInitDevice(device.empty() ? HD_DEFAULT_DEVICE : device.c_str());
    check("cannot initialise the arm");
    hdStartScheduler();
    if (HD_DEVICE_ERROR(hdGetError())) {
      hdDisableDevice(handle_);
      throw TransportError(name_, "cannot start the servo scheduler");
    }
  }
  ~OpenHapticsPoseSource() override {
    hdStopScheduler();
    hdDisableDevice(handle_);
  }
  OpenHapticsPoseSource(const OpenHapticsPoseSource&) = delete;
  OpenHapticsPoseSource& operator=(const OpenHapticsPoseSource&) = delete;

  std::optional<Pose> next() override {
    Sample s{handle_, {}};
    hdScheduleSynchronous(&OpenHapticsPoseSource::read_transform, &s, HD_DEFAULT_SCHEDULER_PRIORITY);
    check("cannot read the arm's transform");
    Eigen::Matrix4d m;
    for (int i = 0; i < 16; ++i) m(i % 4, i / 4) = s.transform[i];  // column-major
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
  void check(const char* what) const {
    const HDErrorInfo e = hdGetError();
    if (HD_DEVICE_ERROR(e))
      throw TransportError(name_, std::string(what) + ": " + hdGetErrorString(e.errorCode));
  }

  std::string name_;
  Eigen::Isometry3d tool_to_pad_;
  HHD handle_{};
};

}  // namespace iclap::rig

// SPDX-License-Identifier: MIT
#pragma once

// A test-only stand-in for the OpenHaptics HD API (<HD/hd.h>), so that
// iclap/rig/openhaptics_pose.hpp compiles and runs without OpenHaptics (not in
// Debian) or an arm. Written for iclap from the names and types that header
// uses; it is not the vendor's header and copies nothing from it. The error
// codes' values are our own.
//
// It models what the pose source relies on: one device, a servo scheduler
// that runs synchronous callbacks (here at once, on the calling thread), frames
// around reads, and HD's error stack (every failing call pushes one error,
// hdGetError pops the newest, or returns HD_SUCCESS when the stack is empty).
// The test scripts it through fake_hd::state: the transform the arm reports
// (column-major, millimetres) and errors to inject at init, at scheduler start
// and at reading; it records every call in order in fake_hd::state.calls.
// Inline functions and variables only (C++17), so one test TU needs no
// library. Call fake_hd::reset() at the start of every test.

#include <string>
#include <vector>

// Tests check this to be sure they were not built against a real OpenHaptics.
#define ICLAP_FAKE_HD 1

using HHD = unsigned int;
using HDdouble = double;
using HDenum = unsigned int;
using HDushort = unsigned short;
using HDErrorCode = unsigned int;
using HDCallbackCode = unsigned int;
using HDstring = const char*;

struct HDErrorInfo {
  HDErrorCode errorCode;
  int internalErrorCode;
  HHD hHD;
};

// On Windows the vendor's callbacks are __stdcall; nothing here.
#define HDCALLBACK
#define HD_DEVICE_ERROR(X) (((X).errorCode) != HD_SUCCESS)

inline constexpr HDErrorCode HD_SUCCESS = 0x0000;
inline constexpr HDErrorCode HD_INVALID_ENUM = 0x0100;
inline constexpr HDErrorCode HD_INVALID_OPERATION = 0x0101;
inline constexpr HDErrorCode HD_ILLEGAL_BEGIN = 0x0102;
inline constexpr HDErrorCode HD_ILLEGAL_END = 0x0103;
inline constexpr HDErrorCode HD_DEVICE_FAULT = 0x0200;
inline constexpr HDErrorCode HD_COMM_ERROR = 0x0201;
inline constexpr HDErrorCode HD_TIMER_ERROR = 0x0202;

inline constexpr HHD HD_INVALID_HANDLE = 0xFFFFFFFFu;
inline constexpr HDstring HD_DEFAULT_DEVICE = nullptr;
inline constexpr HDCallbackCode HD_CALLBACK_DONE = 0;
inline constexpr HDCallbackCode HD_CALLBACK_CONTINUE = 1;
inline constexpr HDushort HD_MIN_SCHEDULER_PRIORITY = 0;
inline constexpr HDushort HD_MAX_SCHEDULER_PRIORITY = 0xFFFF;
inline constexpr HDushort HD_DEFAULT_SCHEDULER_PRIORITY = 0x7FFF;
inline constexpr HDenum HD_CURRENT_POSITION = 0x2050;
inline constexpr HDenum HD_CURRENT_TRANSFORM = 0x2052;

using HDSchedulerCallback = HDCallbackCode(HDCALLBACK*)(void*);

namespace fake_hd {

struct State {
  // --- Script (set by the test) ---
  // The arm's end-effector transform, 4x4 column-major, translation in mm.
  HDdouble transform[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  // The handle hdInitDevice returns on success (not 0, so that a handle
  // left at HHD{} is told apart from the real one).
  HHD handle = 7;
  // Errors to inject (HD_SUCCESS = none). Each failing call pushes one error
  // on the stack; init_error makes hdInitDevice return HD_INVALID_HANDLE.
  HDErrorCode init_error = HD_SUCCESS;
  HDErrorCode start_error = HD_SUCCESS;
  HDErrorCode begin_frame_error = HD_SUCCESS;
  HDErrorCode read_error = HD_SUCCESS;  // hdGetDoublev (the transform is not written)
  HDErrorCode end_frame_error = HD_SUCCESS;

  // --- Record ---
  std::vector<std::string> calls;   // e.g. "hdInitDevice(default)", "hdDisableDevice(7)"
  std::vector<HDErrorInfo> errors;  // HD's error stack, newest last
  std::vector<HHD> enabled;         // devices initialised and not yet disabled
  bool scheduler_running = false;
  bool in_callback = false;  // inside a scheduler callback (the servo thread)
  bool in_frame = false;
};

inline State state;

inline void reset() { state = State{}; }

inline void push_error(HDErrorCode code, HHD device) { state.errors.push_back(HDErrorInfo{code, 0, device}); }

/// Sets the reported transform from a column-major array (mm).
inline void set_transform(const HDdouble (&m)[16]) {
  for (int i = 0; i < 16; ++i) state.transform[i] = m[i];
}

}  // namespace fake_hd

inline HHD hdInitDevice(HDstring config_name) {
  fake_hd::state.calls.push_back(std::string("hdInitDevice(") + (config_name ? config_name : "default") + ")");
  if (fake_hd::state.init_error != HD_SUCCESS) {
    fake_hd::push_error(fake_hd::state.init_error, HD_INVALID_HANDLE);
    return HD_INVALID_HANDLE;
  }
  fake_hd::state.enabled.push_back(fake_hd::state.handle);
  return fake_hd::state.handle;
}

inline void hdDisableDevice(HHD device) {
  fake_hd::state.calls.push_back("hdDisableDevice(" + std::to_string(device) + ")");
  auto& e = fake_hd::state.enabled;
  for (auto it = e.begin(); it != e.end(); ++it)
    if (*it == device) {
      e.erase(it);
      return;
    }
  fake_hd::push_error(HD_INVALID_OPERATION, device);
}

inline void hdStartScheduler() {
  fake_hd::state.calls.push_back("hdStartScheduler");
  if (fake_hd::state.start_error != HD_SUCCESS) {
    fake_hd::push_error(fake_hd::state.start_error, HD_INVALID_HANDLE);
    return;
  }
  fake_hd::state.scheduler_running = true;
}

inline void hdStopScheduler() {
  fake_hd::state.calls.push_back("hdStopScheduler");
  fake_hd::state.scheduler_running = false;
}

inline HDErrorInfo hdGetError() {
  auto& s = fake_hd::state.errors;
  if (s.empty()) return HDErrorInfo{HD_SUCCESS, 0, HD_INVALID_HANDLE};
  const HDErrorInfo e = s.back();
  s.pop_back();
  return e;
}

inline HDstring hdGetErrorString(HDErrorCode code) {
  switch (code) {
    case HD_SUCCESS: return "no error";
    case HD_INVALID_ENUM: return "invalid enum";
    case HD_INVALID_OPERATION: return "invalid operation";
    case HD_ILLEGAL_BEGIN: return "illegal begin frame";
    case HD_ILLEGAL_END: return "illegal end frame";
    case HD_DEVICE_FAULT: return "device fault";
    case HD_COMM_ERROR: return "communication error";
    case HD_TIMER_ERROR: return "timer error";
    default: return "unknown error";
  }
}

inline void hdScheduleSynchronous(HDSchedulerCallback callback, void* data, HDushort priority) {
  fake_hd::state.calls.push_back("hdScheduleSynchronous(" + std::to_string(priority) + ")");
  if (!fake_hd::state.scheduler_running) {
    fake_hd::push_error(HD_TIMER_ERROR, HD_INVALID_HANDLE);
    return;
  }
  fake_hd::state.in_callback = true;
  // The source's callbacks read once and return HD_CALLBACK_DONE; anything
  // else would be rescheduled forever by the real scheduler.
  const HDCallbackCode code = callback(data);
  fake_hd::state.in_callback = false;
  if (code != HD_CALLBACK_DONE) fake_hd::state.calls.push_back("callback returned " + std::to_string(code));
}

inline void hdBeginFrame(HHD device) {
  fake_hd::state.calls.push_back("hdBeginFrame(" + std::to_string(device) + ")");
  if (!fake_hd::state.in_callback || fake_hd::state.in_frame) {
    fake_hd::push_error(HD_ILLEGAL_BEGIN, device);
    return;
  }
  fake_hd::state.in_frame = true;
  if (fake_hd::state.begin_frame_error != HD_SUCCESS) fake_hd::push_error(fake_hd::state.begin_frame_error, device);
}

inline void hdEndFrame(HHD device) {
  fake_hd::state.calls.push_back("hdEndFrame(" + std::to_string(device) + ")");
  if (!fake_hd::state.in_frame) {
    fake_hd::push_error(HD_ILLEGAL_END, device);
    return;
  }
  fake_hd::state.in_frame = false;
  if (fake_hd::state.end_frame_error != HD_SUCCESS) fake_hd::push_error(fake_hd::state.end_frame_error, device);
}

inline void hdGetDoublev(HDenum name, HDdouble* values) {
  fake_hd::state.calls.push_back(name == HD_CURRENT_TRANSFORM ? std::string("hdGetDoublev(HD_CURRENT_TRANSFORM)")
                                                              : "hdGetDoublev(" + std::to_string(name) + ")");
  if (!fake_hd::state.in_frame) {
    fake_hd::push_error(HD_INVALID_OPERATION, HD_INVALID_HANDLE);
    return;
  }
  if (name != HD_CURRENT_TRANSFORM) {
    fake_hd::push_error(HD_INVALID_ENUM, HD_INVALID_HANDLE);
    return;
  }
  if (fake_hd::state.read_error != HD_SUCCESS) {
    fake_hd::push_error(fake_hd::state.read_error, HD_INVALID_HANDLE);
    return;
  }
  for (int i = 0; i < 16; ++i) values[i] = fake_hd::state.transform[i];
}

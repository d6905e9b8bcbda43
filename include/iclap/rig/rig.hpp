// SPDX-License-Identifier: MIT
#pragma once

/// \file
/// Umbrella header of the rig layer's portable part (needs only Eigen): the
/// WTS protocol codec and stream parser, the byte-stream and pose-source
/// interfaces, the sensor session and the frame sources. The OS- and
/// vendor-specific parts are opt-in, each in its own header:
/// - iclap/rig/serial_port.hpp, serial_enumeration.hpp  (POSIX termios)
/// - iclap/rig/hid_device.hpp                           (hidapi)
/// - iclap/rig/openhaptics_pose.hpp                     (OpenHaptics HD)
/// - iclap/rig/pose_spec.hpp (command-line pose specs; OpenHaptics only
///   with ICLAP_HAVE_OPENHAPTICS)

#include "iclap/rig/byte_stream.hpp"
#include "iclap/rig/crc16.hpp"
#include "iclap/rig/dataset_frame_source.hpp"
#include "iclap/rig/frame_source.hpp"
#include "iclap/rig/packet_framer.hpp"
#include "iclap/rig/pose_source.hpp"
#include "iclap/rig/sensor_frame_source.hpp"
#include "iclap/rig/stream_parser.hpp"
#include "iclap/rig/wts_message.hpp"
#include "iclap/rig/wts_protocol.hpp"
#include "iclap/rig/wts_sensor.hpp"

// SPDX-License-Identifier: MIT
#pragma once

// What hidapi reports about one HID interface (enumerate_hid_devices in
// hid_device.hpp), in a header of its own that does not need hidapi, for
// code that only shows or filters the list.

#include <cstdint>
#include <string>

namespace iclap::rig {

/// One HID interface as enumerated by hidapi.
struct HidDeviceInfo {
  std::string path;  ///< platform path for HidDevice (hidraw: /dev/hidrawN)
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::string manufacturer;
  std::string product;
  std::string serial_number;
  std::uint16_t release_number = 0;  ///< BCD
  std::uint16_t usage_page = 0;
  std::uint16_t usage = 0;
  int interface_number = -1;
  std::string bus;  ///< "usb", "bluetooth", "i2c", "spi" or "unknown"
};

}  // namespace iclap::rig

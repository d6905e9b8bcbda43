// SPDX-License-Identifier: MIT
#pragma once

// The lines `iclap devices` prints for one serial port and one HID device,
// apart from the enumeration, so that tests can check them without devices
// (and without hidapi). Names from the device or the file system are
// written as escape_text writes them: a product string with a line break,
// an escape sequence or bytes that are not UTF-8 cannot forge lines or
// drive the terminal.

#include <cstdio>
#include <string>

#include "iclap/core/error.hpp"
#include "iclap/rig/hid_device_info.hpp"
#include "iclap/rig/serial_enumeration.hpp"

namespace iclap::cli {

/// A serial port's lines: its path (and a permission hint when the user may
/// not open it), then one line per alias and per by-id name.
inline std::string serial_port_lines(const rig::SerialPortInfo& p) {
  std::string out = "  " + escape_text(p.path);
  if (!p.accessible) out += "  [no read/write permission: add your user to the port's group, usually 'dialout']";
  out += "\n";
  for (const auto& alias : p.aliases) out += "      alias: " + escape_text(alias) + "\n";
  for (const auto& link : p.by_id) out += "      by-id: " + escape_text(link) + "\n";
  return out;
}

/// A HID device's line: path, vendor:product, names, serial number, usage
/// and interface.
inline std::string hid_device_line(const rig::HidDeviceInfo& d) {
  char ids[32];
  std::snprintf(ids, sizeof ids, "  %04x:%04x", d.vendor_id, d.product_id);
  std::string out = "  " + escape_text(d.path) + ids;
  const std::string name = d.manufacturer.empty() ? d.product : d.manufacturer + " " + d.product;
  if (!name.empty()) out += "  " + escape_text(name);
  if (!d.serial_number.empty()) out += "  serial " + escape_text(d.serial_number);
  char rest[128];
  std::snprintf(rest, sizeof rest, "  (usage page 0x%04x, usage 0x%04x, interface %d, ", d.usage_page, d.usage,
                d.interface_number);
  return out + rest + escape_text(d.bus) + ")\n";
}

}  // namespace iclap::cli

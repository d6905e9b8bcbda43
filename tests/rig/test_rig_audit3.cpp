// SPDX-License-Identifier: MIT
// Reproducers of two defects left by the session-57 rig audit (session 58):
// a udev alias among the serial ports, and HID device strings printed raw.
// Each case failed on the code it was written against; the comment above
// it says what the input is, what used to happen and what happens now.
//
// Build: like test_rig_audit2 (include tests/rig and examples/iclap, link
// util). The `iclap devices` case needs ICLAP_CLI_PATH and is left out
// without it.

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "device_listing.hpp"
#include "iclap/rig/hid_device_info.hpp"
#include "iclap/rig/serial_enumeration.hpp"
#include "../support/temporaries.hpp"
#ifdef ICLAP_CLI_PATH
#include "process_util.hpp"
#endif

using namespace iclap::rig;
namespace fs = std::filesystem;

namespace {
std::vector<std::string> port_paths(const std::vector<SerialPortInfo>& ports) {
  std::vector<std::string> paths;
  for (const auto& p : ports) paths.push_back(p.path);
  return paths;
}
}  // namespace

// Input: a device root with the devices ttyACM0 and ttyUSB3, the udev
// aliases ttyUSB1 and ttyUSB2 -> ttyACM0 and ttyACM7 -> ttyUSB3 (an alias
// that sorts before its device), and a by-id link made through an alias.
// Was: one port per device, named after whichever of its names the
// directory listed first (the alias ttyACM7 could hide the device
// ttyUSB3, or the other way round); the other names were lost.
// Now: each device once under its own node, its aliases listed, sorted.
TEST_CASE("list_serial_ports: a udev alias of another port is kept as an alias of the device") {
  const iclap::test::TempDir scratch("h58b_alias");
  const fs::path root = scratch.path / "dev";
  fs::create_directories(root / "serial" / "by-id");
  std::ofstream(root / "ttyACM0") << "";
  std::ofstream(root / "ttyUSB3") << "";
  fs::create_symlink("ttyACM0", root / "ttyUSB2");
  fs::create_symlink("ttyACM0", root / "ttyUSB1");
  fs::create_symlink("ttyUSB3", root / "ttyACM7");
  fs::create_symlink("../../ttyUSB1", root / "serial" / "by-id" / "usb-wts-if00");
  const auto ports = list_serial_ports(root.string());
  CHECK(port_paths(ports) == std::vector<std::string>{(root / "ttyACM0").string(), (root / "ttyUSB3").string()});
  REQUIRE(ports.size() == 2);
  CHECK(ports[0].aliases == std::vector<std::string>{(root / "ttyUSB1").string(), (root / "ttyUSB2").string()});
  CHECK(ports[0].by_id == std::vector<std::string>{(root / "serial" / "by-id" / "usb-wts-if00").string()});
  CHECK(ports[1].aliases == std::vector<std::string>{(root / "ttyACM7").string()});
  CHECK(ports[1].by_id.empty());
}

// Input: two aliases ttyUSB4 and ttyUSB10 of a device outside the candidate
// names (ttyS0), and a port without aliases.
// Now: one port, under the first alias in natural order, the other as its
// alias; a port without aliases has none.
TEST_CASE("list_serial_ports: aliases of a device that is no candidate are one port") {
  const iclap::test::TempDir scratch("h58b_alias_other");
  const fs::path root = scratch.path / "dev";
  fs::create_directories(root);
  std::ofstream(root / "ttyS0") << "";
  std::ofstream(root / "ttyACM1") << "";
  fs::create_symlink("ttyS0", root / "ttyUSB10");
  fs::create_symlink("ttyS0", root / "ttyUSB4");
  const auto ports = list_serial_ports(root.string());
  CHECK(port_paths(ports) == std::vector<std::string>{(root / "ttyACM1").string(), (root / "ttyUSB4").string()});
  REQUIRE(ports.size() == 2);
  CHECK(ports[0].aliases.empty());
  CHECK(ports[1].aliases == std::vector<std::string>{(root / "ttyUSB10").string()});
}

// Input: the line `iclap devices` prints for a HID device whose strings
// (the device's own, from hidapi) hold an OSC escape sequence that sets the
// terminal's title, a line break that starts a forged line, the C1 control
// CSI (U+009B) and bytes that are not UTF-8.
// Was: printed raw, so the device drove the terminal and forged output.
// Now: each such byte written as \xNN (as quote_text writes them); UTF-8
// names are kept; the line is one line.
TEST_CASE("iclap devices: HID device strings are printed with control bytes and bad UTF-8 escaped") {
  HidDeviceInfo d;
  d.path = "/dev/hidraw3";
  d.vendor_id = 0x046d;
  d.product_id = 0xc52b;
  d.manufacturer = "M\xc3\xbcller\x1b]0;pwned\x07";
  d.product = "Pedal\r\nHID devices: fake \xc2\x9b" "2J";
  d.serial_number = "\xff\xfe" "42";
  d.usage_page = 0x000c;
  d.usage = 0x0001;
  d.interface_number = 0;
  d.bus = "usb";
  const std::string line = iclap::cli::hid_device_line(d);
  CHECK(line ==
        "  /dev/hidraw3  046d:c52b  M\xc3\xbcller\\x1b]0;pwned\\x07 Pedal\\x0d\\x0aHID devices: fake \\xc2\\x9b2J"
        "  serial \\xff\\xfe42  (usage page 0x000c, usage 0x0001, interface 0, usb)\n");
  // Plain strings are unchanged.
  d.manufacturer = "Acme";
  d.product = "Foot pedal";
  d.serial_number = "A1";
  CHECK(iclap::cli::hid_device_line(d) ==
        "  /dev/hidraw3  046d:c52b  Acme Foot pedal  serial A1  (usage page 0x000c, usage 0x0001, interface 0, usb)\n");
}

// Input: the lines of a serial port whose by-id and alias names (under a
// --dev-root of the user's choice) hold an escape sequence and a line break.
// Was: printed raw.
// Now: escaped like the HID strings.
TEST_CASE("iclap devices: serial port names are printed with control bytes escaped") {
  SerialPortInfo p;
  p.path = "/dev/ttyACM0";
  p.accessible = true;
  p.aliases = {"/dev/ttyUSB\x1b[2J"};
  p.by_id = {"/dev/serial/by-id/usb-x\nfake"};
  CHECK(iclap::cli::serial_port_lines(p) ==
        "  /dev/ttyACM0\n      alias: /dev/ttyUSB\\x1b[2J\n      by-id: /dev/serial/by-id/usb-x\\x0afake\n");
}

#ifdef ICLAP_CLI_PATH
// Input: `iclap devices --serial-only --dev-root DIR` where DIR holds the
// device ttyACM0 and a udev alias ttyUSB1 -> ttyACM0.
// Was: one port, listed under whichever name the directory listed first;
// the other name appeared nowhere.
// Now: the device is listed once as ttyACM0, with "alias: DIR/ttyUSB1".
TEST_CASE("iclap devices: a udev alias of a listed port is shown, not dropped") {
  test::ScratchDir scratch("h58b_alias_cli");
  const fs::path root = scratch.path / "dev";
  fs::create_directories(root);
  std::ofstream(root / "ttyACM0") << "";
  fs::create_symlink("ttyACM0", root / "ttyUSB1");
  const auto r = test::run_iclap({"devices", "--serial-only", "--dev-root", root.string()}, scratch);
  INFO(r.out);
  INFO(r.err);
  CHECK(r.status == 0);
  CHECK(r.out.find("\n  " + (root / "ttyACM0").string() + "\n") != std::string::npos);
  CHECK(r.out.find("\n      alias: " + (root / "ttyUSB1").string() + "\n") != std::string::npos);
}
#endif

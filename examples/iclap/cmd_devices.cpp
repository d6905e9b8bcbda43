// SPDX-License-Identifier: MIT
//
// `iclap devices`: lists the serial ports where the WTS sensor can appear
// and the HID devices (pedals, buttons, bridges) hidapi can open.

#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

#include "cli.hpp"
#include "device_listing.hpp"
#include "iclap/rig/serial_enumeration.hpp"
#ifdef ICLAP_HAVE_HIDAPI
#include "iclap/rig/hid_device.hpp"
#endif

namespace {

using namespace iclap::cli;

const char* const kUsage =
    "usage: iclap devices [--serial-only | --hid-only] [--dev-root DIR]\n"
    "\n"
    "Lists the serial ports where a Weiss WTS sensor can appear (USB CDC-ACM:\n"
    "/dev/ttyACM*, also /dev/ttyUSB* and the stable /dev/serial/by-id names),\n"
    "each device once with its other names (aliases: udev symlinks, by-id),\n"
    "and the HID devices found by hidapi (foot pedals, stylus buttons,\n"
    "microcontroller bridges). The sensor itself is not a HID device.\n"
    "Says so plainly when nothing is found; exit status 0 either way (but 2 when\n"
    "--dev-root names no directory).\n"
    "\n"
    "  --serial-only    list serial ports only\n"
    "  --hid-only       list HID devices only\n"
    "  --dev-root DIR   look for serial ports under DIR instead of /dev";

void list_serial(const std::string& root) {
  const auto ports = iclap::rig::list_serial_ports(root);
  if (ports.empty()) {
    std::printf("Serial ports: none found (looked for %s/ttyACM*, %s/ttyUSB* and %s/serial/by-id/*)\n",
                root.c_str(), root.c_str(), root.c_str());
    return;
  }
  std::printf("Serial ports (the WTS sensor is USB CDC-ACM, usually ttyACM*):\n");
  for (const auto& p : ports) std::fputs(serial_port_lines(p).c_str(), stdout);
}

#ifdef ICLAP_HAVE_HIDAPI
void list_hid() {
  const auto devices = iclap::rig::enumerate_hid_devices();
  const std::string version = iclap::rig::HidLibrary::version();
  if (devices.empty()) {
    std::printf("HID devices: none found (hidapi %s)\n", version.c_str());
    return;
  }
  std::printf("HID devices (hidapi %s):\n", version.c_str());
  for (const auto& d : devices) std::fputs(hid_device_line(d).c_str(), stdout);
}
#endif

int run_devices(const Args& args) {
  const Options o(args, {"dev-root"}, {"serial-only", "hid-only"});
  o.expect_positional(0, 0, "no positional arguments");
  if (o.flag("serial-only") && o.flag("hid-only"))
    throw UsageError("--serial-only and --hid-only exclude each other");
  const std::string root = o.string("dev-root", "/dev");
  // A --dev-root that is no directory (a typo) must not read as "none
  // found", which says the devices are absent.
  std::error_code ec;
  if (o.has("dev-root") && !std::filesystem::is_directory(root, ec))
    throw UsageError("--dev-root " + iclap::quote_text(root, 200) + " is not a directory");
  if (!o.flag("hid-only")) list_serial(root);
  if (!o.flag("serial-only")) {
#ifdef ICLAP_HAVE_HIDAPI
    list_hid();
#else
    std::printf("HID devices: not available (this iclap was built without hidapi)\n");
#endif
  }
  return kExitOk;
}

}  // namespace

ICLAP_COMMAND("devices", "list serial ports and HID devices of the rig", kUsage, run_devices);

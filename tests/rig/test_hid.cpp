// SPDX-License-Identifier: MIT
// The hidapi transport: builds, links, enumerates (CI machines have no HID
// devices, so the list may be empty), and reports open errors by path.

#include <doctest/doctest.h>

#include <string>

#include "iclap/rig/hid_device.hpp"

using namespace iclap::rig;

TEST_CASE("hidapi: library version and enumeration") {
  CHECK(HidLibrary::version().rfind(std::to_string(HID_API_VERSION_MAJOR) + "." +
                                        std::to_string(HID_API_VERSION_MINOR) + ".",
                                    0) == 0);
  const auto devices = enumerate_hid_devices();
  for (const auto& d : devices) {
    CHECK_FALSE(d.path.empty());
    CHECK_FALSE(d.bus.empty());
  }
  MESSAGE("HID devices on this machine: " << devices.size());
  // A vendor/product pair nobody uses: an empty list, no error.
  CHECK(enumerate_hid_devices(0xFFFF, 0xFFFE).empty());
  // Library init is reference-counted: nested users are fine.
  HidLibrary a;
  {
    HidLibrary b;
    CHECK(enumerate_hid_devices(0xFFFF, 0xFFFE).empty());
  }
  CHECK(enumerate_hid_devices(0xFFFF, 0xFFFE).empty());
}

TEST_CASE("hidapi: open errors name the path; settings are checked first") {
  try {
    HidDevice d("/dev/iclap-no-such-hidraw");
    FAIL("opened a missing device");
  } catch (const TransportError& e) {
    CHECK(e.path() == "/dev/iclap-no-such-hidraw");
    CHECK(std::string(e.what()).find("cannot open HID device") != std::string::npos);
  }
  CHECK_THROWS_AS(HidByteStream("/dev/iclap-no-such-hidraw"), TransportError);
  HidByteStream::Settings s;
  s.report_size = 1;
  CHECK_THROWS_AS(HidByteStream("/dev/iclap-no-such-hidraw", s), iclap::InvalidArgument);
}

TEST_CASE("hidapi: wide strings become UTF-8") {
  CHECK(hid_detail::to_utf8(nullptr).empty());
  CHECK(hid_detail::to_utf8(L"Weiss") == "Weiss");
  CHECK(hid_detail::to_utf8(L"\u00e9") == "\xC3\xA9");
  CHECK(hid_detail::to_utf8(L"\u4e2d") == "\xE4\xB8\xAD");
  CHECK(hid_detail::to_utf8(L"\U0001F600") == "\xF0\x9F\x98\x80");
}

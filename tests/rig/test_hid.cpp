// SPDX-License-Identifier: MIT
// The hidapi transport: builds, links, enumerates (CI machines have no HID
// devices, so the list may be empty), and reports open errors by path.

#include <doctest/doctest.h>

#include <cstddef>
#include <cstdint>
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

TEST_CASE("hidapi: code points UTF-8 cannot carry become U+FFFD, their neighbours stay") {
  const auto utf8_of = [](std::uint32_t c) {
    const wchar_t text[] = {static_cast<wchar_t>(c), 0};
    return hid_detail::to_utf8(text);
  };
  const std::string replacement = "\xEF\xBF\xBD";
  CHECK(utf8_of(0xD800) == replacement);  // the surrogate range, both ends
  CHECK(utf8_of(0xDFFF) == replacement);
  CHECK(utf8_of(0x110000) == replacement);  // past the last code point
  CHECK(utf8_of(0xD7FF) == "\xED\x9F\xBF");
  CHECK(utf8_of(0xE000) == "\xEE\x80\x80");
  CHECK(utf8_of(0x10FFFF) == "\xF4\x8F\xBF\xBF");
}

TEST_CASE("hidapi: report_size 2..4096 is accepted, outside it named before the device is opened") {
  for (std::size_t size : {std::size_t{0}, std::size_t{1}, std::size_t{4097}}) {
    CAPTURE(size);
    HidByteStream::Settings s;
    s.report_size = size;
    try {
      HidByteStream stream("/dev/iclap-no-such-hidraw", s);
      FAIL("accepted a bad report size");
    } catch (const iclap::InvalidArgument& e) {
      CHECK(e.argument() == "settings.report_size");
      CHECK(e.reason().find(std::to_string(size)) != std::string::npos);
    }
  }
  // At the bounds the settings pass and the missing device is what fails.
  for (std::size_t size : {std::size_t{2}, std::size_t{4096}}) {
    CAPTURE(size);
    HidByteStream::Settings s;
    s.report_size = size;
    CHECK_THROWS_AS(HidByteStream("/dev/iclap-no-such-hidraw", s), TransportError);
  }
}

TEST_CASE("hidapi: a device that is not there is an open error with hidapi's reason, not an unplug") {
  try {
    HidDevice d("/dev/iclap-no-such-hidraw");
    FAIL("opened a missing device");
  } catch (const DeviceLost&) {
    FAIL("a missing device reported as lost");  // DeviceLost means an unplug of an open device
  } catch (const TransportError& e) {
    CHECK(e.path() == "/dev/iclap-no-such-hidraw");
#if HID_API_VERSION >= HID_API_MAKE_VERSION(0, 13, 0)
    // hidapi 0.13 reports why an open failed (hid_error(NULL)).
    CHECK(std::string(e.what()).find("unknown hidapi error") == std::string::npos);
#endif
  }
}

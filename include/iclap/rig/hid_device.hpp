// SPDX-License-Identifier: MIT
#pragma once

// hidapi transport for HID-class peripherals on the rig: a foot pedal or a
// stylus button that marks touches, or a microcontroller bridge that
// forwards taxel frames as HID reports. Including this header is the opt-in:
// it needs hidapi (<hidapi/hidapi.h>, link hidapi-hidraw or hidapi-libusb),
// which no other iclap header includes. The WTS sensor itself is CDC-ACM,
// not HID: use serial_port.hpp for it.
//
// Tested: enumeration and open errors (no HID devices in CI). Reading and
// writing real reports is not exercised by the test suite.

#include <hidapi/hidapi.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cwchar>
#include <mutex>
#include <string>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/core/utf8.hpp"
#include "iclap/rig/byte_stream.hpp"
#include "iclap/rig/hid_device_info.hpp"

namespace iclap::rig {

namespace hid_detail {
// hidapi strings are wchar_t (UTF-32 on Linux and macOS); tools print UTF-8.
inline std::string to_utf8(const wchar_t* text) {
  std::string out;
  if (!text) return out;
  for (; *text; ++text) {
    auto c = static_cast<std::uint32_t>(*text);
    if (c > 0x10FFFF || (c >= 0xD800 && c <= 0xDFFF)) c = 0xFFFD;
    append_utf8(out, c);
  }
  return out;
}
inline std::string last_error(hid_device* dev) {
  const std::string e = to_utf8(::hid_error(dev));
  return e.empty() ? std::string("unknown hidapi error") : e;
}
}  // namespace hid_detail

/// Keeps hidapi initialised: hid_init() on the first live instance,
/// hid_exit() when the last one goes. Thread-safe. Throws TransportError
/// ("hidapi: ...") if initialisation fails.
class HidLibrary {
 public:
  HidLibrary() {
    std::lock_guard<std::mutex> lock(mutex());
    if (count() == 0 && ::hid_init() != 0)
      throw TransportError("hidapi", "cannot initialise: " + hid_detail::last_error(nullptr));
    ++count();
  }
  ~HidLibrary() {
    std::lock_guard<std::mutex> lock(mutex());
    if (--count() == 0) ::hid_exit();
  }
  HidLibrary(const HidLibrary&) : HidLibrary() {}
  HidLibrary& operator=(const HidLibrary&) = default;

  /// The hidapi version in use, e.g. "0.13.1".
  static std::string version() { return ::hid_version_str(); }

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  static int& count() {
    static int c = 0;
    return c;
  }
};

/// All HID interfaces (or those of one vendor/product; 0 matches any).
/// Empty when there are none. Throws TransportError if hidapi cannot start.
inline std::vector<HidDeviceInfo> enumerate_hid_devices(std::uint16_t vendor_id = 0, std::uint16_t product_id = 0) {
  HidLibrary library;
  std::vector<HidDeviceInfo> devices;
  hid_device_info* list = ::hid_enumerate(vendor_id, product_id);
  for (const hid_device_info* d = list; d; d = d->next) {
    HidDeviceInfo info;
    info.path = d->path ? d->path : "";
    info.vendor_id = d->vendor_id;
    info.product_id = d->product_id;
    info.manufacturer = hid_detail::to_utf8(d->manufacturer_string);
    info.product = hid_detail::to_utf8(d->product_string);
    info.serial_number = hid_detail::to_utf8(d->serial_number);
    info.release_number = d->release_number;
    info.usage_page = d->usage_page;
    info.usage = d->usage;
    info.interface_number = d->interface_number;
    switch (d->bus_type) {
      case HID_API_BUS_USB: info.bus = "usb"; break;
      case HID_API_BUS_BLUETOOTH: info.bus = "bluetooth"; break;
      case HID_API_BUS_I2C: info.bus = "i2c"; break;
      case HID_API_BUS_SPI: info.bus = "spi"; break;
      default: info.bus = "unknown"; break;
    }
    devices.push_back(std::move(info));
  }
  ::hid_free_enumeration(list);
  std::sort(devices.begin(), devices.end(),
            [](const HidDeviceInfo& a, const HidDeviceInfo& b) { return a.path < b.path; });
  return devices;
}

/// An open HID device, report by report. Move-only; one reader and one
/// writer thread.
class HidDevice {
 public:
  /// Opens the device at `path` (from enumerate_hid_devices). Throws
  /// TransportError naming the path.
  explicit HidDevice(std::string path) : path_(std::move(path)) {
    handle_ = ::hid_open_path(path_.c_str());
    if (!handle_) throw TransportError(path_, "cannot open HID device: " + hid_detail::last_error(nullptr));
  }
  ~HidDevice() { close(); }
  HidDevice(HidDevice&& o) noexcept : library_(o.library_), path_(std::move(o.path_)), handle_(o.handle_) {
    o.handle_ = nullptr;
  }
  HidDevice& operator=(HidDevice&& o) noexcept {
    if (this != &o) {
      close();
      path_ = std::move(o.path_);
      handle_ = o.handle_;
      o.handle_ = nullptr;
    }
    return *this;
  }
  HidDevice(const HidDevice&) = delete;
  HidDevice& operator=(const HidDevice&) = delete;

  /// Reads one input report (its first byte is the report id if the device
  /// numbers its reports). Returns its size, 0 on timeout. Throws DeviceLost
  /// when a hidraw device node has gone, TransportError on other errors.
  std::size_t read_report(std::uint8_t* buffer, std::size_t capacity, std::chrono::milliseconds timeout) {
    require_open();
    const int ms = static_cast<int>(std::clamp<std::chrono::milliseconds::rep>(timeout.count(), 0, 24 * 3600 * 1000));
    const int n = ::hid_read_timeout(handle_, buffer, capacity, ms);
    if (n >= 0) return static_cast<std::size_t>(n);
    const std::string why = hid_detail::last_error(handle_);
    // hidapi gives no error code; a vanished /dev/hidrawN means an unplug.
    struct stat st {};
    if (path_.compare(0, 5, "/dev/") == 0 && ::stat(path_.c_str(), &st) != 0)
      throw DeviceLost(path_, "device lost (" + why + ")");
    throw TransportError(path_, "HID read failed: " + why);
  }

  /// Writes one output report: `data[0]` is the report id (0 for devices
  /// with a single report), then the report's bytes.
  void write_report(const std::uint8_t* data, std::size_t size) {
    require_open();
    const int n = ::hid_write(handle_, data, size);
    if (n < 0 || static_cast<std::size_t>(n) != size)
      throw TransportError(path_, "HID write failed: " + hid_detail::last_error(handle_));
  }

  void close() noexcept {
    if (handle_) ::hid_close(handle_);
    handle_ = nullptr;
  }
  bool is_open() const noexcept { return handle_ != nullptr; }
  const std::string& path() const noexcept { return path_; }
  /// The hidapi handle (nullptr when closed), for calls iclap does not wrap.
  hid_device* native_handle() const noexcept { return handle_; }

 private:
  void require_open() const {
    if (!handle_) throw TransportError(path_, "HID device is closed");
  }

  HidLibrary library_;  // first member: initialised before, destroyed after the handle
  std::string path_;
  hid_device* handle_ = nullptr;
};

/// A byte stream carried in fixed-size HID reports, for a microcontroller
/// bridge that forwards the sensor's serial bytes. Framing of each report:
/// `[report id if numbered] [count:u8 if length_prefix] data... [padding]`.
/// Without a length prefix every byte of a report is data (so the bridge
/// must not pad); with one, at most 255 data bytes travel per report.
/// Not copyable; one reader and one writer thread.
class HidByteStream final : public ByteStream {
 public:
  struct Settings {
    std::size_t report_size = 64;  ///< bytes per report, without the report id (2..4096)
    std::uint8_t report_id = 0;    ///< id of output reports (0: unnumbered)
    bool numbered_reports = false; ///< input reports start with a report id byte
    bool length_prefix = true;     ///< each report's first data byte counts its valid bytes
  };

  explicit HidByteStream(std::string path) : HidByteStream(std::move(path), Settings{}) {}
  /// Throws InvalidArgument ("settings.report_size") before touching the
  /// device, TransportError if it cannot be opened.
  HidByteStream(std::string path, Settings settings) : settings_(checked(settings)), device_(std::move(path)) {
    report_.resize(settings_.report_size + 1);
  }

  std::size_t read(std::uint8_t* buffer, std::size_t capacity, std::chrono::milliseconds timeout) override {
    if (pending_.empty()) {
      const std::size_t n = device_.read_report(report_.data(), report_.size(), timeout);
      std::size_t first = settings_.numbered_reports ? 1 : 0;
      if (n <= first) return 0;
      std::size_t count = n - first;
      if (settings_.length_prefix) {
        count = std::min<std::size_t>(report_[first], count - 1);
        ++first;
      }
      pending_.assign(report_.begin() + static_cast<std::ptrdiff_t>(first),
                      report_.begin() + static_cast<std::ptrdiff_t>(first + count));
      pending_pos_ = 0;
    }
    const std::size_t n = std::min(capacity, pending_.size() - pending_pos_);
    std::copy_n(pending_.begin() + static_cast<std::ptrdiff_t>(pending_pos_), n, buffer);
    pending_pos_ += n;
    if (pending_pos_ == pending_.size()) pending_.clear();
    return n;
  }

  void write(const std::uint8_t* data, std::size_t size, std::chrono::milliseconds /*timeout*/) override {
    const std::size_t room =
        settings_.length_prefix ? std::min<std::size_t>(settings_.report_size - 1, 255) : settings_.report_size;
    std::vector<std::uint8_t> out(settings_.report_size + 1);
    for (std::size_t done = 0; done < size;) {
      const std::size_t n = std::min(room, size - done);
      std::fill(out.begin(), out.end(), std::uint8_t{0});
      out[0] = settings_.report_id;
      std::size_t at = 1;
      if (settings_.length_prefix) out[at++] = static_cast<std::uint8_t>(n);
      std::copy_n(data + done, n, out.begin() + static_cast<std::ptrdiff_t>(at));
      device_.write_report(out.data(), out.size());
      done += n;
    }
  }
  using ByteStream::write;

  void close() noexcept override { device_.close(); }
  bool is_open() const noexcept override { return device_.is_open(); }
  const std::string& name() const noexcept override { return device_.path(); }

 private:
  static Settings checked(const Settings& s) {
    if (s.report_size < 2 || s.report_size > 4096)
      throw InvalidArgument("settings.report_size", std::to_string(s.report_size) + " is outside 2..4096");
    return s;
  }

  Settings settings_;
  HidDevice device_;
  std::vector<std::uint8_t> report_;
  std::vector<std::uint8_t> pending_;
  std::size_t pending_pos_ = 0;
};

}  // namespace iclap::rig

// SPDX-License-Identifier: MIT
#pragma once

// Lists candidate serial ports for the sensor. POSIX only (uses access());
// opt-in like serial_port.hpp.

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace iclap::rig {

/// A serial port found under /dev.
struct SerialPortInfo {
  std::string path;                ///< e.g. /dev/ttyACM0
  std::vector<std::string> by_id;  ///< /dev/serial/by-id links to it (stable names), sorted
  bool accessible = false;         ///< the current user may open it for reading and writing
  /// Other ttyACM*/ttyUSB* names under the device root for the same device
  /// (symlinks such as a udev alias ttyUSB1 -> ttyACM0), sorted naturally.
  std::vector<std::string> aliases;
};

namespace serial_detail {
inline bool is_candidate_name(const std::string& name) {
  for (const char* prefix : {"ttyACM", "ttyUSB"}) {
    const std::string p(prefix);
    if (name.size() > p.size() && name.compare(0, p.size(), p) == 0 &&
        std::all_of(name.begin() + static_cast<std::ptrdiff_t>(p.size()), name.end(),
                    [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }))
      return true;
  }
  return false;
}
// "ttyACM2" < "ttyACM10": compare the text prefix, then the number.
inline bool natural_less(const std::string& a, const std::string& b) {
  const auto split = [](const std::string& s) {
    std::size_t i = s.size();
    while (i > 0 && std::isdigit(static_cast<unsigned char>(s[i - 1]))) --i;
    const std::string digits = s.substr(i);
    return std::make_pair(s.substr(0, i), digits.empty() ? -1LL : std::stoll(digits.substr(0, 18)));
  };
  return split(a) < split(b);
}
}  // namespace serial_detail

/// The serial ports under `dev_root` (default /dev) where a WTS sensor or a
/// USB-serial bridge can appear: ttyACM* and ttyUSB* (not a directory or a
/// dangling link), plus every target of a `serial/by-id` link (dangling
/// ones skipped), each with its by-id names. A device is listed once: when
/// several of these names lead to it, the one that is not a symlink (the
/// device node itself), else the first in natural order, is its `path` and
/// the others are its `aliases`. Sorted naturally (ttyACM2 before
/// ttyACM10). Empty when there are none; never throws for a missing or
/// unreadable directory. `dev_root` exists for tests.
inline std::vector<SerialPortInfo> list_serial_ports(const std::string& dev_root = "/dev") {
  namespace fs = std::filesystem;
  std::vector<SerialPortInfo> ports;
  std::error_code ec;
  const auto canonical_or_self = [](const fs::path& p) {
    std::error_code e;
    const fs::path c = fs::canonical(p, e);
    return e ? p.lexically_normal() : c;
  };
  const auto find_or_add = [&](const fs::path& path) -> SerialPortInfo& {
    const std::string key = canonical_or_self(path).string();
    for (auto& port : ports)
      if (canonical_or_self(port.path).string() == key) return port;
    ports.push_back(SerialPortInfo{path.string(), {}, false, {}});
    return ports.back();
  };
  struct Name {
    fs::path path;
    bool link;
  };
  std::vector<Name> names;
  for (fs::directory_iterator it(dev_root, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (!serial_detail::is_candidate_name(name)) continue;
    // What the name leads to: a dangling link (a stale udev alias) is no
    // port, as a dangling by-id link is not; nor is a directory.
    std::error_code e;
    const fs::file_status target = it->status(e);
    if (e || !fs::exists(target) || fs::is_directory(target)) continue;
    const bool link = it->is_symlink(e);
    names.push_back(Name{it->path(), link && !e});
  }
  // The device node before its aliases, whatever order the directory lists
  // them in: the first name of a device is its path, the others aliases.
  std::sort(names.begin(), names.end(), [](const Name& a, const Name& b) {
    if (a.link != b.link) return !a.link;
    return serial_detail::natural_less(a.path.string(), b.path.string());
  });
  for (const Name& n : names) {
    SerialPortInfo& port = find_or_add(n.path);
    if (port.path != n.path.string()) port.aliases.push_back(n.path.string());
  }
  const fs::path by_id = fs::path(dev_root) / "serial" / "by-id";
  ec.clear();
  for (fs::directory_iterator it(by_id, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code e;
    if (!it->is_symlink(e)) continue;
    const fs::path target = fs::canonical(it->path(), e);
    if (e) continue;  // dangling link
    // Prefer the name under dev_root when the target lives there.
    const fs::path under_root = fs::path(dev_root) / target.filename();
    const bool same = canonical_or_self(under_root) == target;
    find_or_add(same ? under_root : target).by_id.push_back(it->path().string());
  }
  for (auto& port : ports) {
    std::sort(port.by_id.begin(), port.by_id.end());
    port.accessible = ::access(port.path.c_str(), R_OK | W_OK) == 0;
  }
  std::sort(ports.begin(), ports.end(), [](const SerialPortInfo& a, const SerialPortInfo& b) {
    return serial_detail::natural_less(a.path, b.path);
  });
  return ports;
}

}  // namespace iclap::rig

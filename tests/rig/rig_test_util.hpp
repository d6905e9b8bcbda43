// SPDX-License-Identifier: MIT
#pragma once
// Small helpers shared by the rig tests.

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace iclap::rig::test {

/// "aa aa 30" for {0xAA, 0xAA, 0x30}.
inline std::string hex(const std::vector<std::uint8_t>& bytes) {
  std::string out;
  char buf[4];
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%02x", bytes[i]);
    if (i) out += ' ';
    out += buf;
  }
  return out;
}

}  // namespace iclap::rig::test

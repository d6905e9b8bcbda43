// SPDX-License-Identifier: MIT
#pragma once

// Checks that an all-or-nothing writer (AtomicFileWriter) left no temporary
// file (`PATH.partial-...`) beside its target.

#include <filesystem>
#include <string>

namespace iclap::test {

inline bool temporary_left_beside(const std::string& path) {
  const std::filesystem::path p(path);
  const std::string prefix = p.filename().string() + ".partial-";
  const std::filesystem::path dir = p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().filename().string().rfind(prefix, 0) == 0) return true;
  return false;
}

}  // namespace iclap::test

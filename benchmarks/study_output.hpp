// SPDX-License-Identifier: MIT
// The study programs (trade_study, scaling_study, shape_bound) run for
// minutes to hours and write their files at the end; their --out DIR is
// checked before the study starts, so that a path that can never be a
// directory is refused at once instead of after the run.
#pragma once

#include <filesystem>
#include <string>
#include <system_error>

#include "cli.hpp"

namespace iclap::bench {

/// Refuses (cli::UsageError naming --out) an output directory that exists
/// and is not a directory, or whose closest existing ancestor is not a
/// directory (e.g. `--out results.csv/x` under a file): create_directories
/// would fail there after the whole study. It creates nothing; the program
/// creates the directory when it writes.
inline void check_out_dir(const std::string& out) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path p(out);
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec)) throw cli::UsageError("--out: '" + out + "' exists and is not a directory");
    return;
  }
  for (fs::path a = p.parent_path(); !a.empty(); a = a.parent_path()) {
    if (fs::exists(a, ec)) {
      if (!fs::is_directory(a, ec))
        throw cli::UsageError("--out: '" + out + "' cannot be created: '" + a.string() + "' is not a directory");
      return;
    }
    if (a == a.parent_path()) return;  // the root
  }
}

}  // namespace iclap::bench

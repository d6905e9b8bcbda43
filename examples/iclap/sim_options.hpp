// SPDX-License-Identifier: MIT
#pragma once

// The simulated scene and operator, as options: shared by `iclap simulate`
// and `iclap live --simulate`, so that a live exploration can be simulated
// exactly as the references were.

#include <set>
#include <string>

#include "cli.hpp"
#include "iclap/sim/exploration.hpp"

namespace iclap::cli {

/// The options parse_simulation_options reads.
inline std::set<std::string> simulation_option_names() {
  return {"shift-mm", "yaw-deg", "frames", "sweep-min-mm", "sweep-max-mm", "turn-probability", "start-candidates"};
}

/// Sets the ExplorationSettings the given options name; the others keep
/// their values (the library's defaults). Throws UsageError naming the
/// option for a value out of range.
inline void parse_simulation_options(const Options& opt, ExplorationSettings& ex) {
  constexpr double kDegree = 3.14159265358979323846 / 180.0;
  if (opt.has("shift-mm")) ex.placement_shift = opt.number("shift-mm", 0.0, 0.0, 1000.0) * 1e-3;
  if (opt.has("yaw-deg")) ex.placement_yaw = opt.number("yaw-deg", 0.0, 0.0, 180.0) * kDegree;
  if (opt.has("frames")) ex.max_frames_mean = opt.number("frames", 0.0, 1.0, ExplorationSettings::kMaxFramesMean);
  if (opt.has("sweep-min-mm")) ex.sweep_length_min = opt.number("sweep-min-mm", 0.0, 0.1, 1000.0) * 1e-3;
  if (opt.has("sweep-max-mm")) ex.sweep_length_max = opt.number("sweep-max-mm", 0.0, 0.1, 1000.0) * 1e-3;
  if (ex.sweep_length_max < ex.sweep_length_min)
    throw UsageError("--sweep-max-mm must be >= --sweep-min-mm, got " +
                     (opt.has("sweep-max-mm") ? opt.string("sweep-max-mm") : format_value(ex.sweep_length_max * 1e3)) +
                     " < " +
                     (opt.has("sweep-min-mm") ? opt.string("sweep-min-mm") : format_value(ex.sweep_length_min * 1e3)));
  if (opt.has("turn-probability")) ex.turn_probability = opt.number("turn-probability", 0.0, 0.0, 1.0);
  if (opt.has("start-candidates"))
    ex.start_candidates =
        static_cast<int>(opt.integer("start-candidates", 1, 1, ExplorationSettings::kMaxStartCandidates));
}

}  // namespace iclap::cli

// SPDX-License-Identifier: MIT
#pragma once

// A dataset with the geometry of the rig's sensor, for tests that build
// their frames by hand.

#include <utility>
#include <vector>

#include "iclap/data/dataset.hpp"

namespace iclap::test {

/// A dataset of the WTS 0614-34A's 14 x 6 taxels holding `frames`, with no
/// comments (so no pitch_m=: taxel_pitch_of gives its fallback).
inline Dataset wts_dataset(std::vector<Frame> frames = {}) {
  Dataset ds;
  ds.rows = 14;
  ds.cols = 6;
  ds.frames = std::move(frames);
  return ds;
}

}  // namespace iclap::test

// SPDX-License-Identifier: MIT
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/rig/frame_source.hpp"
#include "iclap/sim/simulator.hpp"

namespace iclap::rig {

/// Frames of a simulated exploration, as if the rig were exploring the
/// object now: `iclap live --simulate`, demos and tests without hardware.
/// The exploration is exactly simulate_exploration(object, settings, seed,
/// exploration), so it equals that exploration of a dataset simulated with
/// the same object, settings and seed (e.g. `iclap simulate`).
///
/// The explorer is simulated lazily, in one go, at the first next() (tens of
/// milliseconds for a built-in object). Frames are returned in time order;
/// by default without waiting, or, with `real_time`, each when its time `t`
/// has passed since the first next() (the rig's pace, 5 frames/s): next()
/// then waits at most `timeout` and returns kTimeout while the frame is not
/// due. kEnd after the last frame. Not thread-safe.
class SimFrameSource final : public FrameSource {
 public:
  struct Settings {
    bool real_time = false;  ///< pace frames by their time stamps
  };

  /// Throws InvalidArgument for invalid simulation settings or a negative
  /// exploration id.
  SimFrameSource(SimObject object, SimulationSettings settings, std::uint64_t seed, std::int64_t exploration)
      : SimFrameSource(std::move(object), std::move(settings), seed, exploration, Settings{}) {}
  SimFrameSource(SimObject object, SimulationSettings settings, std::uint64_t seed, std::int64_t exploration,
                 Settings source_settings)
      : object_(std::move(object)),
        sim_(std::move(settings)),
        seed_(seed),
        exploration_(exploration),
        settings_(source_settings) {
    sim_.validate();
    if (exploration_ < 0) throw InvalidArgument("exploration", "must be >= 0, got " + std::to_string(exploration_));
  }

  Status next(PosedFrame& out, std::chrono::milliseconds timeout) override {
    if (!simulated_) {
      frames_ = simulate_exploration(object_, sim_, seed_, exploration_);
      simulated_ = true;
      start_ = std::chrono::steady_clock::now();
    }
    if (next_ >= frames_.size()) return Status::kEnd;
    const Frame& f = frames_[next_];
    if (settings_.real_time && f.time) {
      const auto due = start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                    std::chrono::duration<double>(*f.time - first_time()));
      const auto now = std::chrono::steady_clock::now();
      if (due > now) {
        // (Compared in milliseconds, rounded up: the timeout in the clock's
        // nanoseconds overflowed for milliseconds::max(), which then slept
        // for the whole timeout.)
        if (std::chrono::ceil<std::chrono::milliseconds>(due - now) > timeout) {
          std::this_thread::sleep_for(timeout);
          return Status::kTimeout;
        }
        std::this_thread::sleep_until(due);
      }
    }
    ++next_;
    out.pressures = f.pressures;
    out.pose = Pose{f.position, f.orientation};
    out.time = f.time;
    return Status::kFrame;
  }

  Grid grid() const override { return Grid{sim_.sensor.rows, sim_.sensor.cols}; }
  bool has_time() const override { return true; }
  bool has_orientation() const override { return true; }
  std::string description() const override {
    return "simulated exploration " + std::to_string(exploration_) + " of " + object_.name + " (seed " +
           std::to_string(seed_) + ")";
  }

  /// The simulated dataset row of the last kFrame (its object is the truth).
  const Frame& last_frame() const {
    if (next_ == 0) throw InvalidArgument("last_frame", "no frame has been returned yet");
    return frames_[next_ - 1];
  }
  const SimObject& object() const noexcept { return object_; }

 private:
  double first_time() const { return frames_.front().time.value_or(0.0); }

  SimObject object_;
  SimulationSettings sim_;
  std::uint64_t seed_;
  std::int64_t exploration_;
  Settings settings_;
  bool simulated_ = false;
  std::vector<Frame> frames_;
  std::size_t next_ = 0;
  std::chrono::steady_clock::time_point start_{};
};

}  // namespace iclap::rig

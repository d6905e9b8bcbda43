// SPDX-License-Identifier: MIT
#pragma once

#include <chrono>
#include <string>
#include <utility>

#include "iclap/core/error.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/rig/frame_source.hpp"

namespace iclap::rig {

/// Replays the frames of a dataset in file order, as if they came from the
/// rig: for testing live recognition without hardware, or re-running a
/// session. Never waits; kEnd after the last frame.
class DatasetFrameSource final : public FrameSource {
 public:
  /// Throws EmptyInput ("dataset") if it has no frames.
  explicit DatasetFrameSource(Dataset dataset, std::string name = "dataset")
      : dataset_(std::move(dataset)), name_(std::move(name)) {
    if (dataset_.frames.empty()) throw EmptyInput("dataset", name_ + " has no frames");
    const auto& first = dataset_.frames.front();
    has_time_ = first.time.has_value();
    has_orientation_ = first.orientation.has_value();
  }

  Status next(PosedFrame& out, std::chrono::milliseconds /*timeout*/) override {
    if (next_ >= dataset_.frames.size()) return Status::kEnd;
    const Frame& f = dataset_.frames[next_++];
    out.pressures = f.pressures;
    out.pose = Pose{f.position, f.orientation};
    out.time = f.time;
    return Status::kFrame;
  }

  Grid grid() const override { return Grid{dataset_.rows, dataset_.cols}; }
  bool has_time() const override { return has_time_; }
  bool has_orientation() const override { return has_orientation_; }
  std::string description() const override { return "replay of " + name_; }
  /// The dataset frame that the last kFrame came from (labels for
  /// evaluation). Throws InvalidArgument ("last_frame") before the first.
  const Frame& last_frame() const {
    if (next_ == 0) throw InvalidArgument("last_frame", "no frame has been returned yet");
    return dataset_.frames[next_ - 1];
  }

 private:
  Dataset dataset_;
  std::string name_;
  bool has_time_ = false;
  bool has_orientation_ = false;
  std::size_t next_ = 0;
};

}  // namespace iclap::rig

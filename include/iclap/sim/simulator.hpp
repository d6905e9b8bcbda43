// SPDX-License-Identifier: MIT
#pragma once

// The rig simulator: datasets exactly as the WTS + Phantom Omni recorder
// would write them, from one seed.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/core/parallel.hpp"
#include "iclap/core/progress.hpp"
#include "iclap/core/random.hpp"
#include "iclap/core/version.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/sim/exploration.hpp"
#include "iclap/sim/objects.hpp"
#include "iclap/sim/sensor.hpp"

namespace iclap {

/// Everything that defines a simulated data collection, besides the objects
/// and the seed.
struct SimulationSettings {
  TactileSensorSettings sensor;
  ArmSettings arm;
  ExplorationSettings exploration;
  int explorations = 5;  ///< explorations per object (paper: 5)
  /// Worker threads (0: one per hardware thread). The output does not
  /// depend on it.
  unsigned threads = 1;

  void validate() const {
    sensor.validate();
    arm.validate();
    exploration.validate();
    if (explorations < 1) throw InvalidArgument("explorations", "must be >= 1, got " + std::to_string(explorations));
  }
};

namespace detail {
/// FNV-1a of the object name: the random stream of an object depends on its
/// name only, not on its position in the list.
inline std::uint64_t name_stream(const std::string& name) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (char c : name) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ull;
  }
  return h;
}
}  // namespace detail

/// Simulates exploration `exploration` (0-based) of `object`: the object is
/// put down with a random planar shift and yaw, then the operator sweeps the
/// pad over it (README, "Simulator") for about 85 frames at 5 frames/s.
/// Frames are in time order, numbered from 0; the first has no contact;
/// frames without contact (lifts, moves) are included. Positions are the
/// pad centre in the world (table) frame, metres, quantised like the Omni;
/// `t` in seconds from the exploration's start; orientation the pad axes
/// (see PadPose). The random stream is Rng::derive(seed, hash(name),
/// exploration), so the result depends only on (object, settings, seed,
/// exploration). Thread-safe (no shared state).
inline std::vector<Frame> simulate_exploration(const SimObject& object, const SimulationSettings& settings,
                                               std::uint64_t seed, std::int64_t exploration) {
  settings.validate();
  const TactileSensorModel sensor(settings.sensor);
  Rng rng = Rng::derive(seed, detail::name_stream(object.name), static_cast<std::uint64_t>(exploration));
  const ExplorationSettings& ex = settings.exploration;
  const double factor = 1.0 + ex.frames_spread * rng.uniform(-1.0, 1.0);
  const std::size_t frames = static_cast<std::size_t>(std::max(1.0, std::round(ex.max_frames_mean * factor)));
  detail::Explorer explorer(object, sensor, settings.arm, ex, rng);
  return explorer.run(exploration, frames);
}

/// The comment lines simulate_dataset writes at the top of a dataset.
inline std::vector<std::string> simulation_comments(const std::vector<SimObject>& objects,
                                                    const SimulationSettings& s, std::uint64_t seed) {
  auto num = [](double v) {
    std::string out;
    detail::append_number(out, v);
    return out;
  };
  return {"sensor: WTS 0614-34A (simulated) rows=" + std::to_string(s.sensor.rows) +
              " cols=" + std::to_string(s.sensor.cols) + " pitch_m=" + num(s.sensor.pitch),
          "arm: Phantom Omni (simulated) resolution_m=" + num(s.arm.position_resolution),
          std::string("generator: iclap ") + ICLAP_VERSION_STRING + " simulator, seed=" + std::to_string(seed) +
              " objects=" + std::to_string(objects.size()) + " explorations=" + std::to_string(s.explorations) +
              " frame_rate_hz=" + num(s.exploration.frame_rate)};
}

/// Simulates `settings.explorations` explorations of every object and
/// returns them as one dataset (objects in the given order, explorations
/// 0..n-1, frames in time order), ready for write_dataset_csv. Same objects,
/// settings and seed give identical data whatever the thread count.
/// `progress` counts finished explorations (called from worker threads).
/// Throws InvalidArgument for an object name the CSV cannot hold (empty,
/// a comma, ...: as make_sim_object), duplicate names or bad settings.
/// With the defaults and the 20 built-in objects: about 8,500
/// frames (the paper collected 8,492).
inline Dataset simulate_dataset(const std::vector<SimObject>& objects, const SimulationSettings& settings,
                                std::uint64_t seed, const ProgressCallback& progress = {}) {
  settings.validate();
  if (objects.empty()) throw EmptyInput("objects");
  std::set<std::string> names;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    // (SimObject is a plain struct: its name need not have come through
    // make_sim_object's check.)
    const std::string& name = objects[i].name;
    detail::check_sim_object_name(name, "objects[" + std::to_string(i) + "].name");
    if (!names.insert(name).second) throw InvalidArgument("objects", "two objects are named '" + name + "'");
  }
  const std::size_t per = static_cast<std::size_t>(settings.explorations);
  const std::size_t jobs = objects.size() * per;
  std::vector<std::vector<Frame>> results(jobs);
  ProgressCounter counter(progress, jobs);
  detail::parallel_for(jobs, settings.threads, [&](std::size_t j, unsigned) {
    results[j] = simulate_exploration(objects[j / per], settings, seed, static_cast<std::int64_t>(j % per));
    counter.tick();
  });
  Dataset ds;
  ds.rows = settings.sensor.rows;
  ds.cols = settings.sensor.cols;
  ds.comments = simulation_comments(objects, settings, seed);
  std::size_t total = 0;
  for (const auto& r : results) total += r.size();
  ds.frames.reserve(total);
  for (auto& r : results)
    for (auto& f : r) ds.frames.push_back(std::move(f));
  return ds;
}

}  // namespace iclap

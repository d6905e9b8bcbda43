// SPDX-License-Identifier: MIT
// Rig simulator: sensor physics on simple shapes, exploration invariants,
// determinism, objects from mesh folders.

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <typeinfo>
#include <vector>

#include "iclap/data/csv_writer.hpp"
#include "iclap/mesh/primitives.hpp"
#include "iclap/sim/sim.hpp"
#include "../support/temporaries.hpp"
#include "../support/zero_area_mesh.hpp"

namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;

iclap::TactileSensorSettings quiet_sensor() {
  iclap::TactileSensorSettings s;
  s.noise_sigma = 0;
  s.dead_band = 0;
  return s;
}

// Pad pressing straight down (pad z = -world z), long side along world x
// (or along y when `turned`).
iclap::PadPose pad_down(const Eigen::Vector3d& centre, bool turned = false) {
  iclap::PadPose p;
  p.centre = centre;
  const Eigen::Vector3d ez(0, 0, -1);
  const Eigen::Vector3d ex = turned ? Eigen::Vector3d(0, 1, 0) : Eigen::Vector3d(1, 0, 0);
  p.axes.col(0) = ex;
  p.axes.col(1) = ez.cross(ex);
  p.axes.col(2) = ez;
  return p;
}

Eigen::MatrixXd press(const iclap::MeshBvh& shape, const iclap::PadPose& pose, double force,
                      const iclap::TactileSensorModel& sensor, iclap::Rng* noise = nullptr) {
  iclap::PadContact c;
  sensor.probe(shape, pose, c);
  if (!c.any_surface()) return sensor.render(c, 0.0, noise);
  const double shift = sensor.balance(c, force);
  CHECK(sensor.force(c, shift) == doctest::Approx(force).epsilon(1e-6));
  return sensor.render(c, shift, noise);
}

std::string csv_bytes(const iclap::Dataset& ds) {
  std::ostringstream out;
  iclap::write_dataset_csv(out, ds);
  return out.str();
}

// No arm noise or quantisation and the object never re-placed: the recorded
// poses are the simulated ones, in the object's frame.
iclap::SimulationSettings exact_arm_still_object() {
  iclap::SimulationSettings s;
  s.arm.position_noise = 0;
  s.arm.orientation_noise = 0;
  s.arm.position_resolution = 0;
  s.exploration.placement_shift = 0;
  s.exploration.placement_yaw = 0;
  return s;
}

std::vector<iclap::SimObject> some_builtins() {
  return {iclap::builtin_object("pliers_1"), iclap::builtin_object("wooden_cuboid_1"),
          iclap::builtin_object("fixed_wrench_2")};
}

}  // namespace

TEST_CASE("sensor: a flat plate gives a uniform patch at the expected pressure") {
  const iclap::TactileSensorModel sensor(quiet_sensor());
  const iclap::MeshBvh plate(iclap::transformed(iclap::make_box({0.2, 0.1, 0.02}),
                                                Eigen::Affine3d(Eigen::Translation3d(0, 0, 0.01))));
  for (double force : {1.0, 3.0, 8.0}) {
    const Eigen::MatrixXd p = press(plate, pad_down({0.003, -0.002, 0.025}), force, sensor);
    REQUIRE(p.rows() == 14);
    REQUIRE(p.cols() == 6);
    // Uniform: every taxel reads the same (up to the integer rounding).
    CHECK(p.maxCoeff() - p.minCoeff() <= 1.0);
    // Pressure = force / pad area, scaled to raw units.
    const auto& s = sensor.settings();
    const double pad_area = static_cast<double>(sensor.sample_count()) * sensor.sample_area();
    CHECK(pad_area == doctest::Approx(s.pad_length * s.pad_width).epsilon(0.1));
    const double expected = force / pad_area / s.full_scale_pressure * s.max_raw;
    CHECK(std::abs(p.mean() - expected) <= 0.5);  // integer readings
  }
}

TEST_CASE("sensor: an edge gives a line along it") {
  const iclap::TactileSensorModel sensor(quiet_sensor());
  // A square bar with one edge up along world x, the edge at z = 0.02.
  Eigen::Affine3d T = Eigen::Affine3d::Identity();
  T.translate(Eigen::Vector3d(0, 0, 0.02 - 0.01 * std::sqrt(2.0)));
  T.rotate(Eigen::AngleAxisd(kPi / 4, Eigen::Vector3d::UnitX()));
  const iclap::MeshBvh ridge(iclap::transformed(iclap::make_box({0.3, 0.02, 0.02}), T));

  // Edge along the pad's long side: the two middle columns (2, 3) carry it,
  // the same in every row.
  const Eigen::MatrixXd along = press(ridge, pad_down({0, 0, 0.021}), 3.0, sensor);
  const double middle = along.col(2).sum() + along.col(3).sum();
  CHECK(middle > 0.9 * along.sum());
  CHECK(along.col(0).maxCoeff() == 0);
  CHECK(along.col(5).maxCoeff() == 0);
  CHECK(along.col(2).maxCoeff() - along.col(2).minCoeff() <= 1.0);
  CHECK(std::abs(along(7, 2) - along(7, 3)) <= 1.0);
  // The same force on 2 of the 6 columns: about 3 times the flat reading.
  CHECK(along.maxCoeff() > 2.5 * 3.0 / (0.051 * 0.024) / 250e3 * 4095);

  // Edge across the pad: the two middle rows (6, 7) carry it.
  const Eigen::MatrixXd across = press(ridge, pad_down({0, 0, 0.021}, true), 3.0, sensor);
  CHECK(across.row(6).sum() + across.row(7).sum() > 0.9 * across.sum());
  CHECK(across.row(0).maxCoeff() == 0);
  CHECK(across.row(13).maxCoeff() == 0);
  CHECK(across.row(6).maxCoeff() - across.row(6).minCoeff() <= 1.0);
}

TEST_CASE("sensor: no contact gives an empty frame; a point saturates") {
  const iclap::MeshBvh plate(iclap::transformed(iclap::make_box({0.2, 0.1, 0.02}),
                                                Eigen::Affine3d(Eigen::Translation3d(0, 0, 0.01))));
  const iclap::TactileSensorModel quiet(quiet_sensor());
  iclap::PadContact c;
  quiet.probe(plate, pad_down({0, 0, 0.025}), c);
  CHECK(c.any_surface());
  CHECK(c.max_depth == doctest::Approx(-0.005));
  CHECK(quiet.render(c, 0.0, nullptr).maxCoeff() == 0);
  // With the default read noise the frame stays below the contact threshold.
  const iclap::TactileSensorModel noisy;
  iclap::Rng rng(1);
  for (int i = 0; i < 50; ++i) CHECK(noisy.render(c, 0.0, &rng).maxCoeff() <= iclap::kDefaultContactThreshold);
  // Nothing in reach at all.
  noisy.probe(plate, pad_down({0, 0, 0.2}), c);
  CHECK_FALSE(c.any_surface());
  CHECK(std::isnan(noisy.balance(c, 3.0)));

  // A cone tip pressed with 5 N: one spot, saturated at 4095.
  const iclap::MeshBvh cone(iclap::make_frustum(0.01, 0.0, 0.02, 32));
  const Eigen::MatrixXd p = press(cone, pad_down({0.0017, 0.0017, 0.021}), 5.0, quiet);
  CHECK(p.maxCoeff() == 4095);
  CHECK((p.array() > 0).count() < 12);
  CHECK_THROWS_AS(iclap::TactileSensorModel([] {
                    iclap::TactileSensorSettings s;
                    s.pad_width = 0.01;
                    return s;
                  }()),
                  iclap::InvalidArgument);
}

TEST_CASE("built-in objects: 20 stable names, resting on the table, tool-sized") {
  const auto names = iclap::builtin_object_names();
  REQUIRE(names.size() == 20);
  CHECK(std::set<std::string>(names.begin(), names.end()).size() == 20);
  const auto objects = iclap::builtin_objects();
  REQUIRE(objects.size() == 20);
  for (std::size_t i = 0; i < objects.size(); ++i) {
    CAPTURE(names[i]);
    CHECK(objects[i].name == names[i]);
    const auto b = objects[i].shape.bounds();
    CHECK(std::abs(b.min().z()) < 1e-12);
    CHECK(std::abs(b.center().x()) < 1e-12);
    CHECK(std::abs(b.center().y()) < 1e-12);
    CHECK(b.sizes().maxCoeff() > 0.05);
    CHECK(b.sizes().maxCoeff() < 0.35);
    CHECK(iclap::signed_volume(objects[i].shape.mesh()) > 0);
  }
  auto length = [](const iclap::SimObject& o) { return o.shape.bounds().sizes().x(); };
  // Same heads, different lengths; same frame, different jaws.
  CHECK(length(iclap::builtin_object("fixed_wrench_2")) - length(iclap::builtin_object("fixed_wrench_1")) > 0.05);
  CHECK(std::abs(length(iclap::builtin_object("pliers_1")) - length(iclap::builtin_object("pliers_2"))) < 0.015);
  CHECK_THROWS_AS(iclap::builtin_object("spoon"), iclap::InvalidArgument);
}

TEST_CASE("exploration: frames, timing, quantisation, start without contact") {
  iclap::SimulationSettings s;
  const auto obj = iclap::builtin_object("wooden_cuboid_2");
  std::size_t contacts = 0, total = 0;
  for (int e = 0; e < 3; ++e) {
    const auto frames = iclap::simulate_exploration(obj, s, 9, e);
    CHECK(frames.size() >= 72);
    CHECK(frames.size() <= 98);
    REQUIRE_FALSE(frames.empty());
    CHECK_FALSE(iclap::is_contact(frames.front()));
    CHECK(frames.front().pressures.maxCoeff() == 0);
    for (std::size_t k = 0; k < frames.size(); ++k) {
      const auto& f = frames[k];
      CHECK(f.object == "wooden_cuboid_2");
      CHECK(f.exploration == e);
      CHECK(f.frame == static_cast<std::int64_t>(k));
      REQUIRE(f.time.has_value());
      CHECK(*f.time == static_cast<double>(k) / 5.0);
      REQUIRE(f.orientation.has_value());
      CHECK(f.orientation->norm() == doctest::Approx(1.0));
      for (int i = 0; i < 3; ++i) {
        const double q = f.position[i] / s.arm.position_resolution;
        CHECK(std::abs(q - std::round(q)) < 1e-6);
      }
      CHECK(f.pressures.minCoeff() >= 0);
      CHECK(f.pressures.maxCoeff() <= 4095);
      CHECK((f.pressures.array() == f.pressures.array().round()).all());
      if (iclap::is_contact(f)) ++contacts;
      ++total;
    }
  }
  // Most of the time is spent sweeping over the surface.
  CHECK(contacts > total / 3);
}

TEST_CASE("exploration: physically consistent on every built-in object") {
  const iclap::SimulationSettings s = exact_arm_still_object();
  const double raw_to_newton = s.sensor.full_scale_pressure / s.sensor.max_raw * s.sensor.pitch * s.sensor.pitch;
  for (const auto& obj : iclap::builtin_objects()) {
    CAPTURE(obj.name);
    std::size_t checked = 0;
    for (const auto& f : iclap::simulate_exploration(obj, s, 4, 0)) {
      // The taxels never feel more than the operator pushes (forces up to
      // force_max with 10 % jitter): the pad never ends up inside the object.
      CHECK(f.pressures.sum() * raw_to_newton < 1.6 * s.exploration.force_max);
      if (!iclap::is_contact(f)) continue;
      ++checked;
      const Eigen::Vector3d ez = f.orientation->toRotationMatrix().col(2);
      // The surface under the pad is within the foam's reach.
      const auto c = obj.shape.closest_point(f.position);
      CHECK(std::sqrt(c.squared_distance) < 0.03);  // within the pad's half-diagonal
      const auto hit = obj.shape.intersect(f.position - 0.02 * ez, ez, 0.04, iclap::RaySide::front);
      if (hit) CHECK(hit->t > 0.02 - s.sensor.foam_thickness - 1e-9);  // never deeper than the foam
      // The pad stays above the table.
      CHECK(iclap::detail::pad_lowest_z({f.position, f.orientation->toRotationMatrix()}, s.sensor) >=
            s.exploration.table_clearance - 1e-9);
    }
    CHECK(checked > 25);
  }
}

TEST_CASE("simulator: same seed same bytes, different seed differs, threads and order do not matter") {
  iclap::SimulationSettings s;
  s.explorations = 2;
  const auto objects = some_builtins();
  const std::string a = csv_bytes(iclap::simulate_dataset(objects, s, 42));
  const std::string b = csv_bytes(iclap::simulate_dataset(objects, s, 42));
  CHECK(a == b);
  CHECK(a != csv_bytes(iclap::simulate_dataset(objects, s, 43)));
  s.threads = 3;
  CHECK(a == csv_bytes(iclap::simulate_dataset(objects, s, 42)));
  // An object's frames depend on its name, not its place in the list.
  const auto reordered = iclap::simulate_dataset({objects[2], objects[0]}, s, 42);
  const auto original = iclap::simulate_dataset(objects, s, 42);
  std::vector<iclap::Frame> x, y;
  for (const auto& f : original.frames)
    if (f.object == "pliers_1") x.push_back(f);
  for (const auto& f : reordered.frames)
    if (f.object == "pliers_1") y.push_back(f);
  REQUIRE(x.size() == y.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    CHECK(x[i].position == y[i].position);
    CHECK(x[i].pressures == y[i].pressures);
  }
  // Structure and comments.
  CHECK(original.rows == 14);
  CHECK(original.cols == 6);
  CHECK(iclap::object_names(original) == std::vector<std::string>{"pliers_1", "wooden_cuboid_1", "fixed_wrench_2"});
  CHECK(iclap::explorations_of(original, "fixed_wrench_2") == std::vector<std::int64_t>{0, 1});
  REQUIRE(original.comments.size() == 3);
  CHECK(original.comments[0] == "sensor: WTS 0614-34A (simulated) rows=14 cols=6 pitch_m=0.0034");
  CHECK(original.comments[2].find("seed=42") != std::string::npos);
  // Bad input.
  CHECK_THROWS_AS(iclap::simulate_dataset({}, s, 1), iclap::EmptyInput);
  CHECK_THROWS_AS(iclap::simulate_dataset({objects[0], objects[0]}, s, 1), iclap::InvalidArgument);
  s.explorations = 0;
  CHECK_THROWS_AS(iclap::simulate_dataset(objects, s, 1), iclap::InvalidArgument);
}

TEST_CASE("simulator: the object is re-placed between explorations (configurable, zero allowed)") {
  iclap::SimulationSettings s;
  s.arm.position_noise = 0;
  const auto obj = iclap::builtin_object("wooden_cuboid_3");
  // Same exploration stream, with and without re-placement: the same motion
  // in the object frame, moved by a planar rigid transform in the world.
  const auto moved = iclap::simulate_exploration(obj, s, 5, 1);
  s.exploration.placement_shift = 0;
  s.exploration.placement_yaw = 0;
  const auto still = iclap::simulate_exploration(obj, s, 5, 1);
  REQUIRE(moved.size() == still.size());
  double max_dz = 0, max_dxy = 0;
  for (std::size_t i = 0; i < moved.size(); ++i) {
    max_dz = std::max(max_dz, std::abs(moved[i].position.z() - still[i].position.z()));
    max_dxy = std::max(max_dxy, (moved[i].position - still[i].position).head<2>().norm());
  }
  CHECK(max_dz < 1e-4);   // quantisation only
  CHECK(max_dxy > 1e-4);  // shifted and turned
  CHECK(max_dxy < 0.04);  // by a small amount
}

TEST_CASE("exploration: the covering operator spreads its touches over the object") {
  // Short sweeps and a lift after each: where the pad starts anew is what
  // differs. Same seeds, 1 (uninformed) or 16 start candidates; the spread
  // is the mean distance from each contact to the nearest contact of an
  // earlier sweep of the same exploration (pad centres, object frame).
  iclap::SimulationSettings s = exact_arm_still_object();
  s.exploration.sweep_length_min = 0.01;
  s.exploration.sweep_length_max = 0.02;
  s.exploration.turn_probability = 0;
  const auto spread = [&](const iclap::SimObject& obj, int candidates) {
    s.exploration.start_candidates = candidates;
    double sum = 0;
    std::size_t n = 0;
    for (int e = 0; e < 20; ++e) {
      std::vector<Eigen::Vector3d> earlier, current;
      bool in_contact = false;
      for (const auto& f : iclap::simulate_exploration(obj, s, 11, e)) {
        const bool c = iclap::is_contact(f);
        if (!c && in_contact) {  // a sweep ended
          earlier.insert(earlier.end(), current.begin(), current.end());
          current.clear();
        }
        in_contact = c;
        if (!c) continue;
        if (current.empty() && !earlier.empty()) {  // the first touch of a new sweep
          double d2 = std::numeric_limits<double>::infinity();
          for (const auto& q : earlier) d2 = std::min(d2, (q - f.position).squaredNorm());
          sum += std::sqrt(d2);
          ++n;
        }
        current.push_back(f.position);
      }
    }
    REQUIRE(n > 30);
    return sum / static_cast<double>(n);
  };
  for (const char* name : {"hammer", "wooden_cuboid_3", "fixed_wrench_2"}) {
    CAPTURE(name);
    const auto obj = iclap::builtin_object(name);
    const double uninformed = spread(obj, 1), covering = spread(obj, 16);
    MESSAGE(std::string(name) << ": uninformed " << uninformed << " m, covering " << covering << " m");
    CHECK(covering > 1.3 * uninformed);
  }
}

TEST_CASE("mesh objects: folder with meshes.json, explicit units, errors") {
  const std::string dir = std::string(ICLAP_TEST_FIXTURES) + "/mesh/objects";
  const auto objects = iclap::load_mesh_objects(dir);
  REQUIRE(objects.size() == 2);
  CHECK(objects[0].name == "block");
  CHECK(objects[1].name == "wedge");
  // The tilted block lies on its largest face: 60 x 40 x 30 mm.
  CHECK(objects[0].shape.bounds().sizes().isApprox(Eigen::Vector3d(0.06, 0.04, 0.03), 1e-6));
  CHECK(std::abs(objects[0].shape.bounds().min().z()) < 1e-12);
  // The wedge (80 x 30 x 20 mm right prism, millimetres) rests on its slope:
  // the largest face (85.4 x 20 mm) and the lowest centre of mass (9.4 mm).
  CHECK(objects[1].shape.bounds().sizes().isApprox(Eigen::Vector3d(0.08544, 0.02, 0.02809), 1e-3));

  // Explicit unit for every file: the block would be 1000 times larger in mm.
  const auto as_mm = iclap::load_mesh_objects(dir, iclap::LengthUnit::millimetres);
  CHECK(as_mm[0].shape.bounds().sizes().maxCoeff() == doctest::Approx(0.06e-3));

  // Automatic units without a manifest, a file missing from it, duplicate stems.
  const iclap::test::TempDir scratch("sim");
  const fs::path& tmp = scratch.path;
  fs::copy_file(dir + "/block.obj", tmp / "block.obj");
  CHECK_THROWS_WITH_AS(iclap::load_mesh_objects(tmp.string()), doctest::Contains("meshes.json"), iclap::InvalidArgument);
  std::ofstream(tmp / "meshes.json") << "[{\"file\": \"other.obj\", \"scale_to_metres\": 1}]";
  CHECK_THROWS_WITH_AS(iclap::load_mesh_objects(tmp.string()), doctest::Contains("block.obj is not listed"),
                       iclap::InvalidArgument);
  fs::copy_file(dir + "/wedge.ply", tmp / "block.ply");
  CHECK_THROWS_WITH_AS(iclap::load_mesh_objects(tmp.string(), iclap::LengthUnit::metres),
                       doctest::Contains("two meshes are named 'block'"), iclap::InvalidArgument);
  std::ofstream(tmp / "meshes.json") << "[{\"file\": \"block.obj\",\n \"scale_to_metres\": oops}]";
  fs::remove(tmp / "block.ply");
  try {
    iclap::load_mesh_objects(tmp.string());
    FAIL("accepted");
  } catch (const iclap::ParseError& e) {
    CHECK(e.line() == 2);
  }
  CHECK_THROWS_AS(iclap::load_mesh_objects(dir + "/nothing_here"), iclap::IoError);
}

TEST_CASE("mesh objects: the shared manifest lists the 25 meshes with their scales") {
  const std::string path = std::string(ICLAP_SHARED_DIR) + "/data/meshes/meshes.json";
  if (std::string(ICLAP_SHARED_DIR).empty() || !std::ifstream(path)) {
    MESSAGE("shared meshes not available; skipped");
    return;
  }
  const auto scales = iclap::read_mesh_manifest(path);
  CHECK(scales.size() == 25);
  CHECK(scales.at("wt_pliers.ply") == 0.001);
  CHECK(scales.at("ycb_037_scissors.obj") == 1.0);
}

TEST_CASE("settings: non-finite and oversized values are refused, naming the setting and the value") {
  constexpr double inf = std::numeric_limits<double>::infinity();
  struct Bad {
    const char* argument;
    const char* value;
    void (*apply)(iclap::SimulationSettings&);
  };
  const Bad cases[] = {
      {"arm.position_noise", "inf", [](iclap::SimulationSettings& s) { s.arm.position_noise = inf; }},
      {"arm.orientation_noise", "inf", [](iclap::SimulationSettings& s) { s.arm.orientation_noise = inf; }},
      {"arm.position_resolution", "inf", [](iclap::SimulationSettings& s) { s.arm.position_resolution = inf; }},
      {"arm.position_noise", "nan", [](iclap::SimulationSettings& s) { s.arm.position_noise = std::nan(""); }},
      {"sensor.noise_sigma", "inf", [](iclap::SimulationSettings& s) { s.sensor.noise_sigma = inf; }},
      {"sensor.dead_band", "inf", [](iclap::SimulationSettings& s) { s.sensor.dead_band = inf; }},
      {"sensor.spread_sigma", "inf", [](iclap::SimulationSettings& s) { s.sensor.spread_sigma = inf; }},
      {"sensor.spread_sigma", "1e+300", [](iclap::SimulationSettings& s) { s.sensor.spread_sigma = 1e300; }},
      {"sensor.pad_length", "inf", [](iclap::SimulationSettings& s) { s.sensor.pad_length = inf; }},
      {"sensor.pad_width", "1e+06", [](iclap::SimulationSettings& s) { s.sensor.pad_width = 1e6; }},
      {"sensor.pad_length", "1e+300", [](iclap::SimulationSettings& s) {
         s.sensor.rows = 1000000;
         s.sensor.pad_length = 1e300;
       }},
      {"exploration.max_frames_mean", "inf", [](iclap::SimulationSettings& s) { s.exploration.max_frames_mean = inf; }},
      {"exploration.max_frames_mean", "1e+07",
       [](iclap::SimulationSettings& s) { s.exploration.max_frames_mean = 1e7; }},
      {"exploration.sweep_length_max", "inf",
       [](iclap::SimulationSettings& s) { s.exploration.sweep_length_max = inf; }},
      {"exploration.force_max", "inf", [](iclap::SimulationSettings& s) { s.exploration.force_max = inf; }},
      {"exploration.start_candidates", "got 0", [](iclap::SimulationSettings& s) { s.exploration.start_candidates = 0; }},
      {"exploration.start_candidates", "got 65",
       [](iclap::SimulationSettings& s) { s.exploration.start_candidates = 65; }},
  };
  const iclap::SimObject object = iclap::builtin_object(iclap::builtin_object_names().front());
  for (const Bad& b : cases) {
    CAPTURE(b.argument);
    CAPTURE(b.value);
    iclap::SimulationSettings s;
    b.apply(s);
    try {
      simulate_exploration(object, s, 42, 0);
      FAIL("accepted");
    } catch (const iclap::InvalidArgument& e) {
      CHECK(e.argument() == b.argument);
      CHECK_MESSAGE(e.reason().find(b.value) != std::string::npos, e.what());
    }
    if (std::string(b.argument).rfind("sensor.", 0) == 0)
      CHECK_THROWS_AS(iclap::TactileSensorModel(s.sensor), iclap::InvalidArgument);
  }
  // The limits themselves are fine (only validated here: not simulated).
  iclap::SimulationSettings s;
  s.exploration.max_frames_mean = 1e6;
  s.sensor.spread_sigma = 0.999e4 * s.sensor.pitch / s.sensor.samples_per_taxel;
  s.exploration.start_candidates = iclap::ExplorationSettings::kMaxStartCandidates;
  CHECK_NOTHROW(s.validate());
}

namespace {
// The file-to-scale map of a meshes.json text.
std::map<std::string, double> parse_manifest(const std::string& text) {
  return iclap::detail::ManifestParser(text, "meshes.json").parse();
}
}  // namespace

TEST_CASE("mesh objects: manifest nesting is capped, not a stack overflow") {
  try {
    parse_manifest("[{\"x\":" + std::string(2000000, '['));
    FAIL("accepted");
  } catch (const iclap::ParseError& e) {
    CHECK(e.file() == "meshes.json");
    CHECK(e.line() == 1);
    CHECK(e.reason() == "nesting deeper than 256");
  }
  // 256 levels in all (the top-level array and object, 254 below) are fine.
  const auto nested = [](int n) {
    return "[{\"file\": \"a.obj\", \"x\": " + std::string(static_cast<std::size_t>(n), '[') +
           std::string(static_cast<std::size_t>(n), ']') + ", \"scale_to_metres\": 0.001}]";
  };
  const auto scales = parse_manifest(nested(254));
  CHECK(scales.size() == 1);
  CHECK(scales.at("a.obj") == 0.001);
  CHECK_THROWS_WITH_AS(parse_manifest(nested(255)), "meshes.json:1: nesting deeper than 256", iclap::ParseError);
  CHECK_THROWS_WITH_AS(parse_manifest("[{\"x\": {\"y\": [1, {\"z\": [[[" + std::string(300, '[')),
                       "meshes.json:1: nesting deeper than 256", iclap::ParseError);
}

TEST_CASE("mesh objects: a file listed twice in meshes.json is refused at the second entry") {
  // The second entry used to override the first silently (a 1 mm-scale cube
  // read as metres became 1000 times larger).
  try {
    parse_manifest("[{\"file\": \"cube.obj\", \"scale_to_metres\": 0.001},\n"
          " {\"file\": \"other.obj\", \"scale_to_metres\": 1},\n"
          " {\"file\": \"cube.obj\",\n  \"scale_to_metres\": 1}]");
    FAIL("accepted");
  } catch (const iclap::ParseError& e) {
    CHECK(e.file() == "meshes.json");
    CHECK(e.line() == 3);
    CHECK(e.reason() == "'cube.obj' is listed twice (first at line 1)");
  }
  // Even with the same scale: the manifest is ambiguous or a copy-paste slip.
  CHECK_THROWS_WITH_AS(parse_manifest("[{\"file\": \"a.obj\", \"scale_to_metres\": 1}, {\"file\": \"a.obj\", "
                             "\"scale_to_metres\": 1}]"),
                       "meshes.json:1: 'a.obj' is listed twice (first at line 1)", iclap::ParseError);
  // Entries without both members are ignored, so they are not duplicates.
  const auto scales = parse_manifest("[{\"file\": \"a.obj\"}, {\"file\": \"a.obj\", \"scale_to_metres\": 0.01}]");
  CHECK(scales.at("a.obj") == 0.01);

  // Through load_mesh_objects: the error names the manifest's path.
  const std::string dir = std::string(ICLAP_TEST_FIXTURES) + "/mesh/objects";
  const iclap::test::TempDir scratch("sim_dup");
  const fs::path& tmp = scratch.path;
  fs::copy_file(dir + "/block.obj", tmp / "block.obj");
  std::ofstream(tmp / "meshes.json") << "[\n{\"file\": \"block.obj\", \"scale_to_metres\": 0.001},\n"
                                        "{\"file\": \"block.obj\", \"scale_to_metres\": 1}\n]\n";
  try {
    iclap::load_mesh_objects(tmp.string());
    FAIL("accepted");
  } catch (const iclap::ParseError& e) {
    CHECK(e.file() == (tmp / "meshes.json").string());
    CHECK(e.line() == 3);
  }
}

TEST_CASE("mesh objects: a mesh of zero-area triangles is refused by name") {
  const iclap::TriangleMesh m = iclap::test::zero_area_mesh();
  for (const bool place : {true, false}) {
    try {
      iclap::make_sim_object("degen", m, place);
      FAIL("accepted");
    } catch (const iclap::InvalidArgument& e) {
      CHECK(e.argument() == "mesh of 'degen'");
      CHECK(e.reason() == "every one of its 4 triangles has zero area (no surface)");
    }
  }
}

TEST_CASE("settings: exploration ranges between settings are refused, naming the setting and the value") {
  struct Bad {
    const char* argument;
    const char* reason;
    void (*apply)(iclap::ExplorationSettings&);
  };
  const Bad cases[] = {
      {"exploration.turn_probability", "must be in [0, 1], got 1.5",
       [](iclap::ExplorationSettings& e) { e.turn_probability = 1.5; }},
      {"exploration.turn_probability", "must be in [0, 1], got -0.25",
       [](iclap::ExplorationSettings& e) { e.turn_probability = -0.25; }},
      {"exploration.turn_probability", "must be in [0, 1], got nan",
       [](iclap::ExplorationSettings& e) { e.turn_probability = std::nan(""); }},
      {"exploration.sweep_length_max", "must be >= sweep_length_min, got 0.029",
       [](iclap::ExplorationSettings& e) {
         e.sweep_length_min = 0.03;
         e.sweep_length_max = 0.029;
       }},
      {"exploration.force_max", "must be >= force_min, got 1.5",
       [](iclap::ExplorationSettings& e) {
         e.force_min = 2;
         e.force_max = 1.5;
       }},
      {"exploration.frames_spread", "must be in [0, 1), got 1",
       [](iclap::ExplorationSettings& e) { e.frames_spread = 1; }},
      {"exploration.frames_spread", "must be in [0, 1), got -0.1",
       [](iclap::ExplorationSettings& e) { e.frames_spread = -0.1; }},
  };
  const iclap::SimObject object = iclap::builtin_object(iclap::builtin_object_names().front());
  for (const Bad& b : cases) {
    const std::string argument = b.argument, reason = b.reason;
    CAPTURE(argument);
    CAPTURE(reason);
    iclap::SimulationSettings s;
    b.apply(s.exploration);
    // Directly, and before any simulation.
    for (int through_simulation = 0; through_simulation < 2; ++through_simulation) {
      try {
        if (through_simulation) (void)iclap::simulate_exploration(object, s, 42, 0);
        else s.exploration.validate();
        FAIL_CHECK("accepted");
      } catch (const iclap::InvalidArgument& e) {
        CHECK(typeid(e) == typeid(iclap::InvalidArgument));
        CHECK(e.argument() == argument);
        CHECK(e.reason() == reason);
      }
    }
  }
  // The ends of the ranges are fine: equal bounds, never or always turning,
  // no spread.
  iclap::ExplorationSettings e;
  e.turn_probability = 0;
  e.sweep_length_max = e.sweep_length_min;
  e.force_max = e.force_min;
  e.frames_spread = 0;
  CHECK_NOTHROW(e.validate());
  e.turn_probability = 1;
  e.frames_spread = 0.999;
  CHECK_NOTHROW(e.validate());
}

TEST_CASE("exploration: with no start where the pad fits, the pad is pressed straight down on the highest point") {
  // A card 0.8 mm thick: lower than the pad may come to the table (1 mm), so
  // no start point on it passes (flat on the top face, the pad would be too
  // close to the table; on the sides it would be in it). The operator falls
  // back to lowering the pad, facing straight down, onto the highest vertex
  // (a corner of the top face), and the exploration still feels the card.
  iclap::SimulationSettings s = exact_arm_still_object();
  s.exploration.max_frames_mean = 60;
  s.exploration.frames_spread = 0;
  const iclap::SimObject card = iclap::make_sim_object("card", iclap::make_box({0.06, 0.04, 0.0008}), false);
  const double top = card.shape.bounds().max().z();
  REQUIRE(top == doctest::Approx(0.0008));
  REQUIRE(top < s.exploration.table_clearance);
  const auto frames = iclap::simulate_exploration(card, s, 3, 0);
  REQUIRE(frames.size() == 60);
  CHECK_FALSE(iclap::is_contact(frames.front()));
  CHECK(frames.front().position.z() == doctest::Approx(top + s.exploration.clearance));
  std::size_t contacts = 0;
  for (const auto& f : frames) {
    CAPTURE(f.frame);
    // Every move is vertical, above a corner of the top face, pad facing down.
    CHECK(std::abs(f.position.x()) == doctest::Approx(0.03));
    CHECK(std::abs(f.position.y()) == doctest::Approx(0.02));
    CHECK(f.position.x() == frames.front().position.x());
    CHECK(f.position.y() == frames.front().position.y());
    REQUIRE(f.orientation.has_value());
    CHECK(f.orientation->toRotationMatrix().col(2).isApprox(Eigen::Vector3d(0, 0, -1), 1e-12));
    if (!iclap::is_contact(f)) continue;
    ++contacts;
    // In contact the pad rests on the top face, the foam compressed.
    CHECK(f.position.z() < top);
    CHECK(f.position.z() > top - s.sensor.foam_thickness);
  }
  CHECK(contacts >= 10);
}

TEST_CASE("exploration: an approach that feels nothing gives up, lifts and tries again") {
  // An open mesh seen only from below: one triangle 10 mm above the table,
  // facing down. No start point faces up, so the pad is lowered onto the
  // highest point (the first vertex); it feels nothing there (the back of a
  // face is not felt) and, 20 mm past the hover clearance, lifts, moves
  // through the air and comes down again.
  iclap::TriangleMesh m;
  m.vertices.resize(3, 3);
  m.vertices << 0, 0.03, 0,  //
      0, 0, 0.03,            //
      0.01, 0.01, 0.01;
  m.triangles.resize(3, 1);
  m.triangles << 0, 2, 1;
  REQUIRE(m.area_normal(0).z() < 0);
  const iclap::SimObject canopy{"canopy", iclap::MeshBvh(m)};
  iclap::SimulationSettings s = exact_arm_still_object();
  s.exploration.max_frames_mean = 60;
  s.exploration.frames_spread = 0;
  const auto frames = iclap::simulate_exploration(canopy, s, 3, 0);
  REQUIRE(frames.size() == 60);
  const double hover = 0.01 + s.exploration.clearance;
  const double step = s.exploration.approach_speed / s.exploration.frame_rate;
  const double give_up = s.exploration.clearance + 0.02;  // approach length before lifting
  CHECK(frames.front().position.z() == doctest::Approx(hover));
  double lowest = std::numeric_limits<double>::infinity();
  int lifts = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const auto& f = frames[k];
    CAPTURE(f.frame);
    CHECK(f.pressures.maxCoeff() == 0);
    CHECK(f.position.x() == 0);
    CHECK(f.position.y() == 0);
    // Never lowered further than the approach length (and one step).
    CHECK(f.position.z() >= hover - give_up - step - 1e-9);
    lowest = std::min(lowest, f.position.z());
    if (k >= 2 && frames[k - 1].position.z() < frames[k - 2].position.z() &&
        f.position.z() > frames[k - 1].position.z())
      ++lifts;  // going down, then up
  }
  CHECK(lowest <= hover - give_up);  // the whole approach was tried
  CHECK(lifts >= 2);
}

namespace {
iclap::ParseError manifest_error(const std::string& text) {
  try {
    (void)parse_manifest(text);
  } catch (const iclap::ParseError& e) {
    return e;
  }
  FAIL_CHECK("accepted: " << text);
  return iclap::ParseError("", 0, "accepted");
}
}  // namespace

TEST_CASE("mesh objects: manifest strings decode JSON escapes; malformed escapes are refused") {
  // The file name of a one-entry manifest whose "file" is written `json`.
  auto file_name = [&](const std::string& json) {
    const auto scales = parse_manifest("[{\"file\": \"" + json + "\", \"scale_to_metres\": 0.5}]");
    REQUIRE(scales.size() == 1);
    CHECK(scales.begin()->second == 0.5);
    return scales.begin()->first;
  };
  CHECK(file_name(R"(plain.obj)") == "plain.obj");
  CHECK(file_name(R"(a\"b.obj)") == "a\"b.obj");
  CHECK(file_name(R"(dir\\x.obj)") == "dir\\x.obj");
  CHECK(file_name(R"(dir\/x.obj)") == "dir/x.obj");
  CHECK(file_name(R"(\b\f\n\r\t)") == "\b\f\n\r\t");
  // \u escapes decode to UTF-8 (Python's json.dump writes every non-ASCII
  // character so): one, two and three bytes, and a surrogate pair.
  CHECK(file_name(R"(\u0041\u004a.obj)") == "AJ.obj");
  CHECK(file_name(R"(bl\u00f6ck.obj)") == "bl\xc3\xb6" "ck.obj");
  CHECK(file_name(R"(\u20AC\u20ac)") == "\xe2\x82\xac\xe2\x82\xac");
  CHECK(file_name(R"(\ud83d\ude00.ply)") == "\xf0\x9f\x98\x80.ply");
  // Names that differ only in an escaped character are two files, not one
  // listed twice.
  const auto two = parse_manifest(R"([{"file": "\u00e9.obj", "scale_to_metres": 1},)"
                         R"( {"file": "\u00e8.obj", "scale_to_metres": 0.001}])");
  CHECK(two.size() == 2);
  CHECK(two.at("\xc3\xa9.obj") == 1);
  CHECK(two.at("\xc3\xa8.obj") == 0.001);
  // Escapes in members that are skipped, and in keys.
  CHECK(parse_manifest(R"([{"n\u006fte": "tab\there \u00e9 \"q\"", "file": "a.obj", "scale_to_metres": 1}])").at("a.obj") == 1);
  CHECK(parse_manifest(R"([{"fil\u0065": "a.obj", "scale_to_metres": 2}])").at("a.obj") == 2);

  // Malformed escapes: a ParseError at the line of the string, saying why.
  struct Bad {
    std::string json;  // the "file" value
    std::string reason;
  };
  const Bad bad[] = {
      {R"(a\x41.obj)", "invalid escape '\\x' in a string"},
      {R"(a\'.obj)", "invalid escape '\\'' in a string"},
      {"a\\\n.obj", "invalid escape '\\\\x0a' in a string"},  // not a way around "line break inside a string"
      {R"(a\uZZZZ.obj)", "invalid \\u escape (4 hex digits expected)"},
      {R"(a\u12.obj)", "invalid \\u escape (4 hex digits expected)"},
      {R"(a\u12)", "invalid \\u escape (4 hex digits expected)"},  // would swallow the closing quote
      {R"(a\u-123.obj)", "invalid \\u escape (4 hex digits expected)"},
      {R"(\ud83d.obj)", "unpaired surrogate in a \\u escape"},
      {R"(\ud83d\u0041)", "unpaired surrogate in a \\u escape"},
      {R"(\ude00x)", "unpaired surrogate in a \\u escape"},
  };
  for (const Bad& b : bad) {
    CAPTURE(b.json);
    const iclap::ParseError e =
        manifest_error("[\n{\"file\": \"" + b.json + "\", \"scale_to_metres\": 1}]");
    CHECK(e.file() == "meshes.json");
    CHECK(e.line() == 2);
    CHECK(e.reason() == b.reason);
  }
  // Cut short inside an escape.
  CHECK(manifest_error(R"([{"file": "a\u00)").reason() == "truncated \\u escape");
  CHECK(manifest_error(R"([{"file": "a\)").reason() == "expected '\"'");

  // Through load_mesh_objects: a file with a non-ASCII name, listed with a
  // \u escape, gets its scale.
  const std::string dir = std::string(ICLAP_TEST_FIXTURES) + "/mesh/objects";
  const iclap::test::TempDir scratch("sim_utf8");
  const fs::path& tmp = scratch.path;
  fs::copy_file(dir + "/block.obj", tmp / "bl\xc3\xb6" "ck.obj");
  std::ofstream(tmp / "meshes.json") << "[{\"file\": \"bl\\u00f6ck.obj\", \"scale_to_metres\": 0.001}]";
  const auto objects = iclap::load_mesh_objects(tmp.string());
  REQUIRE(objects.size() == 1);
  CHECK(objects[0].name == "bl\xc3\xb6" "ck");
  CHECK(objects[0].shape.bounds().sizes().maxCoeff() == doctest::Approx(0.06e-3));
}

TEST_CASE("mesh objects: manifest values of every JSON kind; empty arrays and objects") {
  CHECK(parse_manifest("[]").empty());
  CHECK(parse_manifest(" \n[ \t]\n").empty());
  CHECK(parse_manifest("[{}]").empty());
  CHECK(parse_manifest("[{ }, {\"file\": \"a.obj\", \"scale_to_metres\": 2}]") == std::map<std::string, double>{{"a.obj", 2.0}});
  // Members other than "file" and "scale_to_metres" are skipped whatever
  // their kind.
  const auto scales = parse_manifest(
      R"([{"closed": false, "file": "a.obj", "watertight": true, "scale_to_metres": 1e-3, "licence": null,)"
      R"( "tags": [], "meta": {}, "aabb": [-1.5, 2E2, {"k": [false, true, null, "s"]}], "bytes": 12}])");
  CHECK(scales == std::map<std::string, double>{{"a.obj", 0.001}});
  // Misspelt literals and text after the array are errors.
  CHECK(manifest_error(R"([{"closed": fals}])").reason() == "expected a number");
  CHECK(manifest_error(R"([{"closed": nul, "file": "a.obj"}])").reason() == "expected a number");
  CHECK(manifest_error(R"([{"closed": falsey}])").reason() == "expected '}'");
  CHECK(manifest_error("[] []").reason() == "unexpected text after the top-level array");
  CHECK(manifest_error("[{}").reason() == "expected ']'");
}

TEST_CASE("mesh objects: an invalid object file is refused naming its path") {
  const iclap::test::TempDir scratch("sim_bad");
  const fs::path& tmp = scratch.path;
  auto load_error = [&](const fs::path& file) {
    try {
      (void)iclap::load_mesh_objects(tmp.string(), iclap::LengthUnit::metres);
    } catch (const iclap::InvalidArgument& e) {
      CHECK(typeid(e) == typeid(iclap::InvalidArgument));
      CHECK(e.argument() == file.string());
      return e.reason();
    }
    FAIL("accepted " << file);
    return std::string();
  };
  // A name the CSV cannot hold (a tetrahedron named "a,b").
  const fs::path comma = tmp / "a,b.obj";
  std::ofstream(comma) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  CHECK(load_error(comma) == "name: object name 'a,b' contains a comma");
  fs::remove(comma);
  // A flat mesh: a square, no volume to rest on the table.
  const fs::path flat = tmp / "flat.obj";
  std::ofstream(flat) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
  CHECK(load_error(flat).find("all points lie on a plane") != std::string::npos);
}

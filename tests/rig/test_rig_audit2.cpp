// SPDX-License-Identifier: MIT
// Reproducers from helper h57b's audit (session 57) of the rig code not
// audited before: serial enumeration, SerialPort, pose specs and sources,
// frame sources, `iclap devices` and `iclap record`. Each case failed on the
// code it was written against; the comment above it says what the input
// is, what used to happen and what happens now.
//
// Build: like test_rig_devices (include tests/rig, link util). The `iclap
// record` cases need ICLAP_CLI_PATH, like test_record_cli, and are left out
// without it.

#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/data/csv_reader.hpp"
#include "iclap/data/csv_writer.hpp"
#include "iclap/rig/pose_spec.hpp"
#include "iclap/rig/serial_enumeration.hpp"
#include "../support/temporaries.hpp"
#ifdef ICLAP_CLI_PATH
#include "fake_wts_sensor.hpp"
#include "process_util.hpp"
#include "rig_test_util.hpp"
#endif

using namespace iclap::rig;
namespace fs = std::filesystem;

// Input: a device root with regular "port" files ttyACM0..ttyACM3 and a
// dangling symlink ttyUSB7 -> nowhere (a stale alias left by a udev rule, or
// a scratch tree).
// Was: ttyUSB7 listed as a port (accessible = false), so `iclap devices`
// advised joining the 'dialout' group for a port that does not exist
// (`!is_directory` is true for a missing target).
// Now: skipped, like a dangling serial/by-id link.
TEST_CASE("list_serial_ports: a dangling ttyUSB symlink is not listed as a port") {
  const iclap::test::TempDir scratch("h57b_dangling");
  const fs::path root = scratch.path / "dev";
  fs::create_directories(root / "serial" / "by-id");
  for (const char* name : {"ttyACM0", "ttyACM1", "ttyACM2", "ttyACM3"}) std::ofstream(root / name) << "";
  fs::create_symlink("nowhere", root / "ttyUSB7");  // dangling
  const auto ports = list_serial_ports(root.string());
  std::vector<std::string> paths;
  for (const auto& p : ports) paths.push_back(p.path);
  CHECK(paths == std::vector<std::string>{(root / "ttyACM0").string(), (root / "ttyACM1").string(),
                                          (root / "ttyACM2").string(), (root / "ttyACM3").string()});
}

// Input: make_pose_source("fixed:0,0,0,0.7071,0.7071,0,0") - 90 degrees
// about x, typed with 4 significant digits, as a user types it and as the
// dataset format itself stores orientations (kQuaternionNormTolerance =
// 1e-3 in data/dataset.hpp: "values written with 4 significant digits are
// within it"; ReplayPoseSource::from_dataset normalises such quaternions).
// Was: InvalidArgument "pose: 'fixed:...': pose: orientation quaternion has
// norm 0.9999904099540154, expected 1 within 1e-6" - a typed pose needed
// about 7 correct digits.
// Now: accepted within the dataset tolerance and normalised, as
// from_dataset does; a zero or scaled quaternion is still refused.
TEST_CASE("make_pose_source: a fixed quaternion typed with 4 digits is accepted and normalised") {
  std::unique_ptr<PoseSource> source;
  REQUIRE_NOTHROW(source = make_pose_source("fixed:0,0,0,0.7071,0.7071,0,0"));
  REQUIRE(source->has_orientation());
  const auto pose = source->next();
  REQUIRE(pose);
  REQUIRE(pose->orientation);
  CHECK(std::abs(pose->orientation->norm() - 1.0) < 1e-12);
  CHECK(pose->orientation->x() == doctest::Approx(std::sqrt(0.5)).epsilon(1e-9));
  // Still refused: clearly not a unit quaternion.
  CHECK_THROWS_AS(make_pose_source("fixed:0,0,0,2,0,0,0"), iclap::InvalidArgument);
}

#ifdef ICLAP_CLI_PATH
namespace {
struct Scratch57 : test::ScratchDir {
  explicit Scratch57(const std::string& tag) : test::ScratchDir(tag) {}
};
std::vector<std::string> record_args57(const std::string& port, const std::string& out) {
  return {"record", "--port", port, "--object", "mug", "--exploration", "2", "--out", out};
}
using test::one_mug_frame;
bool sent_start(const test::PtyFakeSensor& fake) {
  for (auto id : fake.command_ids())
    if (id == wts_id::kStartPeriodicFrames) return true;
  return false;
}
}  // namespace

// Input: `iclap record --pose replay:DIR/po<newline>ses.csv --out new.csv`
// with a valid 4-pose dataset under that (legal) file name.
// Was: the sensor STARTED, then at the first frame exit 2 with "comments[3]:
// contains a line break" (the raw path in the "poses:" dataset comment);
// nothing recorded.
// Now: the 4 frames are recorded; the comment holds the quoted name (\x0a).
TEST_CASE("iclap record: a replay file whose name has a line break does not fail after streaming") {
  Scratch57 scratch("h57b_replay_nl");
  iclap::Dataset poses;
  poses.rows = 1;
  poses.cols = 1;
  for (int i = 0; i < 4; ++i) {
    iclap::Frame f;
    f.object = "path";
    f.frame = i;
    f.position = Eigen::Vector3d(0.01 * i, 0, 0.3);
    f.pressures = Eigen::MatrixXd::Zero(1, 1);
    poses.frames.push_back(f);
  }
  const std::string pose_file = scratch("po\nses.csv");
  iclap::write_dataset_csv(pose_file, poses);
  test::FakeSensorScript script;
  test::PtyFakeSensor fake(script);
  const std::string out = scratch("new.csv");
  auto args = record_args57(fake.path(), out);
  args.insert(args.end(), {"--pose", "replay:" + pose_file});
  const auto r = test::run_iclap(args, scratch);
  INFO(r.err);
  CHECK(r.err.find("comments[") == std::string::npos);
  REQUIRE(r.status == 0);
  CHECK(iclap::read_dataset_csv(out).frames.size() == 4);
  CHECK(test::read_text(out).find("# poses: replay of '" + scratch("po") + "\\x0ases.csv' (4 poses)\n") !=
        std::string::npos);
}

// Input: `iclap record --out link.csv` where link.csv is a symlink to a file
// that does not exist yet (e.g. data/latest.csv -> session-5.csv).
// Was: exit 2, "DIR/latest.csv: cannot create: File exists" (O_CREAT |
// O_EXCL fails on any symlink).
// Now: exit 2 before the sensor streams, naming the dangling symlink and
// its target.
TEST_CASE("iclap record: --out a dangling symlink is not refused with 'File exists'") {
  Scratch57 scratch("h57b_out_link");
  const std::string target = scratch("session-5.csv");
  const std::string link = scratch("latest.csv");
  fs::create_symlink(target, link);
  test::FakeSensorScript script;
  test::PtyFakeSensor fake(script);
  auto args = record_args57(fake.path(), link);
  args.insert(args.end(), {"--frames", "3", "--pose", "fixed:0,0,0"});
  const auto r = test::run_iclap(args, scratch);
  INFO(r.err);
  CHECK(r.err.find("File exists") == std::string::npos);
  CHECK(r.status == 2);
  CHECK(r.err.find(link + ": is a dangling symlink to '" + target + "'") != std::string::npos);
  CHECK_FALSE(sent_start(fake));
  CHECK_FALSE(fs::exists(target));
  CHECK(fs::is_symlink(link));
}
// Input: `iclap record --out kept.csv` where kept.csv holds one complete row
// and a partial last row "mug,2,1,0,0" (an earlier run lost power), and the
// sensor then sends no frame (--seconds 0.3).
// Was: exit 1 with "...; DIR/kept.csv is unchanged", although opening had
// cut its last 11 bytes.
// Now: "... keeps its complete rows; only its partial last row (11 bytes)
// was cut off".
TEST_CASE("iclap record: a run that cut a partial row does not report the file as unchanged") {
  Scratch57 scratch("h57b_partial");
  const std::string out = scratch("kept.csv");
  iclap::write_dataset_csv(out, one_mug_frame(0));
  { std::ofstream(out, std::ios::app) << "mug,2,1,0,0"; }  // partial row, no line break
  const std::string before = test::read_text(out);
  test::FakeSensorScript script;
  script.max_frames = 0;  // silent
  test::PtyFakeSensor fake(script);
  auto args = record_args57(fake.path(), out);
  args.insert(args.end(), {"--seconds", "0.3", "--pose", "fixed:0,0,0"});
  const auto r = test::run_iclap(args, scratch);
  INFO(r.err);
  CHECK(r.status == 1);
  REQUIRE(test::read_text(out) != before);  // the partial row was cut (by design)
  CHECK(r.err.find(out + " is unchanged") == std::string::npos);
  CHECK(r.err.find(out + " keeps its complete rows; only its partial last row (11 bytes) was cut off") !=
        std::string::npos);
}

// Input: `iclap record --out full.csv` where full.csv has a row of the same
// object and exploration with frame 9223372036854775807 (INT64_MAX).
// Was: the next frame number overflowed a signed integer (undefined).
// Now: exit 2 before the sensor streams, saying no frame number is left;
// the file is unchanged.
TEST_CASE("iclap record: an exploration at frame INT64_MAX is refused, not overflowed") {
  Scratch57 scratch("h57b_frame_max");
  const std::string out = scratch("full.csv");
  iclap::write_dataset_csv(out, one_mug_frame(std::numeric_limits<std::int64_t>::max()));
  const std::string before = test::read_text(out);
  test::FakeSensorScript script;
  test::PtyFakeSensor fake(script);
  auto args = record_args57(fake.path(), out);
  args.insert(args.end(), {"--frames", "2", "--pose", "fixed:0,0,0"});
  const auto r = test::run_iclap(args, scratch);
  INFO(r.err);
  CHECK(r.status == 2);
  CHECK(r.err.find("mug exploration 2 has frame 9223372036854775807, after which no frame number is left") !=
        std::string::npos);
  CHECK_FALSE(sent_start(fake));
  CHECK(test::read_text(out) == before);
}
#endif  // ICLAP_CLI_PATH

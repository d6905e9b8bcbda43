// SPDX-License-Identifier: MIT
// `iclap record` and `iclap devices` end to end: the real iclap binary
// records from the fake sensor on a pseudo-terminal; the dataset it writes
// is read back with the project's reader and compared with what the fake
// sent.

#include <doctest/doctest.h>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "fake_wts_sensor.hpp"
#include "iclap/data/csv_reader.hpp"
#include "iclap/data/csv_writer.hpp"
#include "process_util.hpp"
#include "rig_test_util.hpp"

using namespace iclap::rig;
using namespace std::chrono_literals;
using test::FakeSensorScript;
using test::PtyFakeSensor;
namespace fs = std::filesystem;

namespace {

/// A scratch directory of this test program.
struct Scratch : test::ScratchDir {
  Scratch() : test::ScratchDir("record") {}
};

using test::run_iclap;

std::vector<std::string> record_args(const std::string& port, const std::string& out) {
  return {"record", "--port", port, "--object", "mug", "--exploration", "2", "--out", out};
}

// `iclap record` from `fake` into `out`, started in the background (for a
// Ctrl-C); its output goes to `stem`.stdout and `stem`.stderr of `scratch`.
pid_t spawn_record(const PtyFakeSensor& fake, const std::string& out, const Scratch& scratch, const std::string& stem) {
  std::vector<std::string> argv{ICLAP_CLI_PATH};
  for (auto& a : record_args(fake.path(), out)) argv.push_back(a);
  return test::spawn_process(argv, scratch(stem + ".stdout"), scratch(stem + ".stderr"));
}

// Sequence numbers of the recorded rows, after checking every row against
// the frame the fake sent under that number.
std::vector<std::size_t> recorded_seqs(const iclap::Dataset& d, std::uint64_t seed) {
  std::vector<std::size_t> seqs;
  for (const auto& f : d.frames) {
    REQUIRE(f.pressures.rows() == 14);
    REQUIRE(f.pressures.cols() == 6);
    const std::size_t seq = test::fake_frame_seq(f.pressures(0, 0), f.pressures(0, 1));
    const TactileFrame sent = test::fake_frame(seed, seq, Grid{14, 6});
    CHECK(f.pressures == sent.pressures());
    REQUIRE(f.time);
    CHECK(*f.time == sent.timestamp_ms / 1000.0);  // exact: written shortest, read back
    seqs.push_back(seq);
  }
  return seqs;
}

bool ends_with_newline(const std::string& path) {
  const std::string text = test::read_text(path);
  return !text.empty() && text.back() == '\n';
}

std::size_t count_lines_starting_with(const std::string& path, char c) {
  std::ifstream in(path);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) n += !line.empty() && line[0] == c;
  return n;
}

}  // namespace

TEST_CASE("iclap record: records every intact frame, none corrupted, and stops the stream") {
  Scratch scratch;
  FakeSensorScript script;
  script.corrupt_every = 4;
  script.junk_every = 3;
  script.seed = 5;
  PtyFakeSensor fake(script);
  const std::string out = scratch("mug.csv");
  auto args = record_args(fake.path(), out);
  args.insert(args.end(), {"--frames", "12", "--pose", "fixed:0.1,0.2,0.3"});
  const auto r = run_iclap(args, scratch);
  INFO(r.err);
  REQUIRE(r.status == 0);
  CHECK(r.err.find("12 frames recorded") != std::string::npos);
  const iclap::Dataset d = iclap::read_dataset_csv(out);
  CHECK(d.rows == 14);
  CHECK(d.cols == 6);
  REQUIRE(d.frames.size() == 12);
  const auto seqs = recorded_seqs(d, script.seed);
  const auto intact = fake.intact();
  REQUIRE(intact.size() >= 12);
  CHECK(seqs == std::vector<std::size_t>(intact.begin(), intact.begin() + 12));
  for (std::size_t i = 0; i < d.frames.size(); ++i) {
    CHECK(d.frames[i].object == "mug");
    CHECK(d.frames[i].exploration == 2);
    CHECK(d.frames[i].frame == static_cast<std::int64_t>(i));
    CHECK(d.frames[i].position == Eigen::Vector3d(0.1, 0.2, 0.3));
    CHECK_FALSE(d.frames[i].orientation);
  }
  CHECK(ends_with_newline(out));
  // Protocol: stop a leftover stream, matrix info, start at 200 ms, stop.
  const auto ids = fake.command_ids();
  REQUIRE(ids.size() == 4);
  CHECK(ids == std::vector<std::uint8_t>{0x22, 0x30, 0x21, 0x22});
  CHECK(fake.commands()[2].payload == Bytes{0x00, 0xC8, 0x00});
  CHECK_FALSE(fake.streaming());
  bool has_sensor_comment = false;
  for (const auto& c : d.comments) has_sensor_comment |= c.find("sensor: WTS rows=14 cols=6 pitch_m=0.0034") == 0;
  CHECK(has_sensor_comment);
}

TEST_CASE("iclap record: a sensor clock reset is reported, and t runs on without a step back") {
  Scratch scratch;
  FakeSensorScript script;
  script.first_seq = 50;  // 11.0 s, 11.2 s, 11.4 s, then the sensor restarts at 1.0 s
  script.reset_after = 3;
  PtyFakeSensor fake(script);
  const std::string out = scratch("mug.csv");
  auto args = record_args(fake.path(), out);
  args.insert(args.end(), {"--frames", "5", "--pose", "fixed:0,0,0"});
  const auto r = run_iclap(args, scratch);
  INFO(r.err);
  REQUIRE(r.status == 0);
  CHECK(r.err.find("warning: the sensor clock stepped back before frame 3 (a sensor reset?)") != std::string::npos);
  const iclap::Dataset d = iclap::read_dataset_csv(out);
  REQUIRE(d.frames.size() == 5);
  std::vector<double> times;
  for (const auto& f : d.frames) times.push_back(f.time.value_or(-1));
  CHECK(times == std::vector<double>{11.0, 11.2, 11.4, 11.4, 11.6});
}

TEST_CASE("iclap record: an unplug keeps every intact frame, exits 3, and a second run appends") {
  Scratch scratch;
  const std::string out = scratch("unplug.csv");
  FakeSensorScript script;
  script.unplug_after = 20;
  script.corrupt_every = 5;
  script.junk_every = 2;
  script.seed = 9;
  std::vector<std::size_t> first_intact;
  {
    PtyFakeSensor fake(script);
    const auto r = run_iclap(record_args(fake.path(), out), scratch);
    INFO(r.err);
    CHECK(r.status == 3);
    CHECK(r.err.find("device lost") != std::string::npos);
    CHECK(r.err.find("16 frames recorded") != std::string::npos);
    CHECK(fake.unplugged());
    first_intact = fake.intact();
  }
  REQUIRE(first_intact.size() == 16);
  CHECK(ends_with_newline(out));
  iclap::Dataset d = iclap::read_dataset_csv(out);
  CHECK(recorded_seqs(d, script.seed) == first_intact);
  const std::size_t comment_lines = count_lines_starting_with(out, '#');
  CHECK(comment_lines >= 3);

  // Second run, same object and exploration: appends, numbering continues.
  FakeSensorScript again = script;
  again.unplug_after = std::numeric_limits<std::size_t>::max();
  again.first_seq = 1000;
  PtyFakeSensor fake(again);
  auto args = record_args(fake.path(), out);
  args.insert(args.end(), {"--frames", "5"});
  const auto r = run_iclap(args, scratch);
  INFO(r.err);
  REQUIRE(r.status == 0);
  CHECK(r.err.find("appending") != std::string::npos);
  d = iclap::read_dataset_csv(out);
  REQUIRE(d.frames.size() == 21);
  const auto seqs = recorded_seqs(d, script.seed);
  std::vector<std::size_t> expected = first_intact;
  const auto second = fake.intact();
  expected.insert(expected.end(), second.begin(), second.begin() + 5);
  CHECK(seqs == expected);
  for (std::size_t i = 0; i < d.frames.size(); ++i) CHECK(d.frames[i].frame == static_cast<std::int64_t>(i));
  CHECK(count_lines_starting_with(out, '#') == comment_lines);  // header and comments once
  CHECK(count_lines_starting_with(out, 'o') == 1);              // one header row ("object,...")
}

TEST_CASE("iclap record: Ctrl-C stops the sensor and keeps complete rows") {
  Scratch scratch;
  FakeSensorScript script;
  script.seed = 3;
  PtyFakeSensor fake(script);
  const std::string out = scratch("sigint.csv");
  const pid_t pid = spawn_record(fake, out, scratch, "sigint");
  REQUIRE(fake.wait_for([&] { return fake.intact().size() >= 10; }));
  ::kill(pid, SIGINT);
  const int status = test::wait_process(pid);
  const std::string err = test::read_text(scratch("sigint.stderr"));
  INFO(err);
  CHECK(status == 130);
  CHECK(err.find("interrupted") != std::string::npos);
  CHECK(fake.wait_for([&] { return !fake.streaming(); }, 2000ms));
  CHECK(fake.command_ids().back() == wts_id::kStopPeriodicFrames);
  CHECK(ends_with_newline(out));
  const iclap::Dataset d = iclap::read_dataset_csv(out);
  REQUIRE(d.frames.size() >= 1);
  const auto seqs = recorded_seqs(d, script.seed);
  const auto intact = fake.intact();
  REQUIRE(intact.size() >= seqs.size());
  CHECK(seqs == std::vector<std::size_t>(intact.begin(), intact.begin() + static_cast<std::ptrdiff_t>(seqs.size())));
}

TEST_CASE("iclap record: a pose replay gives positions in file order and ends the run") {
  Scratch scratch;
  iclap::Dataset poses;
  poses.rows = 1;
  poses.cols = 1;
  for (int i = 0; i < 4; ++i) {
    iclap::Frame f;
    f.object = "path";
    f.frame = i;
    f.position = Eigen::Vector3d(0.01 * i, -0.02 * i, 0.3);
    f.orientation = Eigen::Quaterniond(0, 1, 0, 0);
    f.pressures = Eigen::MatrixXd::Zero(1, 1);
    poses.frames.push_back(f);
  }
  const std::string pose_file = scratch("poses.csv");
  iclap::write_dataset_csv(pose_file, poses);
  FakeSensorScript script;
  PtyFakeSensor fake(script);
  const std::string out = scratch("replay.csv");
  auto args = record_args(fake.path(), out);
  args.insert(args.end(), {"--pose", "replay:" + pose_file, "--rate", "10"});
  const auto r = run_iclap(args, scratch);
  INFO(r.err);
  REQUIRE(r.status == 0);
  CHECK(r.err.find("pose replay ended") != std::string::npos);
  const iclap::Dataset d = iclap::read_dataset_csv(out);
  REQUIRE(d.frames.size() == 4);
  for (int i = 0; i < 4; ++i) {
    CHECK(d.frames[static_cast<std::size_t>(i)].position.isApprox(poses.frames[static_cast<std::size_t>(i)].position));
    REQUIRE(d.frames[static_cast<std::size_t>(i)].orientation);
    CHECK(d.frames[static_cast<std::size_t>(i)].orientation->x() == 1.0);
  }
  CHECK(fake.commands()[2].payload == Bytes{0x00, 0x64, 0x00});  // 10 frames/s: 100 ms
}

TEST_CASE("iclap record: --seconds, --grid and a silent sensor") {
  Scratch scratch;
  {
    FakeSensorScript script;
    PtyFakeSensor fake(script);
    auto args = record_args(fake.path(), scratch("seconds.csv"));
    args.insert(args.end(), {"--seconds", "0.3"});
    const auto r = run_iclap(args, scratch);
    INFO(r.err);
    CHECK(r.status == 0);
    CHECK(iclap::read_dataset_csv(scratch("seconds.csv")).frames.size() >= 1);
  }
  {  // The sensor does not answer matrix info: fails without --grid ...
    FakeSensorScript script;
    script.answer_matrix_info = false;
    PtyFakeSensor fake(script);
    const auto r = run_iclap(record_args(fake.path(), scratch("silent.csv")), scratch);
    CHECK(r.status == 1);
    CHECK(r.err.find("no reply to 'get matrix info'") != std::string::npos);
    CHECK(r.err.find("--grid") != std::string::npos);
    CHECK_FALSE(fs::exists(scratch("silent.csv")));
  }
  {  // ... and records with it, transposed on purpose (the override wins).
    FakeSensorScript script;
    script.answer_matrix_info = false;
    PtyFakeSensor fake(script);
    auto args = record_args(fake.path(), scratch("override.csv"));
    args.insert(args.end(), {"--grid", "6x14", "--frames", "3"});
    const auto r = run_iclap(args, scratch);
    INFO(r.err);
    CHECK(r.status == 0);
    const auto d = iclap::read_dataset_csv(scratch("override.csv"));
    CHECK(d.rows == 6);
    CHECK(d.cols == 14);
    CHECK(d.frames.size() == 3);
  }
  {  // A grid whose taxel count contradicts the sensor is refused.
    FakeSensorScript script;
    PtyFakeSensor fake(script);
    auto args = record_args(fake.path(), scratch("wrong.csv"));
    args.insert(args.end(), {"--grid", "10x10"});
    const auto r = run_iclap(args, scratch);
    CHECK(r.status == 2);
    CHECK(r.err.find("--grid 10x10 has 100 taxels") != std::string::npos);
  }
  {  // Appending to a file with another grid names the file and line.
    iclap::Dataset other;
    other.rows = 2;
    other.cols = 2;
    iclap::Frame f;
    f.object = "x";
    f.pressures = Eigen::MatrixXd::Zero(2, 2);
    other.frames.push_back(f);
    iclap::write_dataset_csv(scratch("other.csv"), other);
    FakeSensorScript script;
    PtyFakeSensor fake(script);
    const auto r = run_iclap(record_args(fake.path(), scratch("other.csv")), scratch);
    CHECK(r.status == 2);
    INFO(r.err);
    CHECK(r.err.find("\n" + scratch("other.csv") + ":1: header does not match") != std::string::npos);
    const auto ids = fake.command_ids();
    CHECK(std::find(ids.begin(), ids.end(), wts_id::kStartPeriodicFrames) == ids.end());  // never started
  }
}

TEST_CASE("iclap record: a run that records no frame leaves no file behind and exits 1") {
  Scratch scratch;
  {  // A grid the frames do not fit: exit 1 and no header-only file, so the
     // advised retry with the right grid records.
    const std::string out = scratch("grid.csv");
    // Five frames into `out` from a sensor that sends no matrix info.
    const auto record_with_grid = [&](const char* grid) {
      FakeSensorScript script;
      script.answer_matrix_info = false;
      PtyFakeSensor fake(script);
      auto args = record_args(fake.path(), out);
      args.insert(args.end(), {"--grid", grid, "--frames", "5"});
      return run_iclap(args, scratch);
    };
    {
      const auto r = record_with_grid("10x6");
      INFO(r.err);
      CHECK(r.status == 1);
      CHECK(r.err.find("frames of 84 taxels but the grid 10x6 has 60; pass --grid ROWSxCOLS") != std::string::npos);
      CHECK_FALSE(fs::exists(out));
    }
    const auto r = record_with_grid("14x6");
    INFO(r.err);
    CHECK(r.status == 0);
    CHECK(r.err.find("appending") == std::string::npos);
    REQUIRE(fs::exists(out));
    CHECK(iclap::read_dataset_csv(out).frames.size() == 5);
  }
  {  // A silent sensor: exit 1 ("sensor silent" in the usage), no file.
    FakeSensorScript script;
    script.max_frames = 0;
    PtyFakeSensor fake(script);
    auto args = record_args(fake.path(), scratch("silent.csv"));
    args.insert(args.end(), {"--seconds", "0.3"});
    const auto r = run_iclap(args, scratch);
    INFO(r.err);
    CHECK(r.status == 1);
    CHECK(r.err.find("no frame recorded from " + fake.path()) != std::string::npos);
    CHECK(r.err.find(scratch("silent.csv") + " was not created") != std::string::npos);
    CHECK(r.err.find("..-1") == std::string::npos);
    CHECK_FALSE(fs::exists(scratch("silent.csv")));
    CHECK_FALSE(fake.streaming());
  }
  {  // Appending with a silent sensor: exit 1, the file is kept byte for byte;
     // an existing empty file stays (empty), and so does one holding only a
     // byte-order mark (it is a new file, opened at the first frame; it got
     // a header before session 58).
    iclap::write_dataset_csv(scratch("kept.csv"), test::one_mug_frame(0));
    std::ofstream(scratch("empty.csv")).flush();
    std::ofstream(scratch("bom.csv"), std::ios::binary) << "\xEF\xBB\xBF";
    for (const std::string name : {"kept.csv", "empty.csv", "bom.csv"}) {
      CAPTURE(name);
      const std::string before = test::read_text(scratch(name));
      FakeSensorScript script;
      script.max_frames = 0;
      PtyFakeSensor fake(script);
      auto args = record_args(fake.path(), scratch(name));
      args.insert(args.end(), {"--seconds", "0.2", "--pose", "fixed:0,0,0"});
      const auto r = run_iclap(args, scratch);
      INFO(r.err);
      CHECK(r.status == 1);
      REQUIRE(fs::exists(scratch(name)));
      CHECK(test::read_text(scratch(name)) == before);
    }
  }
  {  // A header cut short by an earlier run (killed while creating the file)
     // is completed, and the run says so (session 58; it was refused as a
     // header mismatch before).
    const std::string torn = scratch("torn.csv");
    std::ofstream(torn, std::ios::binary) << "object,exploration,fr";
    FakeSensorScript script;
    script.max_frames = 0;
    PtyFakeSensor fake(script);
    auto args = record_args(fake.path(), torn);
    args.insert(args.end(), {"--seconds", "0.2", "--pose", "fixed:0,0,0"});
    const auto r = run_iclap(args, scratch);
    INFO(r.err);
    CHECK(r.status == 1);
    CHECK(r.err.find(torn + ": completed its header, cut short by an earlier run") != std::string::npos);
    CHECK(r.err.find(torn + " has no row; only its header, cut short by an earlier run, was completed") !=
          std::string::npos);
    const std::string text = test::read_text(torn);
    CHECK(text.rfind("object,exploration,frame,t,x,y,z,p0_0,", 0) == 0);
    CHECK(std::count(text.begin(), text.end(), '\n') == 1);
    const iclap::Dataset ds = iclap::read_dataset_csv(torn);
    CHECK(ds.frames.empty());
    CHECK(ds.rows == 14);
    CHECK(ds.cols == 6);
  }
  {  // Ctrl-C before the first frame: exit 130, no file.
    FakeSensorScript script;
    script.max_frames = 0;
    PtyFakeSensor fake(script);
    const std::string out = scratch("sigint.csv");
    const pid_t pid = spawn_record(fake, out, scratch, "sigint");
    REQUIRE(fake.wait_for([&] { return fake.streaming(); }));
    ::kill(pid, SIGINT);
    const int status = test::wait_process(pid);
    INFO(test::read_text(scratch("sigint.stderr")));
    CHECK(status == 130);
    CHECK_FALSE(fs::exists(out));
  }
  {  // A file size limit (ulimit -f 0) fails the header's write: exit 1 (not
     // killed by SIGXFSZ), and the empty file it created is removed. (Its
     // stderr, a file too, stays empty under the limit.)
    FakeSensorScript script;
    PtyFakeSensor fake(script);
    const std::string out = scratch("limit.csv");
    std::vector<std::string> argv{"/bin/sh", "-c", "ulimit -f 0 && exec \"$0\" \"$@\"", ICLAP_CLI_PATH};
    for (auto& a : record_args(fake.path(), out)) argv.push_back(a);
    argv.insert(argv.end(), {"--frames", "3", "--pose", "fixed:0,0,0"});
    const auto r = test::run_process(argv, scratch("limit"));
    CHECK(r.status == 1);
    CHECK_FALSE(fs::exists(out));
    CHECK_FALSE(fake.streaming());
  }
}

TEST_CASE("iclap record: control bytes of a name are shown as \\xNN") {
  Scratch scratch;
  const auto r = run_iclap(
      {"record", "--port", "/dev/null", "--object", "ab\x1b[2Jc\rX", "--exploration", "0", "--out", scratch("q.csv")},
      scratch);
  CHECK(r.status == 2);
  CHECK(r.err.find("--object: 'ab\\x1b[2Jc\\x0dX' contains a control character") != std::string::npos);
  CHECK(r.err.find('\x1b') == std::string::npos);
  CHECK(r.err.find('\r') == std::string::npos);
  CHECK_FALSE(fs::exists(scratch("q.csv")));
}

TEST_CASE("iclap record: usage errors exit 2 and name the option") {
  Scratch scratch;
  const test::UsageCases cases = {
      {{"record", "--object", "a", "--exploration", "1", "--out", "x.csv"}, "--port"},
      {{"record", "--port", "/dev/null", "--object", "a,b", "--exploration", "1", "--out", "x.csv"}, "--object"},
      {{"record", "--port", "/dev/null", "--object", "a", "--exploration", "-1", "--out", "x.csv"}, "--exploration"},
      {{"record", "--port", "/dev/null", "--object", "a", "--exploration", "1", "--out", "x.csv", "--frames", "3",
        "--seconds", "1"},
       "exclude"},
      {{"record", "--port", "/dev/null", "--object", "a", "--exploration", "1", "--out", "x.csv", "--grid", "14by6"},
       "--grid"},
      {{"record", "--port", "/dev/null", "--object", "a", "--exploration", "1", "--out", "x.csv", "--rate", "0"},
       "rate"},
      {{"record", "--port", "/dev/null", "--object", "a", "--exploration", "1", "--out", "x.csv", "--pose", "fixed:1"},
       "--pose"},
      {{"record", "--port", "/dev/iclap-none", "--object", "a", "--exploration", "1", "--out", "x.csv"},
       "/dev/iclap-none"},
      {{"record", "--port", "/dev/null", "--object", "a", "--exploration", "1", "--out", "x.csv"}, "not a serial port"},
  };
  test::check_usage_errors(cases, scratch);
}

TEST_CASE("iclap devices: serial ports under a device root, and HID enumeration") {
  Scratch scratch;
  const fs::path root = scratch.path / "dev";
  fs::create_directories(root / "serial" / "by-id");
  for (const char* name : {"ttyACM10", "ttyACM2", "ttyUSB0", "ttyS0", "ttyACMx"}) std::ofstream(root / name) << "";
  fs::create_symlink("../../ttyACM2", root / "serial" / "by-id" / "usb-Weiss_Robotics_WTS0614-34A_0001-if00");
  fs::create_symlink("../../gone", root / "serial" / "by-id" / "usb-dangling-if00");
  auto r = run_iclap({"devices", "--serial-only", "--dev-root", root.string()}, scratch);
  INFO(r.out, r.err);
  CHECK(r.status == 0);
  const std::string acm2 = (root / "ttyACM2").string(), acm10 = (root / "ttyACM10").string(),
                    usb0 = (root / "ttyUSB0").string();
  const auto p2 = r.out.find(acm2 + "\n"), p10 = r.out.find(acm10 + "\n"), pu = r.out.find(usb0 + "\n");
  REQUIRE(p2 != std::string::npos);
  REQUIRE(p10 != std::string::npos);
  REQUIRE(pu != std::string::npos);
  CHECK(p2 < p10);  // natural order
  CHECK(p10 < pu);
  CHECK(r.out.find("by-id: " + (root / "serial" / "by-id" / "usb-Weiss_Robotics_WTS0614-34A_0001-if00").string()) >
        p2);
  CHECK(r.out.find("ttyS0") == std::string::npos);
  CHECK(r.out.find("ttyACMx") == std::string::npos);
  CHECK(r.out.find("dangling") == std::string::npos);
  CHECK(r.out.find("HID") == std::string::npos);

  fs::create_directories(scratch.path / "empty");
  r = run_iclap({"devices", "--dev-root", (scratch.path / "empty").string()}, scratch);
  CHECK(r.status == 0);
  CHECK(r.out.find("Serial ports: none found") != std::string::npos);
  CHECK(r.out.find("HID devices") != std::string::npos);  // listed, or "none found"

  r = run_iclap({"devices", "--serial-only", "--hid-only"}, scratch);
  CHECK(r.status == 2);
}

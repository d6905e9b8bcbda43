// SPDX-License-Identifier: MIT
// The POSIX serial transport and the WTS sensor session, end to end through
// a real OS serial device: a pseudo-terminal with the fake sensor on its
// master side. Also pose sources and frame sources.

#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "fake_wts_sensor.hpp"
#include "iclap/data/csv_writer.hpp"
#include "iclap/rig/dataset_frame_source.hpp"
#include "iclap/rig/pose_spec.hpp"
#include "iclap/rig/sensor_frame_source.hpp"
#include "iclap/rig/serial_port.hpp"
#include "iclap/rig/wts_sensor.hpp"
#include "rig_test_util.hpp"
#include "../support/errors.hpp"
#include "../support/temporaries.hpp"

using namespace iclap::rig;
using namespace std::chrono_literals;
using test::FakeSensorScript;
using test::PtyFakeSensor;

namespace {

// Reads frames until `timeout` passes without one; returns their sequence
// numbers after checking each frame's content against the fake's recipe.
std::vector<std::size_t> read_frames(WtsSensor& sensor, std::uint64_t seed, std::chrono::milliseconds quiet = 300ms) {
  std::vector<std::size_t> seqs;
  while (auto f = sensor.next_frame(quiet)) {
    const std::size_t seq = test::fake_frame_seq(f->texels(0, 0), f->texels(0, 1));
    const TactileFrame expected = test::fake_frame(seed, seq, *sensor.grid());
    CHECK(f->texels == expected.texels);
    CHECK(f->timestamp_ms == expected.timestamp_ms);
    seqs.push_back(seq);
  }
  return seqs;
}

// A fake sensor on a pty, opened and streaming one frame per 5 ms, as an
// application starts it (matrix info, then periodic frames).
struct StreamingFake {
  PtyFakeSensor fake;
  SerialPort port;
  WtsSensor sensor;
  explicit StreamingFake(const FakeSensorScript& script) : fake(script), port(fake.path()), sensor(port) {
    sensor.query_matrix_info();
    sensor.start_periodic_frames(5.0);
  }
};

}  // namespace

TEST_CASE("Serial port: open errors name the path and the cause") {
  try {
    SerialPort p("/dev/iclap-no-such-port");
    FAIL("opened a missing port");
  } catch (const TransportError& e) {
    CHECK(e.path() == "/dev/iclap-no-such-port");
    CHECK(std::string(e.what()).find("No such file") != std::string::npos);
  }
  const iclap::test::TempDir dir("serial_open");
  const std::string file = dir.file("not_a_tty");
  std::ofstream(file) << "x";
  try {
    SerialPort p(file);
    FAIL("opened a regular file");
  } catch (const TransportError& e) {
    CHECK(std::string(e.what()).find("not a serial port") != std::string::npos);
  }
  PtyFakeSensor fake(FakeSensorScript{});
  CHECK_THROWS_AS(SerialPort(fake.path(), SerialPort::Settings{12345, true}), iclap::InvalidArgument);
  SerialPort first(fake.path());
  CHECK(first.is_open());
  try {
    SerialPort second(fake.path());
    FAIL("two owners of one port");
  } catch (const TransportError& e) {
    CHECK(std::string(e.what()).find("in use") != std::string::npos);
  }
  first.close();
  CHECK_FALSE(first.is_open());
  std::uint8_t b = 0;
  CHECK_THROWS_AS(first.read(&b, 1, 10ms), TransportError);
  SerialPort again(fake.path());  // the lock went with the close
  CHECK(again.is_open());
}

TEST_CASE("Serial session: loop echo, matrix info, start at 5 frames/s, frames in order") {
  FakeSensorScript script;
  script.max_frames = 20;
  PtyFakeSensor fake(script);
  SerialPort port(fake.path());
  WtsSensor sensor(port);
  const Reply echo = sensor.request_ok(encode_loop({1, 2, 0xAA, 0xAA, 0xAA, 3}));
  CHECK(echo.payload == Bytes{1, 2, 0xAA, 0xAA, 0xAA, 3});
  const MatrixInfo info = sensor.query_matrix_info();
  CHECK(info.res_x == 6);
  CHECK(info.res_y == 14);
  REQUIRE(sensor.grid());
  CHECK(*sensor.grid() == Grid{14, 6});
  CHECK_THROWS_AS(sensor.request_ok(encode_get_sensor_type()), WtsCommandError);  // the fake does not know it
  sensor.start_periodic_frames(5.0);
  CHECK(sensor.streaming());
  const auto seqs = read_frames(sensor, script.seed);
  CHECK(seqs == fake.intact());
  CHECK(seqs.size() == 20);
  CHECK(sensor.stop_periodic_frames());
  CHECK_FALSE(sensor.streaming());
  // The start command carried delay_ms = 200 (flags 0).
  bool saw_start = false;
  for (const auto& c : fake.commands())
    if (c.id == wts_id::kStartPeriodicFrames) {
      CHECK(c.payload == Bytes{0x00, 0xC8, 0x00});
      saw_start = true;
    }
  CHECK(saw_start);
  CHECK(fake.command_ids().back() == wts_id::kStopPeriodicFrames);
  const auto st = sensor.stats();
  CHECK(st.crc_errors == 0);
  CHECK(st.junk_bytes == 0);
}

TEST_CASE("Serial session: junk and corrupted frames are dropped, every intact frame arrives") {
  FakeSensorScript script;
  script.max_frames = 60;
  script.corrupt_every = 4;
  script.junk_every = 3;
  script.seed = 11;
  StreamingFake session(script);
  auto& fake = session.fake;
  auto& sensor = session.sensor;
  const auto seqs = read_frames(sensor, script.seed);
  CHECK(seqs == fake.intact());
  CHECK(fake.intact().size() == 45);
  CHECK(fake.corrupted().size() == 15);
  const auto st = sensor.stats();
  CHECK(st.junk_bytes > 0);
  CHECK(st.crc_errors + st.truncated + st.oversize + st.frames_out_of_range + st.malformed > 0);
}

TEST_CASE("Serial session: an unplug ends the stream with DeviceLost after every intact frame") {
  FakeSensorScript script;
  script.unplug_after = 25;
  script.corrupt_every = 5;
  script.junk_every = 2;
  StreamingFake session(script);
  auto& fake = session.fake;
  auto& sensor = session.sensor;
  std::vector<std::size_t> seqs;
  bool lost = false;
  const auto start = std::chrono::steady_clock::now();
  try {
    for (;;)
      if (auto f = sensor.next_frame(100ms)) seqs.push_back(test::fake_frame_seq(f->texels(0, 0), f->texels(0, 1)));
  } catch (const DeviceLost& e) {
    lost = true;
    CHECK(e.path() == fake.path());
  }
  CHECK(lost);
  CHECK(fake.unplugged());
  CHECK(std::chrono::steady_clock::now() - start < 10s);
  CHECK(seqs == fake.intact());
  CHECK(seqs.size() == 20);
  CHECK(sensor.lost());
  CHECK_THROWS_AS(sensor.next_frame(10ms), DeviceLost);
  CHECK_THROWS_AS(sensor.request(encode_tare()), DeviceLost);
  CHECK_THROWS_AS(sensor.stop_periodic_frames(), DeviceLost);
}

TEST_CASE("Serial session: a silent sensor times out naming the command") {
  FakeSensorScript script;
  script.answer_matrix_info = false;
  PtyFakeSensor fake(script);
  SerialPort port(fake.path());
  WtsSensor::Settings s;
  s.reply_timeout = 50ms;
  s.attempts = 2;
  WtsSensor sensor(port, s);
  try {
    sensor.query_matrix_info();
    FAIL("no timeout");
  } catch (const WtsTimeout& e) {
    CHECK(std::string(e.what()).find("get matrix info") != std::string::npos);
    CHECK(std::string(e.what()).find("2 attempt") != std::string::npos);
  }
  fake.wait_for([&] { return fake.commands().size() >= 2; }, 1000ms);
  CHECK(fake.command_ids() == std::vector<std::uint8_t>{0x30, 0x30});
  CHECK_THROWS_AS(WtsSensor(port, WtsSensor::Settings{50ms, 0, 10, {}}), iclap::InvalidArgument);
}

TEST_CASE("Serial session: frames of a stream left running are discarded at start") {
  FakeSensorScript script;
  script.streaming_at_connect = true;
  script.max_frames = 1000;
  PtyFakeSensor fake(script);
  REQUIRE(fake.wait_for([&] { return fake.stale_frames() >= 3; }));
  SerialPort port(fake.path());
  WtsSensor::Settings s;
  s.parser.grid = Grid{14, 6};  // with an override, stale frames decode; start must drop them
  WtsSensor sensor(port, s);
  CHECK(sensor.stop_periodic_frames());
  sensor.query_matrix_info();
  sensor.start_periodic_frames(5.0);
  std::vector<std::size_t> seqs;
  while (seqs.size() < 10)
    if (auto f = sensor.next_frame(1000ms)) seqs.push_back(test::fake_frame_seq(f->texels(0, 0), f->texels(0, 1)));
    else break;
  REQUIRE(seqs.size() == 10);
  const auto intact = fake.intact();
  REQUIRE(intact.size() >= 10);
  CHECK(std::vector<std::size_t>(intact.begin(), intact.begin() + 10) == seqs);
  CHECK(seqs.front() >= fake.stale_frames());
}

TEST_CASE("Serial session: the destructor stops a stream it started") {
  FakeSensorScript script;
  PtyFakeSensor fake(script);
  {
    SerialPort port(fake.path());
    WtsSensor sensor(port);
    sensor.query_matrix_info();
    sensor.start_periodic_frames(5.0);
    REQUIRE(sensor.next_frame(2000ms));
  }
  CHECK(fake.wait_for([&] { return !fake.streaming(); }, 2000ms));
  CHECK(fake.command_ids().back() == wts_id::kStopPeriodicFrames);
}

TEST_CASE("Sensor frame source pairs frames with replayed poses and ends with them") {
  FakeSensorScript script;
  PtyFakeSensor fake(script);
  SerialPort port(fake.path());
  WtsSensor sensor(port);
  ReplayPoseSource poses({Pose{{0.1, 0, 0}, {}}, Pose{{0.2, 0, 0}, {}}, Pose{{0.3, 0, 0}, {}}}, "three poses");
  CHECK_THROWS_AS(SensorFrameSource(sensor, poses), iclap::InvalidArgument);  // no grid yet
  sensor.query_matrix_info();
  SensorFrameSource source(sensor, poses);
  CHECK(source.grid() == Grid{14, 6});
  CHECK(source.has_time());
  CHECK_FALSE(source.has_orientation());
  sensor.start_periodic_frames(5.0);
  PosedFrame pf;
  std::vector<double> xs;
  for (int i = 0; i < 100; ++i) {
    const auto st = source.next(pf, 2000ms);
    if (st == FrameSource::Status::kEnd) break;
    REQUIRE(st == FrameSource::Status::kFrame);
    xs.push_back(pf.pose.position.x());
    REQUIRE(pf.time);
    const std::size_t seq = test::fake_frame_seq(pf.pressures(0, 0), pf.pressures(0, 1));
    CHECK(*pf.time == doctest::Approx((1000 + 200 * static_cast<double>(seq)) / 1000.0));
    CHECK(pf.pressures.rows() == 14);
  }
  CHECK(xs == std::vector<double>{0.1, 0.2, 0.3});
  CHECK(source.next(pf, 10ms) == FrameSource::Status::kEnd);
  CHECK(source.description().find(fake.path()) != std::string::npos);
}

namespace {
// A SensorFrameSource on the pty fake sensor run by `script`, with `poses`
// poses at the origin (so it ends after that many frames), streaming at
// 5 frames/s.
struct StreamingFrameSource {
  StreamingFrameSource(const FakeSensorScript& script, std::size_t poses_count)
      : fake(script),
        port(fake.path()),
        sensor(port),
        poses(std::vector<Pose>(poses_count, Pose{{0, 0, 0}, {}}), "poses at the origin"),
        source(queried(sensor), poses) {
    sensor.start_periodic_frames(5.0);
  }
  static WtsSensor& queried(WtsSensor& s) {
    s.query_matrix_info();
    return s;
  }
  PtyFakeSensor fake;
  SerialPort port;
  WtsSensor sensor;
  ReplayPoseSource poses;
  SensorFrameSource source;
};
}  // namespace

TEST_CASE("Sensor frame source: time runs on across the sensor clock's 32-bit wrap") {
  FakeSensorScript script;
  // Frame seq has timestamp 1000 + 200 seq ms modulo 2^32: 4294966600,
  // ..., 4294967200, then 104 (which read as 0.104 s after 4294967.2 s).
  const std::size_t first = 21474828;
  script.first_seq = first;
  StreamingFrameSource s(script, 8);
  auto& source = s.source;
  PosedFrame pf;
  std::vector<double> times;
  std::uint64_t first_ms = 0;  // the unwrapped timestamp of the first frame received
  bool wrapped = false;
  while (source.next(pf, 2000ms) == FrameSource::Status::kFrame) {
    REQUIRE(pf.time);
    // The pressures carry seq modulo 4096^2.
    const std::size_t span = 4096 * 4096;
    const std::size_t low = test::fake_frame_seq(pf.pressures(0, 0), pf.pressures(0, 1));
    const std::size_t seq = first + (low + span - first % span) % span;
    const std::uint64_t ms = 1000 + 200 * static_cast<std::uint64_t>(seq);
    if (times.empty()) first_ms = ms;
    wrapped = wrapped || ms >= (std::uint64_t{1} << 32);
    // The sensor's first timestamp as sent, then the time elapsed since.
    CHECK(*pf.time == static_cast<double>(first_ms % (std::uint64_t{1} << 32) + (ms - first_ms)) / 1000.0);
    times.push_back(*pf.time);
  }
  REQUIRE(times.size() == 8);
  CHECK(wrapped);
  CHECK(std::is_sorted(times.begin(), times.end()));
  CHECK(times.back() > 4294967.2);
  CHECK(source.clock_resets() == 0);
}

TEST_CASE("Sensor frame source: a sensor clock reset adds no time and is counted") {
  FakeSensorScript script;
  // Frames 100..103 (21.0 to 21.6 s), then the sensor restarts at 0 (1.0 s).
  script.first_seq = 100;
  script.reset_after = 4;
  StreamingFrameSource s(script, 7);
  auto& source = s.source;
  PosedFrame pf;
  std::vector<double> times;
  std::vector<std::uint64_t> resets;
  while (source.next(pf, 2000ms) == FrameSource::Status::kFrame) {
    REQUIRE(pf.time);
    times.push_back(*pf.time);
    resets.push_back(source.clock_resets());
  }
  CHECK(times == std::vector<double>{21.0, 21.2, 21.4, 21.6, 21.6, 21.8, 22.0});
  CHECK(resets == std::vector<std::uint64_t>{0, 0, 0, 0, 1, 1, 1});
}

TEST_CASE("Pose specs") {
  auto fixed = make_pose_source("fixed:0.1,-2,3e-3");
  auto p = fixed->next();
  REQUIRE(p);
  CHECK(p->position == Eigen::Vector3d(0.1, -2, 3e-3));
  CHECK_FALSE(p->orientation);
  CHECK_FALSE(fixed->has_orientation());
  CHECK(fixed->next()->position == p->position);  // never ends
  // The norm as it is, not rounded to 6 decimals ("0.000000"); the
  // tolerance is the dataset reader's (kQuaternionNormTolerance).
  const std::string tiny = iclap::test::what_of([] { make_pose_source("fixed:0,0,0,1e-7,0,0,0"); });
  CHECK(tiny == "pose: 'fixed:0,0,0,1e-7,0,0,0': the orientation quaternion has norm 1e-07; the pad orientation "
                "must be a unit quaternion (norm 1 +- 0.001)");
  CHECK(iclap::test::what_of([] { make_pose_source("fixed:0,0,0,0.998,0,0,0"); }).find("has norm 0.998;") !=
        std::string::npos);
  // Within the tolerance: normalised.
  CHECK(make_pose_source("fixed:0,0,0,0.9999986,0,0,0")->next()->orientation->w() == 1.0);
  auto oriented = make_pose_source("fixed:0,0,0,1,0,0,0");
  CHECK(oriented->has_orientation());
  CHECK(oriented->next()->orientation->w() == 1.0);
  // Spaces around the numbers are fine; hex and numbers beyond a double are not.
  CHECK(make_pose_source("fixed: 0.1, -2 ,3e-3")->next()->position == p->position);
  for (const char* bad : {"fixed:", "fixed:1,2", "fixed:1,2,3,4", "fixed:1,2,x", "fixed:1,2,nan", "fixed:1,,3",
                          "fixed:0x1,0,0", "fixed:1e400,0,0", "fixed:1 2,0,0",
                          "fixed:0,0,0,2,0,0,0", "nowhere:1", "replay:", "", "omni"}) {
    CAPTURE(bad);
    if (std::string(bad) == "omni" && kHaveOpenHaptics) continue;
    try {
      make_pose_source(bad, "--pose");
      FAIL("accepted");
    } catch (const iclap::InvalidArgument& e) {
      CHECK(e.argument() == "--pose");
    }
  }
  CHECK_THROWS_AS(make_pose_source("replay:/nonexistent/poses.csv"), iclap::IoError);

  // A replay of a dataset file: poses in file order, orientation carried.
  iclap::Dataset d;
  d.rows = 2;
  d.cols = 1;
  for (int i = 0; i < 3; ++i) {
    iclap::Frame f;
    f.object = "cup";
    f.frame = i;
    f.position = Eigen::Vector3d(i, 2.0 * i, 0.5);
    f.orientation = Eigen::Quaterniond(1, 0, 0, 0);
    f.pressures = Eigen::MatrixXd::Constant(2, 1, i);
    d.frames.push_back(f);
  }
  const iclap::test::TempDir dir("pose_replay");
  const std::string file = dir.file("poses.csv");
  iclap::write_dataset_csv(file, d);
  auto replay = make_pose_source("replay:" + file);
  CHECK(replay->has_orientation());
  for (int i = 0; i < 3; ++i) {
    auto q = replay->next();
    REQUIRE(q);
    CHECK(q->position == Eigen::Vector3d(i, 2.0 * i, 0.5));
  }
  CHECK_FALSE(replay->next());
  CHECK(replay->description().find("3 poses") != std::string::npos);
  // A quaternion printed with 4 digits (norm 0.99999), which the dataset
  // reader accepts, is replayed normalised instead of refused.
  iclap::Dataset four = d;
  four.frames[1].orientation = Eigen::Quaterniond(0.7071, 0.7071, 0, 0);
  const std::string four_file = dir.file("poses4.csv");
  iclap::write_dataset_csv(four_file, four);
  auto replay4 = make_pose_source("replay:" + four_file);
  replay4->next();
  CHECK(std::abs(replay4->next()->orientation->norm() - 1.0) < 1e-12);

  DatasetFrameSource frames(d, file);
  CHECK(frames.grid() == Grid{2, 1});
  CHECK(frames.has_orientation());
  CHECK_FALSE(frames.has_time());
  PosedFrame pf;
  int n = 0;
  while (frames.next(pf, 0ms) == FrameSource::Status::kFrame) {
    CHECK(pf.pressures(1, 0) == n);
    CHECK(frames.last_frame().frame == n);
    ++n;
  }
  CHECK(n == 3);
  CHECK_THROWS_AS(DatasetFrameSource(iclap::Dataset{}), iclap::EmptyInput);
  CHECK_THROWS_AS(ReplayPoseSource({}, "none"), iclap::EmptyInput);
  CHECK_THROWS_AS(FixedPoseSource(Pose{{0, std::nan(""), 0}, {}}), iclap::InvalidArgument);
}

// --- WtsSensor over an in-memory stream; DatasetFrameSource misuse ----------

TEST_CASE("WtsSensor: max_queued_frames = 0 is refused") {
  test::MemoryStream s;
  WtsSensor::Settings st;
  st.parser.grid = Grid{2, 3};
  st.max_queued_frames = 0;  // used to be accepted, then pop_front() on an empty queue
  try {
    WtsSensor sensor(s, st);
    FAIL("max_queued_frames = 0 was accepted");
  } catch (const iclap::InvalidArgument& e) {
    CHECK(e.argument() == "settings.max_queued_frames");
  }
  st.max_queued_frames = 1;
  WtsSensor sensor(s, st);
  s.push(encode_frame(test::flat_frame(1, 100)));
  s.push(encode_frame(test::flat_frame(2, 100)));
  auto f = sensor.next_frame(10ms);
  REQUIRE(f);
  CHECK(f->timestamp_ms == 1);
}

TEST_CASE("WtsSensor: next_frame(0ms) polls the stream") {
  test::MemoryStream s;
  WtsSensor::Settings st;
  st.parser.grid = Grid{2, 3};
  WtsSensor sensor(s, st);
  CHECK_FALSE(sensor.next_frame(0ms));  // nothing sent yet
  CHECK(s.reads >= 1);
  s.push(encode_frame(test::flat_frame(7, 100)));
  auto f = sensor.next_frame(0ms);  // used to return nothing without reading
  REQUIRE(f);
  CHECK(f->timestamp_ms == 7);
  CHECK(s.at == s.incoming.size());
  CHECK_FALSE(sensor.next_frame(0ms));
}

TEST_CASE("WtsSensor: a matrix info grid no frame can carry is refused") {
  test::MemoryStream s;
  WtsSensor sensor(s);
  s.push(encode_reply(Reply{wts_id::kGetMatrixInfo, 0, encode_matrix_info_payload(MatrixInfo{0, 14, 340, 340, 4095})}));
  try {
    sensor.query_matrix_info();
    FAIL("a 14x0 grid was accepted");
  } catch (const iclap::InvalidArgument& e) {
    CHECK(e.argument() == "matrix info");
    CHECK(std::string(e.what()).find("res_x=0") != std::string::npos);
  }
  CHECK_FALSE(sensor.grid());
  s.push(encode_reply(Reply{wts_id::kGetMatrixInfo, 0, encode_matrix_info_payload(MatrixInfo{30, 20, 340, 340, 4095})}));
  const MatrixInfo info = sensor.query_matrix_info();
  CHECK(info.res_x == 30);
  REQUIRE(sensor.grid());
  CHECK(*sensor.grid() == Grid{20, 30});
  CHECK(sensor.parser().max_payload() == 1205);  // 20x30 frames fit
}

TEST_CASE("DatasetFrameSource: last_frame() before any frame names the misuse") {
  iclap::Dataset d;
  d.rows = 1;
  d.cols = 1;
  iclap::Frame fr;
  fr.pressures = Eigen::MatrixXd::Zero(1, 1);
  d.frames.push_back(fr);
  DatasetFrameSource src(d, "x.csv");
  try {
    (void)src.last_frame();  // used to throw std::out_of_range from vector::at
    FAIL("no exception");
  } catch (const iclap::InvalidArgument& e) {
    CHECK(e.argument() == "last_frame");
  }
  PosedFrame pf;
  REQUIRE(src.next(pf, 0ms) == FrameSource::Status::kFrame);
  CHECK_NOTHROW((void)src.last_frame());
}

TEST_CASE("Poses: every position coordinate and the quaternion are checked; a replay names the bad pose") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  using iclap::test::what_of;  // the InvalidArgument's what(), "(no error)" when accepted
  for (int i = 0; i < 3; ++i) {
    CAPTURE(i);
    for (double bad : {nan, inf, -inf}) {
      CAPTURE(bad);
      Pose pose;
      pose.position[i] = bad;
      CHECK(what_of([&] { FixedPoseSource source(pose); }) ==
            "pose: position coordinate " + std::to_string(i) + " is not finite");
      std::vector<Pose> poses(3);
      poses[2] = pose;
      CHECK(what_of([&] { ReplayPoseSource source(poses, "three"); }) ==
            "poses[2]: position coordinate " + std::to_string(i) + " is not finite");
    }
  }
  for (const Eigen::Quaterniond& q : {Eigen::Quaterniond(nan, 0, 0, 0), Eigen::Quaterniond(1, 0, nan, 0)}) {
    const std::string m = what_of([&] { FixedPoseSource source(Pose{{0, 0, 0}, q}); });
    CAPTURE(m);
    CHECK(m.find("pose: orientation quaternion has norm") == 0);
    CHECK(m.find("expected 1 within 1e-6") != std::string::npos);
  }
  // A replay's poses all have an orientation or none has.
  const Pose plain{{0, 0, 0}, {}};
  const Pose oriented{{0, 0, 0}, Eigen::Quaterniond::Identity()};
  CHECK(what_of([&] { ReplayPoseSource source({oriented, plain}, "mixed"); }) ==
        "poses: pose 1 differs from pose 0 in having an orientation");
  CHECK(what_of([&] { ReplayPoseSource source({plain, plain, oriented}, "mixed"); }) ==
        "poses: pose 2 differs from pose 0 in having an orientation");
  CHECK(what_of([&] { ReplayPoseSource source({oriented, oriented}, "both"); }) == "(no error)");
}

TEST_CASE("DatasetFrameSource: each frame carries its own time, or none") {
  iclap::Dataset d;
  d.rows = 1;
  d.cols = 1;
  for (int i = 0; i < 2; ++i) {
    iclap::Frame fr;
    fr.pressures = Eigen::MatrixXd::Constant(1, 1, i);
    fr.time = 0.25 * (i + 1);
    d.frames.push_back(fr);
  }
  DatasetFrameSource timed(d, "timed.csv");
  CHECK(timed.has_time());
  PosedFrame pf;
  for (double t : {0.25, 0.5}) {
    CAPTURE(t);
    REQUIRE(timed.next(pf, 0ms) == FrameSource::Status::kFrame);
    REQUIRE(pf.time);
    CHECK(*pf.time == t);
  }
  // The same PosedFrame, from a dataset without times: the old time goes.
  for (auto& fr : d.frames) fr.time.reset();
  DatasetFrameSource untimed(d, "untimed.csv");
  CHECK_FALSE(untimed.has_time());
  REQUIRE(untimed.next(pf, 0ms) == FrameSource::Status::kFrame);
  CHECK_FALSE(pf.time);
}

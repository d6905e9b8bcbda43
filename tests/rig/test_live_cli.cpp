// SPDX-License-Identifier: MIT
// `iclap live` end to end: the real iclap binary recognises an object from a
// fake WTS sensor on a pseudo-terminal (streaming the tactile frames of a
// known exploration, with junk and corrupted packets, and an unplug), from
// a replayed dataset and from the simulator; bad input; the cross-validated
// report. Also the simulator frame source in process.
//
// Fixtures: tests/fixtures/live (see make_fixtures.sh there): references of
// 4 simulated objects (explorations 0 and 1) and exploration 2 of c_clamp and
// of scissors.

#include <doctest/doctest.h>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "fake_wts_sensor.hpp"
#include "iclap/data/csv_reader.hpp"
#include "iclap/data/csv_writer.hpp"
#include "iclap/rig/sim_frame_source.hpp"
#include "iclap/sim/builtin_objects.hpp"
#include "process_util.hpp"
#include "pty_port.hpp"

using namespace iclap::rig;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

namespace {

const std::string kFixtures = ICLAP_TEST_FIXTURES "/live/";
const std::string kTrain = kFixtures + "train.csv";
const std::string kClamp = kFixtures + "c_clamp_2.csv";
const std::string kScissors = kFixtures + "scissors_2.csv";
// Fixed weights: no weight search, so runs are quick and their outcome
// does not depend on it.
const std::string kMethod = "0.6*iclap+0.2*icp+0.2*bow";

/// A scratch directory of this test program.
struct Scratch : test::ScratchDir {
  Scratch() : test::ScratchDir("live") {}
};

using test::run_iclap;

std::vector<std::string> lines_starting_with(const std::string& text, const std::string& prefix) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (line.compare(0, prefix.size(), prefix) == 0) out.push_back(line);
  return out;
}

/// Frames of a dataset file as the WTS sends them (12-bit taxels).
std::vector<TactileFrame> wire_frames(const iclap::Dataset& d) {
  std::vector<TactileFrame> out;
  for (std::size_t i = 0; i < d.frames.size(); ++i) {
    TactileFrame f;
    f.timestamp_ms = static_cast<std::uint32_t>(1000 + 200 * i);
    f.texels.resize(d.rows, d.cols);
    for (iclap::Index r = 0; r < d.rows; ++r)
      for (iclap::Index c = 0; c < d.cols; ++c) {
        const double p = d.frames[i].pressures(r, c);
        REQUIRE(p == std::round(p));  // the simulator writes raw integer units
        f.texels(r, c) = static_cast<std::uint16_t>(p);
      }
    out.push_back(std::move(f));
  }
  return out;
}

std::size_t contact_frames(const iclap::Dataset& d, std::size_t first_n) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < std::min(first_n, d.frames.size()); ++i) n += iclap::is_contact(d.frames[i]);
  return n;
}

/// A WTS sensor on a pseudo-terminal that streams given frames, in order,
/// after "start periodic frames", then falls silent; it answers the
/// commands `iclap live` sends like PtyFakeSensor (fake_wts_sensor.hpp),
/// whose frames are random and cannot be chosen. Damage never costs a
/// frame, so the pose replay stays paired with the frames: junk bytes go
/// between packets and a corrupted copy of a frame (one flipped bit) goes
/// before the intact one. `unplug_after` closes the port after that many
/// intact frames, once the host has read them.
class ExplorationSensor {
 public:
  struct Script {
    std::vector<TactileFrame> frames;
    std::size_t junk_every = 0;
    std::size_t corrupt_every = 0;
    std::size_t unplug_after = std::numeric_limits<std::size_t>::max();
    int frame_interval_ms = 3;
    std::uint64_t seed = 7;
  };

  explicit ExplorationSensor(Script script) : script_(std::move(script)) {
    thread_ = std::thread([this] { run(); });
  }
  ~ExplorationSensor() {
    quit_ = true;
    thread_.join();
  }
  ExplorationSensor(const ExplorationSensor&) = delete;
  ExplorationSensor& operator=(const ExplorationSensor&) = delete;

  const std::string& path() const { return port_.path(); }
  std::size_t sent() const { return sent_; }
  std::size_t corrupted() const { return corrupted_; }
  bool streaming() const { return streaming_; }
  bool unplugged() const { return unplugged_; }
  std::vector<std::uint8_t> command_ids() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return ids_;
  }

 private:
  void run() {
    iclap::Rng damage(script_.seed);
    auto next = std::chrono::steady_clock::now();
    std::uint8_t buf[512];
    while (!quit_ && port_.is_open()) {
      port_.flush();
      if (const std::size_t n = port_.read(buf, sizeof buf, 2ms)) {
        framer_.feed(buf, n);
        while (auto packet = framer_.next()) handle(*packet);
      }
      if (streaming_ && port_.drained() && sent_ < script_.frames.size() && std::chrono::steady_clock::now() >= next) {
        next = std::chrono::steady_clock::now() + std::chrono::milliseconds(script_.frame_interval_ms);
        send(damage);
        if (sent_ >= script_.unplug_after) {
          unplug();
          return;
        }
      }
    }
  }

  void handle(const RawPacket& packet) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ids_.push_back(packet.id);
    }
    Reply reply{packet.id, 0, {}};
    if (packet.id == wts_id::kGetMatrixInfo) reply.payload = encode_matrix_info_payload(MatrixInfo{6, 14, 340, 340, 4095});
    if (packet.id == wts_id::kStartPeriodicFrames) streaming_ = true;
    if (packet.id == wts_id::kStopPeriodicFrames) streaming_ = false;
    port_.queue(encode_reply(reply));
  }

  void send(iclap::Rng& damage) {
    const std::size_t k = sent_ + 1;
    const Bytes packet = encode_frame(script_.frames[sent_]);
    if (script_.junk_every && k % script_.junk_every == 0)
      for (std::uint64_t i = 0, n = 1 + damage.below(30); i < n; ++i)
        port_.queue(damage.below(3) == 0 ? std::uint8_t{0xAA} : static_cast<std::uint8_t>(damage.below(256)));
    if (script_.corrupt_every && k % script_.corrupt_every == 0) {
      Bytes bad = packet;
      bad[3 + damage.below(bad.size() - 3)] ^= static_cast<std::uint8_t>(1u << damage.below(8));
      port_.queue(bad);
      ++corrupted_;
    }
    port_.queue(packet);
    port_.flush(2000ms);
    ++sent_;
  }

  // Closes the port once the host has read everything.
  void unplug() {
    port_.unplug([this] { unplugged_ = true; });
  }

  Script script_;
  test::PtyPort port_;
  std::thread thread_;
  std::atomic<bool> quit_{false};
  std::atomic<bool> streaming_{false};
  std::atomic<bool> unplugged_{false};
  std::atomic<std::size_t> sent_{0};
  std::atomic<std::size_t> corrupted_{0};
  PacketFramer framer_;
  mutable std::mutex mutex_;
  std::vector<std::uint8_t> ids_;
};

std::vector<std::string> live_args(const std::string& port) {
  return {"live", "--references", kTrain, "--method", kMethod, "--port", port, "--pose", "replay:" + kClamp};
}

}  // namespace

TEST_CASE("iclap live --port: recognises the streamed exploration through junk and corrupted packets") {
  Scratch scratch;
  const iclap::Dataset clamp = iclap::read_dataset_csv(kClamp);
  ExplorationSensor::Script script;
  script.frames = wire_frames(clamp);
  script.junk_every = 2;
  script.corrupt_every = 3;
  ExplorationSensor fake(script);
  const auto r = run_iclap(live_args(fake.path()), scratch);
  INFO(r.out);
  INFO(r.err);
  REQUIRE(r.status == 0);
  const auto decision = lines_starting_with(r.out, "decision: ");
  REQUIRE(decision.size() == 1);
  CHECK(decision[0].find("decision: c_clamp after ") == 0);
  CHECK(decision[0].find("(confident)") != std::string::npos);
  // Stopped by the confidence before the exploration ran out; one line per
  // touch, one touch per contact frame received.
  const auto touches = lines_starting_with(r.out, "touch ");
  REQUIRE(!touches.empty());
  CHECK(touches.size() < contact_frames(clamp, clamp.frames.size()));
  CHECK(touches.back().find("touch " + std::to_string(touches.size()) + " (frame ") == 0);
  CHECK(touches.back().find(": c_clamp, confidence ") != std::string::npos);
  CHECK(decision[0].find("after " + std::to_string(touches.size()) + " touch(es)") != std::string::npos);
  CHECK(fake.corrupted() >= 2);  // damage was on the wire
  // Same touches and decision as replaying the exploration's file: nothing
  // was lost or mispaired on the way.
  const auto replay = run_iclap({"live", "--references", kTrain, "--method", kMethod, "--replay", kClamp}, scratch);
  REQUIRE(replay.status == 0);
  CHECK(lines_starting_with(replay.out, "touch ") == touches);
  // The stream was stopped on the way out: stop (leftover), info, start, stop.
  const auto ids = fake.command_ids();
  CHECK(ids == std::vector<std::uint8_t>{wts_id::kStopPeriodicFrames, wts_id::kGetMatrixInfo,
                                          wts_id::kStartPeriodicFrames, wts_id::kStopPeriodicFrames});
  CHECK_FALSE(fake.streaming());
}

TEST_CASE("iclap live --port: an unplug mid-stream exits 3 and reports the touches so far") {
  Scratch scratch;
  const iclap::Dataset clamp = iclap::read_dataset_csv(kClamp);
  ExplorationSensor::Script script;
  script.frames = wire_frames(clamp);
  script.unplug_after = 9;
  script.junk_every = 4;
  ExplorationSensor fake(script);
  auto args = live_args(fake.path());
  args.insert(args.end(), {"--confidence", "1"});  // never confident: only the unplug ends the run
  const auto r = run_iclap(args, scratch);
  INFO(r.out);
  INFO(r.err);
  CHECK(r.status == 3);
  CHECK(fake.unplugged());
  const std::size_t expected = contact_frames(clamp, 9);
  REQUIRE(expected > 0);
  CHECK(lines_starting_with(r.out, "touch ").size() == expected);
  const auto decision = lines_starting_with(r.out, "decision: ");
  REQUIRE(decision.size() == 1);
  CHECK(decision[0].find("after " + std::to_string(expected) + " touch(es) (9 frames)") != std::string::npos);
  CHECK(decision[0].find("(device lost)") != std::string::npos);
  CHECK(r.err.find("device lost after 9 frames, " + std::to_string(expected) + " touches") != std::string::npos);
}

TEST_CASE("iclap live --port: Ctrl-C stops the sensor's stream and exits 130") {
  Scratch scratch;
  const iclap::Dataset clamp = iclap::read_dataset_csv(kClamp);
  ExplorationSensor::Script script;
  script.frames = wire_frames(clamp);
  script.frame_interval_ms = 40;
  ExplorationSensor fake(script);
  std::vector<std::string> argv{ICLAP_CLI_PATH};
  for (const auto& a : live_args(fake.path())) argv.push_back(a);
  argv.insert(argv.end(), {"--confidence", "1"});
  const pid_t pid = test::spawn_process(argv, scratch("sigint.stdout"), scratch("sigint.stderr"));
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (fake.sent() < 6 && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(5ms);
  REQUIRE(fake.sent() >= 6);
  ::kill(pid, SIGINT);
  const int status = test::wait_process(pid);
  const std::string out = test::read_text(scratch("sigint.stdout"));
  INFO(out);
  INFO(test::read_text(scratch("sigint.stderr")));
  CHECK(status == 130);
  CHECK(lines_starting_with(out, "decision: ").size() == 1);
  CHECK(out.find("(interrupted)") != std::string::npos);
  const auto wait_until = std::chrono::steady_clock::now() + 2s;
  while (fake.streaming() && std::chrono::steady_clock::now() < wait_until) std::this_thread::sleep_for(5ms);
  CHECK_FALSE(fake.streaming());
  CHECK(fake.command_ids().back() == wts_id::kStopPeriodicFrames);
}

TEST_CASE("iclap live --replay and --simulate") {
  Scratch scratch;
  {  // One object of a file, its truth reported; the limit stops the run.
    const auto r = run_iclap({"live", "--references", kTrain, "--method", kMethod, "--replay", kScissors,
                              "--object", "scissors", "--exploration", "2", "--max-touches", "4", "--top", "2"},
                             scratch);
    INFO(r.out);
    INFO(r.err);
    REQUIRE(r.status == 0);
    const auto touches = lines_starting_with(r.out, "touch ");
    REQUIRE(touches.size() == 4);
    for (const auto& t : touches) CHECK(std::count(t.begin(), t.end(), ',') == 2);  // "confidence", then 2 objects
    CHECK(lines_starting_with(r.out, "decision: ")[0].find("after 4 touch(es)") != std::string::npos);
    CHECK(r.out.find("(touch limit)") != std::string::npos);
    CHECK(!lines_starting_with(r.out, "truth: scissors (").empty());
  }
  {  // Threshold 0 stops at --min-touches.
    const auto r = run_iclap({"live", "--references", kTrain, "--method", kMethod, "--replay", kScissors,
                              "--confidence", "0", "--min-touches", "3"},
                             scratch);
    REQUIRE(r.status == 0);
    CHECK(lines_starting_with(r.out, "touch ").size() == 3);
    CHECK(r.out.find("(confident)") != std::string::npos);
  }
  {  // Exploration ids may be negative (the reader takes any integer):
     // --exploration selects one (it was refused as outside [0, ...]).
    iclap::Dataset d = iclap::read_dataset_csv(kClamp);
    for (auto& f : d.frames) f.exploration = -2;
    iclap::write_dataset_csv(scratch("clamp_negative.csv"), d);
    const auto r = run_iclap({"live", "--references", kTrain, "--method", kMethod, "--replay",
                              scratch("clamp_negative.csv"), "--exploration", "-2", "--max-touches", "2"},
                             scratch);
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(r.out.find("source: replay of " + scratch("clamp_negative.csv") + ", exploration -2\n") != std::string::npos);
    CHECK(lines_starting_with(r.out, "touch ").size() == 2);
    CHECK(!lines_starting_with(r.out, "truth: c_clamp (").empty());
    // An id the file does not hold is still named.
    const auto none = run_iclap({"live", "--references", kTrain, "--method", kMethod, "--replay",
                                 scratch("clamp_negative.csv"), "--exploration", "-3"},
                                scratch);
    CHECK(none.status == 2);
    CHECK(none.err.find("has no frame of exploration -3") != std::string::npos);
  }
  {  // A replay without a touch: no decision, exit 1.
    iclap::Dataset idle = iclap::read_dataset_csv(kScissors);
    idle.frames.resize(2);
    for (auto& f : idle.frames) f.pressures.setZero();
    iclap::write_dataset_csv(scratch("idle.csv"), idle);
    const auto r = run_iclap({"live", "--references", kTrain, "--method", kMethod, "--replay", scratch("idle.csv")},
                             scratch);
    CHECK(r.status == 1);
    CHECK(r.out.find("no decision: no touch in 2 frame(s)") != std::string::npos);
  }
  {  // A built-in object simulated now (fitted weights: chosen on the references).
    const auto r = run_iclap({"live", "--references", kTrain, "--method", "iclap+icp", "--simulate", "c_clamp",
                              "--exploration", "7", "--max-touches", "5", "--confidence", "1", "--weight-repeats", "1"},
                             scratch);
    INFO(r.out);
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(r.out.find("method: iclap+icp with weights ") != std::string::npos);
    CHECK(r.out.find("source: simulated exploration 7 of c_clamp (seed 1)") != std::string::npos);
    CHECK(lines_starting_with(r.out, "touch ").size() == 5);
    CHECK(!lines_starting_with(r.out, "truth: c_clamp (").empty());
  }
  {  // Height and contact patches (beyond the paper) from the replayed frames' pad orientation.
    const auto r = run_iclap({"live", "--references", kTrain, "--method", "0.5*height+0.5*patch", "--replay", kScissors,
                              "--confidence", "1", "--max-touches", "3", "--top", "4"},
                             scratch);
    INFO(r.out);
    INFO(r.err);
    REQUIRE(r.status == 0);
    const auto touches = lines_starting_with(r.out, "touch ");
    REQUIRE(!touches.empty());
    CHECK(touches.size() <= 3);
    CHECK(std::count(touches[0].begin(), touches[0].end(), ',') == 4);  // "confidence", then 4 objects
    CHECK(!lines_starting_with(r.out, "truth: scissors (").empty());
    const auto cv = run_iclap({"live", "--references", kTrain, "--cross-validate", "--method", "0.5*height+0.5*patch",
                               "--max-touches", "3", "--fixed", "1,3", "--repeats", "1"},
                              scratch);
    INFO(cv.err);
    REQUIRE(cv.status == 0);
    CHECK(cv.out.find("8 held-out explorations replayed") != std::string::npos);
  }
  {  // Simulated now with the scene and operator options: the same frames as
     // `iclap simulate` writes with them, and not those of the default operator.
    const std::vector<std::string> scene = {"--start-candidates", "8",  "--sweep-min-mm", "10", "--sweep-max-mm", "20",
                                            "--turn-probability", "0",  "--shift-mm",     "4",  "--yaw-deg",      "3",
                                            "--frames",           "60"};
    std::vector<std::string> sim = {"simulate", "--explorations", "1", "--out", scratch("covering.csv")};
    sim.insert(sim.end(), scene.begin(), scene.end());
    REQUIRE(run_iclap(sim, scratch).status == 0);
    const std::vector<std::string> live = {"live", "--references", kTrain, "--method", kMethod, "--confidence", "1",
                                           "--max-touches", "8"};
    std::vector<std::string> now = live, replayed = live, plain = live;
    now.insert(now.end(), {"--simulate", "c_clamp", "--exploration", "0"});
    now.insert(now.end(), scene.begin(), scene.end());
    replayed.insert(replayed.end(), {"--replay", scratch("covering.csv"), "--object", "c_clamp", "--exploration", "0"});
    plain.insert(plain.end(), {"--simulate", "c_clamp", "--exploration", "0"});
    const auto a = run_iclap(now, scratch), b = run_iclap(replayed, scratch), c = run_iclap(plain, scratch);
    INFO(a.err);
    INFO(b.err);
    REQUIRE(a.status == 0);
    REQUIRE(b.status == 0);
    REQUIRE(c.status == 0);
    const auto touches = lines_starting_with(a.out, "touch ");
    CHECK(touches.size() == 8);
    CHECK(touches == lines_starting_with(b.out, "touch "));
    CHECK(touches != lines_starting_with(c.out, "touch "));
  }
  {  // A mesh file, its unit from meshes.json beside it: not a reference object.
    const std::string mesh = ICLAP_SHARED_DIR "/data/meshes/wt_rubber_mallet.ply";
    if (fs::exists(mesh)) {
      const auto r = run_iclap({"live", "--references", kTrain, "--method", kMethod, "--simulate", mesh,
                                "--max-touches", "3"},
                               scratch);
      INFO(r.err);
      REQUIRE(r.status == 0);
      CHECK(r.out.find("truth: wt_rubber_mallet (not among the references)") != std::string::npos);
    }
  }
}

TEST_CASE("iclap live --cross-validate: the stop rule against fixed counts, deterministic") {
  Scratch scratch;
  const std::vector<std::string> args = {"live", "--references", kTrain, "--cross-validate", "--method", kMethod,
                                         "--confidence", "0,0.3,1", "--max-touches", "6", "--fixed", "1,6",
                                         "--repeats", "1", "--weight-repeats", "1", "--traces", scratch("traces.csv")};
  const auto r = run_iclap(args, scratch);
  INFO(r.out);
  INFO(r.err);
  REQUIRE(r.status == 0);
  CHECK(r.out.find("2 folds") != std::string::npos);
  CHECK(r.out.find("8 held-out explorations replayed") != std::string::npos);
  // Threshold 0 stops after 1 touch, threshold 1 never (6 touches): their
  // accuracies are the fixed counts' (time order).
  std::istringstream in(r.out);
  std::string line;
  std::vector<std::string> rows;
  while (std::getline(in, line)) {
    std::istringstream l(line);
    std::string first;
    l >> first;
    if (first == "0.00" || first == "0.30" || first == "1.00" || first == "1" || first == "6") rows.push_back(line);
  }
  REQUIRE(rows.size() == 5);
  auto field = [](const std::string& row, int k) {
    std::istringstream l(row);
    std::string w;
    for (int i = 0; i <= k; ++i) l >> w;
    return w;
  };
  CHECK(field(rows[0], 2) == "1.00");  // mean touches at threshold 0
  CHECK(field(rows[2], 2) == "6.00");  // threshold 1
  CHECK(field(rows[0], 1) == field(rows[3], 1));  // accuracy = fixed 1 touch, time order
  CHECK(field(rows[2], 1) == field(rows[4], 1));  // accuracy = fixed 6 touches
  // The traces: one row per replayed touch, 8 explorations x 6 touches.
  const std::string traces = test::read_text(scratch("traces.csv"));
  CHECK(traces.find("fold,object,exploration,touches,recognised,confidence,correct,d_scissors,d_wooden_cuboid_1,d_c_clamp,d_hammer\n") == 0);  // objects in file order
  CHECK(std::count(traces.begin(), traces.end(), '\n') == 1 + 8 * 6);
  // Deterministic: the same report again (but for the time).
  const auto again = run_iclap(args, scratch);
  auto strip_time = [](const std::string& s) { return s.substr(0, s.find("Total time")); };
  CHECK(strip_time(again.out) == strip_time(r.out));
}

TEST_CASE("iclap live: bad input exits 2 with a clear message") {
  Scratch scratch;
  iclap::Dataset small;
  small.rows = 2;
  small.cols = 2;
  iclap::Frame f;
  f.object = "x";
  f.pressures = Eigen::MatrixXd::Constant(2, 2, 100.0);
  small.frames.push_back(f);
  iclap::write_dataset_csv(scratch("grid2x2.csv"), small);
  // The references and a replay without the pad orientation.
  auto strip_orientation = [&](const std::string& from, const std::string& to) {
    iclap::Dataset d = iclap::read_dataset_csv(from);
    for (auto& fr : d.frames) fr.orientation.reset();
    iclap::write_dataset_csv(scratch(to), d);
  };
  strip_orientation(kTrain, "train_no_pose.csv");
  strip_orientation(kClamp, "clamp_no_pose.csv");
  // References with a position no float ICP can square (a unit error).
  {
    iclap::Dataset d = iclap::read_dataset_csv(kTrain);
    const auto contact = std::find_if(d.frames.begin(), d.frames.end(), [](const iclap::Frame& fr) {
      return iclap::is_contact(fr);
    });
    REQUIRE(contact != d.frames.end());
    contact->position.x() = 1e300;
    iclap::write_dataset_csv(scratch("train_far.csv"), d);
  }
  // Two objects of one exploration each: enough to choose among, too few
  // explorations to hold one out (c_clamp_2.csv alone is one object).
  {
    iclap::Dataset d = iclap::read_dataset_csv(kClamp);
    const iclap::Dataset other = iclap::read_dataset_csv(kScissors);
    d.frames.insert(d.frames.end(), other.frames.begin(), other.frames.end());
    iclap::write_dataset_csv(scratch("two_single.csv"), d);
  }
  const std::string refs = kTrain;
  const test::UsageCases cases = {
      {{"live", "--references", scratch("train_far.csv"), "--method", "0.5*icp+0.5*bow", "--replay", kClamp},
       scratch("train_far.csv") + ": object '"},
      {{"live", "--references", scratch("train_far.csv"), "--method", "0.5*icp+0.5*bow", "--replay", kClamp},
       "position coordinate 1e+300 m is beyond the float ICP's range"},
      {{"live", "--references", refs, "--method", "0.5*icp+0.5*bow", "--replay", scratch("train_far.csv")},
       "replay of " + scratch("train_far.csv")},
      {{"live", "--references", refs, "--method", "0.5*icp+0.5*bow", "--replay", scratch("train_far.csv")},
       ": position coordinate 1e+300 m is beyond the float ICP's range"},
      {{"live", "--references", refs, "--method", "0.5*icp+0.5*bow", "--k", "100000", "--replay", kClamp},
       "--k: k = 100000 exceeds the number of features"},
      {{"live", "--references", scratch("train_no_pose.csv"), "--method", "height", "--replay", kClamp},
       scratch("train_no_pose.csv") + ": the height classifier needs the pad orientation (columns qw, qx, qy, qz)"},
      {{"live", "--references", scratch("train_no_pose.csv"), "--method", "0.5*bow+0.5*patch", "--replay", kClamp},
       "the patch classifier needs the pad orientation"},
      {{"live", "--references", refs, "--method", "0.5*icp+0.5*height", "--replay", scratch("clamp_no_pose.csv")},
       "the height classifier needs the pad orientation, which the source does not give (replay of "},
      {{"live", "--replay", kClamp}, "missing --references"},
      {{"live", "--references", refs}, "no source"},
      {{"live", "--references", refs, "--replay", kClamp, "--simulate", "hammer"}, "exclude each other"},
      {{"live", "--references", scratch("none.csv"), "--replay", kClamp}, scratch("none.csv")},
      {{"live", "--references", refs, "--method", "icp+", "--replay", kClamp}, "--method"},
      {{"live", "--references", refs, "--method", "0.5*icp+0.6*bow", "--replay", kClamp}, "sum to 1.1"},
      {{"live", "--references", refs, "--method", "icp+foo", "--replay", kClamp}, "unknown classifier 'foo'"},
      {{"live", "--references", refs, "--confidence", "1.5", "--replay", kClamp}, "--confidence"},
      {{"live", "--references", refs, "--confidence", "0.2,0.4", "--replay", kClamp}, "needs --cross-validate"},
      {{"live", "--references", refs, "--min-touches", "5", "--max-touches", "2", "--replay", kClamp},
       "--min-touches 5 exceeds --max-touches 2"},
      {{"live", "--references", refs, "--simulate", "teapot"}, "neither a built-in object"},
      // A mesh path that does not exist is named as such (it was "no
      // 'meshes.json' gives its unit; pass --unit m or mm").
      {{"live", "--references", refs, "--simulate", scratch("no_such.obj")},
       scratch("no_such.obj") + ": cannot open for reading"},
      {{"live", "--references", refs, "--replay", kClamp, "--object", "teapot"}, "has no frame of object 'teapot'"},
      {{"live", "--references", refs, "--replay", kClamp, "--pose", "fixed:0,0,0"}, "--pose needs --port"},
      {{"live", "--references", refs, "--replay", kClamp, "--real-time"}, "--real-time needs --simulate"},
      {{"live", "--references", refs, "--replay", kClamp, "--start-candidates", "8"},
       "--start-candidates needs --simulate"},
      {{"live", "--references", refs, "--cross-validate", "--frames", "10"}, "--cross-validate takes no --frames"},
      {{"live", "--references", refs, "--simulate", "hammer", "--sweep-min-mm", "90"},
       "--sweep-max-mm must be >= --sweep-min-mm, got 80 < 90"},
      {{"live", "--references", refs, "--method", kMethod, "--replay", scratch("grid2x2.csv")},
       "taxel grid 2x2 differs from the references' 14x6"},
      {{"live", "--references", scratch("two_single.csv"), "--replay", kClamp}, "give fixed weights"},
      {{"live", "--references", kClamp, "--replay", kClamp},
       kClamp + ": 1 object ('c_clamp'); recognition needs at least 2 objects to choose among"},
      {{"live", "--references", kClamp, "--method", kMethod, "--replay", kScissors},
       kClamp + ": 1 object ('c_clamp'); recognition needs at least 2 objects to choose among"},
      {{"live", "--references", refs, "--port", "/dev/iclap-none"}, "/dev/iclap-none"},
      {{"live", "--references", refs, "--cross-validate", "--replay", kClamp}, "--cross-validate takes no --replay"},
      {{"live", "--references", refs, "--cross-validate", "--fixed", "30"}, "--fixed: 30 exceeds --max-touches 20"},
      {{"live", "--references", scratch("two_single.csv"), "--cross-validate", "--method", kMethod},
       "exploration with touches; cross validation needs at least 2"},
      {{"live", "--references", refs, "--cross-validate", "--method", "iclap+icp"}, "at least 3 explorations"},
      {{"live", "--references", refs, "--cross-validate", "--method", "iclap+icp"}, refs + ": object '"},
      {{"live", "--references", refs, "--replay", kClamp, "--normalization", "minmax"}, "unknown option --normalization"},
  };
  test::check_usage_errors(cases, scratch);
}

TEST_CASE("iclap live --cross-validate: source options are refused, --traces is checked before computing") {
  Scratch scratch;
  // Quick if a case were not refused (as these were): fixed weights, few touches.
  const std::vector<std::string> cv = {"live", "--references", kTrain, "--cross-validate", "--method", kMethod,
                                       "--max-touches", "2", "--fixed", "2", "--repeats", "1"};
  const auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = cv;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  test::UsageCases cases = {
      {with({"--object", "hammer"}), "--cross-validate takes no --object"},
      {with({"--exploration", "7"}), "--cross-validate takes no --exploration"},
      {with({"--pose", "fixed:0,0,0"}), "--cross-validate takes no --pose"},
      {with({"--rate", "1000"}), "--cross-validate takes no --rate"},
      {with({"--grid", "3x3"}), "--cross-validate takes no --grid"},
      {with({"--real-time"}), "--cross-validate takes no --real-time"},
      {with({"--sim-seed", "5"}), "--cross-validate takes no --sim-seed"},
      {with({"--unit", "mm"}), "--cross-validate takes no --unit"},
  };
  fs::create_directories(scratch.path / "tracedir");
  const std::string missing = scratch("nodir") + "/t.csv";
  cases.push_back({with({"--traces", missing}),
                   "--traces '" + missing + "': the directory '" + scratch("nodir") + "' does not exist"});
  cases.push_back({with({"--traces", scratch("tracedir")}), "--traces '" + scratch("tracedir") + "': is a directory"});
  test::check_usage_errors(cases, scratch);
  // Refused before the cross validation: nothing of the report was printed.
  for (const auto& traces : {missing, scratch("tracedir")}) {
    const auto r = run_iclap(with({"--traces", traces}), scratch);
    CHECK(r.status == 2);
    CHECK(r.out.empty());
  }
  CHECK(fs::is_empty(scratch.path / "tracedir"));
  {  // --traces naming the references (directly or through a link) would
     // replace the dataset with the traces: refused, the dataset unchanged.
    fs::copy_file(kTrain, scratch("refs.csv"));
    fs::create_symlink(scratch("refs.csv"), scratch("refs_link.csv"));
    const std::string before = test::read_text(scratch("refs.csv"));
    for (const auto& traces : {scratch("refs.csv"), scratch("refs_link.csv")}) {
      CAPTURE(traces);
      std::vector<std::string> args = with({"--traces", traces});
      args[2] = scratch("refs.csv");  // the --references value
      const auto r = run_iclap(args, scratch);
      INFO(r.err);
      CHECK(r.status == 2);
      CHECK(r.out.empty());
      CHECK(r.err.find("--traces '" + traces + "' is the --references file '" + scratch("refs.csv") +
                       "', which the traces would replace") != std::string::npos);
    }
    CHECK(test::read_text(scratch("refs.csv")) == before);
  }
}

TEST_CASE("iclap live --cross-validate: the default --fixed counts are those --max-touches allows") {
  Scratch scratch;
  // The rows of the "fixed number of touches" table: their touch counts.
  const auto fixed_rows = [](const std::string& out) {
    std::vector<std::string> counts;
    const auto at = out.find("\nfixed number of touches\n");
    REQUIRE(at != std::string::npos);
    std::istringstream in(out.substr(at + 1));
    std::string line;
    std::getline(in, line);  // title
    std::getline(in, line);  // column heads
    while (std::getline(in, line) && !line.empty()) {
      std::istringstream l(line);
      std::string first;
      l >> first;
      counts.push_back(first);
    }
    return counts;
  };
  for (const auto& max_and_rows : std::vector<std::pair<std::string, std::vector<std::string>>>{{"6", {"5"}},
                                                                                                {"3", {"3"}}}) {
    const std::string& max = max_and_rows.first;
    const std::vector<std::string>& expected = max_and_rows.second;
    CAPTURE(max);
    const auto r = run_iclap({"live", "--references", kTrain, "--cross-validate", "--method", kMethod,
                              "--max-touches", max, "--confidence", "0.5", "--repeats", "1"},
                             scratch);
    INFO(r.out);
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(fixed_rows(r.out) == expected);
  }
  // A count the user gave is still refused.
  const auto r = run_iclap({"live", "--references", kTrain, "--cross-validate", "--method", kMethod, "--max-touches",
                            "6", "--fixed", "5,10"},
                           scratch);
  CHECK(r.status == 2);
  CHECK(r.err.find("--fixed: 10 exceeds --max-touches 6") != std::string::npos);
}

TEST_CASE("iclap live --replay: a bad position names the dataset row; control bytes in names are quoted") {
  Scratch scratch;
  iclap::Dataset d = iclap::read_dataset_csv(kTrain);
  const auto contact = std::find_if(d.frames.begin(), d.frames.end(), [](const iclap::Frame& fr) {
    return iclap::is_contact(fr);
  });
  REQUIRE(contact != d.frames.end());
  contact->position.x() = 1e300;
  const std::string row = "object '" + contact->object + "' exploration " + std::to_string(contact->exploration) +
                          " frame " + std::to_string(contact->frame) + ": ";
  iclap::write_dataset_csv(scratch("far.csv"), d);
  const test::UsageCases cases = {
      {{"live", "--references", kTrain, "--method", "0.5*icp+0.5*bow", "--replay", scratch("far.csv")},
       "replay of " + scratch("far.csv") + ": " + row + "position coordinate 1e+300 m is beyond"},
      {{"live", "--references", kTrain, "--method", kMethod, "--replay", kClamp, "--object", "a\x01" "b"},
       "has no frame of object 'a\\x01b'"},
      {{"live", "--references", kTrain, "--method", kMethod, "--simulate", "tea\x1b[2Jpot\r"},
       "--simulate: 'tea\\x1b[2Jpot\\x0d' is neither a built-in object"},
  };
  for (const auto& usage_case : cases) {
    const std::string& needle = usage_case.second;
    CAPTURE(needle);
    const auto r = run_iclap(usage_case.first, scratch);
    INFO(r.err);
    CHECK(r.status == 2);
    CHECK(r.err.find(needle) != std::string::npos);
    CHECK(std::none_of(r.err.begin(), r.err.end(), [](char ch) {
      return ch != '\n' && iclap::is_control_byte(static_cast<unsigned char>(ch));
    }));
  }
}

TEST_CASE("SimFrameSource: the frames of simulate_exploration, optionally paced in real time") {
  const iclap::SimObject object = iclap::builtin_object("scissors");
  iclap::SimulationSettings settings;
  settings.exploration.max_frames_mean = 12;
  const auto expected = iclap::simulate_exploration(object, settings, 3, 4);
  SimFrameSource source(object, settings, 3, 4);
  CHECK(source.grid() == Grid{14, 6});
  CHECK(source.has_time());
  CHECK(source.has_orientation());
  CHECK(source.description() == "simulated exploration 4 of scissors (seed 3)");
  CHECK_THROWS_AS(source.last_frame(), iclap::InvalidArgument);
  PosedFrame pf;
  for (const auto& e : expected) {
    REQUIRE(source.next(pf, 0ms) == FrameSource::Status::kFrame);
    CHECK(pf.pressures == e.pressures);
    CHECK(pf.pose.position == e.position);
    REQUIRE(pf.pose.orientation);
    CHECK(pf.pose.orientation->coeffs() == e.orientation->coeffs());
    CHECK(pf.time == e.time);
    CHECK(source.last_frame().frame == e.frame);
    CHECK(source.last_frame().object == "scissors");
  }
  CHECK(source.next(pf, 0ms) == FrameSource::Status::kEnd);
  CHECK(source.next(pf, 0ms) == FrameSource::Status::kEnd);

  // Real time: frame k is due k / 5 s after the first; a short wait times out.
  SimFrameSource paced(object, settings, 3, 4, SimFrameSource::Settings{true});
  REQUIRE(paced.next(pf, 0ms) == FrameSource::Status::kFrame);  // the first is due at once
  const auto start = std::chrono::steady_clock::now();
  CHECK(paced.next(pf, 20ms) == FrameSource::Status::kTimeout);
  REQUIRE(paced.next(pf, 1000ms) == FrameSource::Status::kFrame);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK(waited >= (*expected[1].time - *expected[0].time) * 0.9);
  CHECK(pf.time == expected[1].time);

  CHECK_THROWS_AS(SimFrameSource(object, settings, 3, -1), iclap::InvalidArgument);
  settings.explorations = 0;
  CHECK_THROWS_AS(SimFrameSource(object, settings, 3, 0), iclap::InvalidArgument);
}

TEST_CASE("SimFrameSource: exploration 0 is valid; real time runs from the first next(), a short timeout never waits longer") {
  const iclap::SimObject object = iclap::builtin_object("scissors");
  iclap::SimulationSettings settings;
  settings.exploration.max_frames_mean = 12;
  const auto first = iclap::simulate_exploration(object, settings, 3, 0);
  REQUIRE_FALSE(first.empty());
  SimFrameSource zero(object, settings, 3, 0);
  PosedFrame pf;
  REQUIRE(zero.next(pf, 0ms) == FrameSource::Status::kFrame);
  CHECK(pf.pressures == first[0].pressures);

  // Frames 1..3 are due (t_k - t_0) after the first next(), not after each
  // call: reading them back to back takes t_3 - t_0 (0.6 s), not the sum.
  const auto expected = iclap::simulate_exploration(object, settings, 3, 4);
  REQUIRE(expected.size() >= 4);
  const double span = *expected[3].time - *expected[0].time;
  SimFrameSource paced(object, settings, 3, 4, SimFrameSource::Settings{true});
  REQUIRE(paced.next(pf, 0ms) == FrameSource::Status::kFrame);  // simulates, then starts the clock
  const auto start = std::chrono::steady_clock::now();
  for (int k = 1; k <= 3; ++k) REQUIRE(paced.next(pf, 1000ms) == FrameSource::Status::kFrame);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK(took >= span * 0.8);
  CHECK(took < span + 0.3);
  CHECK(pf.time == expected[3].time);

  // Frame 1 is due 0.2 s after the first: a 150 ms timeout returns kTimeout
  // instead of waiting for it.
  SimFrameSource short_wait(object, settings, 3, 4, SimFrameSource::Settings{true});
  REQUIRE(short_wait.next(pf, 0ms) == FrameSource::Status::kFrame);
  CHECK(short_wait.next(pf, 150ms) == FrameSource::Status::kTimeout);
}

// --- Reproducer of a defect found by helper-40's audit (session 49), fixed in the same
// session. "Happens" is what the library did before the fix.

TEST_CASE("SimFrameSource: real time with the longest timeout returns the next frame when it is due") {
  // FrameSource::next documents "next() waits at most `timeout`"; with
  // std::chrono::milliseconds::max() ("as long as it takes") the second
  // frame of a real-time source is due 0.2 s after the first. Expected:
  // kFrame after about 0.2 s. Happens: `due - now > timeout` converts the
  // timeout to steady_clock's nanoseconds, which overflows (negative), so
  // the source sleeps for the whole timeout: next() never returns. The call
  // runs on a detached thread here so that the test fails after 5 s instead
  // of hanging; the source is leaked on purpose in that case.
  const iclap::SimObject object = iclap::builtin_object("scissors");
  iclap::SimulationSettings settings;
  settings.exploration.max_frames_mean = 12;
  auto source = std::make_shared<SimFrameSource>(object, settings, 3, 4, SimFrameSource::Settings{true});
  PosedFrame pf;
  REQUIRE(source->next(pf, 0ms) == FrameSource::Status::kFrame);  // the first is due at once
  auto done = std::make_shared<std::atomic<int>>(-1);
  std::thread([source, done] {
    PosedFrame second;
    done->store(static_cast<int>(source->next(second, std::chrono::milliseconds::max())));
  }).detach();
  const auto give_up = std::chrono::steady_clock::now() + 5s;
  while (done->load() < 0 && std::chrono::steady_clock::now() < give_up) std::this_thread::sleep_for(10ms);
  CHECK(done->load() == static_cast<int>(FrameSource::Status::kFrame));
}

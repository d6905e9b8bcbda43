// SPDX-License-Identifier: MIT
// Reproducers from helper-55d's audit (session 55) of the WTS protocol code
// against shared/spec/wts-protocol.md. Each case failed on the code it was
// written against and was fixed in the same session; its comment says what
// happened before ("Now").

#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <utility>
#include <variant>
#include <vector>

#include "iclap/rig/packet_framer.hpp"
#include "iclap/rig/stream_parser.hpp"
#include "iclap/rig/wts_message.hpp"
#include "iclap/rig/wts_protocol.hpp"
#include "iclap/rig/wts_sensor.hpp"
#include "rig_test_util.hpp"

using namespace iclap::rig;
using namespace std::chrono_literals;

namespace {

// A sensor, in memory, that answers every command `latency` after it was
// written (loop: status 0 and the same bytes; any other command: status 0),
// and starts/stops "streaming" on the periodic-frame commands. Bytes
// become readable only when due, so late replies are late, as on a wire.
class SlowSensorStream final : public ByteStream {
 public:
  explicit SlowSensorStream(std::chrono::milliseconds latency) : latency_(latency) {}
  std::size_t read(std::uint8_t* buffer, std::size_t capacity, std::chrono::milliseconds timeout) override {
    const auto deadline = std::chrono::steady_clock::now() + std::min(timeout, std::chrono::milliseconds(5000));
    for (;;) {
      const auto now = std::chrono::steady_clock::now();
      while (!scheduled_.empty() && scheduled_.front().first <= now) {
        out_.insert(out_.end(), scheduled_.front().second.begin(), scheduled_.front().second.end());
        scheduled_.erase(scheduled_.begin());
      }
      if (!out_.empty() || now >= deadline) break;
      std::this_thread::sleep_for(1ms);
    }
    const std::size_t n = std::min(capacity, out_.size());
    std::copy_n(out_.begin(), n, buffer);
    out_.erase(out_.begin(), out_.begin() + static_cast<std::ptrdiff_t>(n));
    return n;
  }
  void write(const std::uint8_t* data, std::size_t size, std::chrono::milliseconds) override {
    PacketFramer framer;
    framer.feed(data, size);
    framer.finish();
    while (auto p = framer.next()) {
      commands.push_back(p->id);
      if (p->id == wts_id::kStartPeriodicFrames) streaming = true;
      if (p->id == wts_id::kStopPeriodicFrames) streaming = false;
      const Reply r{p->id, 0, p->id == wts_id::kLoop ? p->payload : Bytes{}};
      scheduled_.emplace_back(std::chrono::steady_clock::now() + latency_, encode_reply(r));
    }
  }
  void close() noexcept override {}
  bool is_open() const noexcept override { return true; }
  const std::string& name() const noexcept override { return name_; }

  std::vector<std::uint8_t> commands;  // ids received, in order
  bool streaming = false;

 private:
  std::chrono::milliseconds latency_;
  std::vector<std::pair<std::chrono::steady_clock::time_point, Bytes>> scheduled_;
  Bytes out_;
  std::string name_ = "slow sensor";
};

// Settings under which every reply of a SlowSensorStream of 300 ms is late.
WtsSensor::Settings impatient() {
  WtsSensor::Settings st;
  st.reply_timeout = 50ms;
  st.attempts = 1;
  return st;
}

}  // namespace

// Input: attempts = 1, reply_timeout 50 ms, a sensor that answers after
// 300 ms. start_periodic_frames(5) sends "start periodic frames" (the sensor
// receives it and starts streaming), the reply is late, WtsTimeout is
// thrown, then the WtsSensor is destroyed.
// Now: the destructor sent nothing (the last command the sensor received
// was 0x21 start): the sensor was left streaming after the exception, which
// the class comment promises not to do.
// Cause: wts_sensor.hpp, start_periodic_frames set streaming_ only after
// request_ok() returned, and the destructor stops only when streaming_.
TEST_CASE("WtsSensor audit: a start_periodic_frames that timed out is stopped by the destructor") {
  SlowSensorStream s(300ms);
  {
    WtsSensor sensor(s, impatient());
    CHECK_THROWS_AS(sensor.start_periodic_frames(5.0), WtsTimeout);
    CHECK(sensor.streaming());
  }
  REQUIRE_FALSE(s.commands.empty());
  CHECK(s.commands.back() == wts_id::kStopPeriodicFrames);
  CHECK_FALSE(s.streaming);
}

// Input: as above, then stop_periodic_frames(), whose reply is late too.
// Now: stop_periodic_frames() cleared streaming_ before sending, so after
// its timeout the destructor did not send the stop again.
TEST_CASE("WtsSensor audit: a stop that timed out is sent again by the destructor") {
  SlowSensorStream s(300ms);
  {
    WtsSensor sensor(s, impatient());
    CHECK_THROWS_AS(sensor.start_periodic_frames(5.0), WtsTimeout);
    CHECK_FALSE(sensor.stop_periodic_frames());
    CHECK(sensor.streaming());
  }
  CHECK(std::count(s.commands.begin(), s.commands.end(), wts_id::kStopPeriodicFrames) == 2);
  CHECK(s.commands.back() == wts_id::kStopPeriodicFrames);
}

// A stop the sensor acknowledges ends streaming: the destructor sends
// nothing more.
TEST_CASE("WtsSensor audit: an acknowledged stop is not sent again") {
  SlowSensorStream s(10ms);
  {
    WtsSensor sensor(s);
    sensor.start_periodic_frames(5.0);
    CHECK(sensor.streaming());
    CHECK(sensor.stop_periodic_frames());
    CHECK_FALSE(sensor.streaming());
  }
  CHECK(s.commands == std::vector<std::uint8_t>{wts_id::kStartPeriodicFrames, wts_id::kStopPeriodicFrames});
}

// A start the sensor refuses changes nothing: not streaming before, not
// after; streaming before (a start acknowledged earlier), still streaming.
TEST_CASE("WtsSensor audit: a refused start leaves the streaming state as it was") {
  test::MemoryStream s("scripted");
  WtsSensor sensor(s);
  s.push(encode_reply(Reply{wts_id::kStartPeriodicFrames, 3, {}}));
  CHECK_THROWS_AS(sensor.start_periodic_frames(5.0), WtsCommandError);
  CHECK_FALSE(sensor.streaming());
  s.push(encode_reply(Reply{wts_id::kStartPeriodicFrames, 0, {}}));
  sensor.start_periodic_frames(5.0);
  s.push(encode_reply(Reply{wts_id::kStartPeriodicFrames, 3, {}}));
  CHECK_THROWS_AS(sensor.start_periodic_frames(10.0), WtsCommandError);
  CHECK(sensor.streaming());
}

// SPDX-License-Identifier: MIT
// SerialPort's own promises, checked on a pseudo-terminal without a fake
// sensor (the port settings it applies, lock, flush, zero-capacity reads,
// write timeout, descriptors), and list_serial_ports on scratch device trees
// (names it must refuse, by-id links, a device root reached through a
// symlink). Written from a mutation-testing pass over these headers.

#include <doctest/doctest.h>

#include <fcntl.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "iclap/rig/serial_enumeration.hpp"
#include "iclap/rig/serial_port.hpp"
#include "pty_port.hpp"
#include "../support/temporaries.hpp"

using namespace iclap::rig;
using namespace std::chrono_literals;
using test::PtyPort;
namespace fs = std::filesystem;

namespace {

// Open descriptors of this process (a leak check).
std::size_t open_descriptors() {
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator("/proc/self/fd")) {
    (void)e;
    ++n;
  }
  return n;
}

const std::vector<std::uint8_t> kCrLf{'a', '\r', '\n', 0x03, 0x11};

}  // namespace

TEST_CASE("SerialPort: raw 8N1, no flow control, VMIN 1 and the baud rate, whatever the port was set to") {
  PtyPort pty;
  // Leave the port as a login terminal would: canonical, echo, CR->NL,
  // 7 data bits with parity and 2 stop bits, XON/XOFF, 2400 baud.
  {
    const int fd = ::open(pty.path().c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
    REQUIRE(fd >= 0);
    termios cooked{};
    REQUIRE(::tcgetattr(fd, &cooked) == 0);
    cooked.c_lflag |= static_cast<tcflag_t>(ICANON | ECHO | ISIG | IEXTEN);
    cooked.c_iflag |= static_cast<tcflag_t>(ICRNL | IXON | IXOFF | IXANY);
    cooked.c_oflag |= static_cast<tcflag_t>(OPOST | ONLCR);
    cooked.c_cflag &= ~static_cast<tcflag_t>(CSIZE);
    cooked.c_cflag |= static_cast<tcflag_t>(CS7 | PARENB | CSTOPB);
    REQUIRE(::cfsetispeed(&cooked, B2400) == 0);
    REQUIRE(::cfsetospeed(&cooked, B2400) == 0);
    REQUIRE(::tcsetattr(fd, TCSANOW, &cooked) == 0);
    ::close(fd);
  }
  const auto check_port = [&](const SerialPort& port, speed_t speed) {
    termios tio{};
    REQUIRE(::tcgetattr(port.native_handle(), &tio) == 0);
    CHECK((tio.c_lflag & (ICANON | ECHO | ISIG | IEXTEN)) == 0);
    CHECK((tio.c_iflag & (ICRNL | IXON | IXOFF | IXANY)) == 0);
    CHECK((tio.c_oflag & OPOST) == 0);
    CHECK((tio.c_cflag & CSIZE) == CS8);
    CHECK((tio.c_cflag & (PARENB | CSTOPB)) == 0);
    CHECK((tio.c_cflag & (CLOCAL | CREAD)) == (CLOCAL | CREAD));
    CHECK(tio.c_cc[VMIN] == 1);  // with O_NONBLOCK: read() of 0 bytes means a hang-up
    CHECK(tio.c_cc[VTIME] == 0);
    CHECK(::cfgetispeed(&tio) == speed);
    CHECK(::cfgetospeed(&tio) == speed);
    // Non-blocking (the read/write timeouts are poll()s), closed on exec.
    CHECK((::fcntl(port.native_handle(), F_GETFL) & O_NONBLOCK) != 0);
    CHECK((::fcntl(port.native_handle(), F_GETFD) & FD_CLOEXEC) != 0);
  };
  {
    SerialPort port(pty.path());
    check_port(port, B115200);
    // Bytes arrive as sent: no CR translation, no signal or flow-control bytes eaten.
    pty.queue(kCrLf);
    pty.flush(1000ms);
    std::vector<std::uint8_t> got;
    std::uint8_t buf[16];
    for (int i = 0; i < 20 && got.size() < kCrLf.size(); ++i) {
      const std::size_t n = port.read(buf, sizeof buf, 100ms);
      got.insert(got.end(), buf, buf + n);
    }
    CHECK(got == kCrLf);
  }
  SerialPort slow(pty.path(), SerialPort::Settings{9600, true});
  check_port(slow, B9600);
}

TEST_CASE("SerialPort: exclusive = false shares a port another owner has locked") {
  PtyPort pty;
  SerialPort owner(pty.path());
  CHECK_THROWS_AS(SerialPort(pty.path()), TransportError);
  SerialPort shared(pty.path(), SerialPort::Settings{115200, false});
  CHECK(shared.is_open());
}

TEST_CASE("SerialPort: input waiting from before the open is discarded") {
  PtyPort pty;
  pty.queue(std::vector<std::uint8_t>{'s', 't', 'a', 'l', 'e'});
  pty.flush(1000ms);
  REQUIRE(pty.wait_unread_by_host(5, 1000ms));
  SerialPort port(pty.path());
  std::uint8_t buf[16];
  CHECK(port.read(buf, sizeof buf, 100ms) == 0);
  // What comes after the open is kept.
  pty.queue(std::uint8_t{'n'});
  pty.flush(1000ms);
  std::size_t n = 0;
  for (int i = 0; i < 20 && n == 0; ++i) n = port.read(buf, sizeof buf, 100ms);
  REQUIRE(n == 1);
  CHECK(buf[0] == 'n');
}

TEST_CASE("SerialPort: a zero-capacity read returns 0 even with input waiting, and consumes nothing") {
  PtyPort pty;
  SerialPort port(pty.path());
  pty.queue(std::vector<std::uint8_t>{1, 2, 3});
  pty.flush(1000ms);
  REQUIRE(pty.wait_unread_by_host(3, 1000ms));
  std::uint8_t buf[8] = {};
  CHECK(port.read(buf, 0, 100ms) == 0);
  CHECK(port.read(buf, sizeof buf, 100ms) == 3);
  CHECK(buf[0] == 1);
  CHECK(buf[2] == 3);
}

TEST_CASE("SerialPort: a write nobody drains times out after about its timeout, naming the port") {
  PtyPort pty;  // the master never reads: the pty's buffers fill up
  SerialPort port(pty.path());
  const std::vector<std::uint8_t> big(1 << 20, 0x55);
  const auto start = std::chrono::steady_clock::now();
  try {
    port.write(big.data(), big.size(), 100ms);
    FAIL("1 MiB went into an undrained pty");
  } catch (const DeviceLost&) {
    FAIL("a full buffer is not an unplug");
  } catch (const TransportError& e) {
    CHECK(e.path() == pty.path());
    CHECK(std::string(e.what()).find("timed out after 100 ms") != std::string::npos);
  }
  const auto waited = std::chrono::steady_clock::now() - start;
  CHECK(waited >= 90ms);
  CHECK(waited < 1000ms);
}

TEST_CASE("SerialPort: failed opens leave no descriptor behind; a moved-from port is closed") {
  PtyPort pty;
  const iclap::test::TempDir dir("serial_fds");
  const std::string file = dir.file("not_a_tty");
  std::ofstream(file) << "x";
  SerialPort owner(pty.path());
  const std::size_t before = open_descriptors();
  for (int i = 0; i < 4; ++i) {
    CHECK_THROWS_AS(SerialPort{file}, TransportError);        // not a terminal
    CHECK_THROWS_AS(SerialPort(pty.path()), TransportError);  // locked by `owner`
  }
  CHECK(open_descriptors() == before);

  const int fd = owner.native_handle();
  SerialPort moved(std::move(owner));
  CHECK_FALSE(owner.is_open());  // NOLINT(bugprone-use-after-move): the moved-from state is the point
  CHECK(owner.native_handle() == -1);
  CHECK(moved.native_handle() == fd);
  owner.close();  // must not close `moved`'s descriptor
  CHECK(::fcntl(fd, F_GETFD) != -1);
  SerialPort assigned(pty.path(), SerialPort::Settings{115200, false});
  assigned = std::move(moved);
  CHECK(assigned.native_handle() == fd);
  CHECK_FALSE(moved.is_open());  // NOLINT(bugprone-use-after-move)
  CHECK(open_descriptors() == before);  // the shared port `assigned` had is closed
}

TEST_CASE("SerialPort: the port never becomes the controlling terminal (no SIGHUP on unplug)") {
  PtyPort pty;
  // A session leader without a terminal acquires the first one it opens
  // unless O_NOCTTY is given; a daemonised recorder would then get SIGHUP
  // when the sensor is unplugged. Checked in a child that starts a session.
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    if (::setsid() < 0) ::_exit(10);
    try {
      SerialPort port(pty.path());
      const int tty = ::open("/dev/tty", O_RDWR | O_CLOEXEC);
      ::_exit(tty < 0 ? 0 : 1);
    } catch (...) {
      ::_exit(11);
    }
  }
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
}

TEST_CASE("list_serial_ports: only ttyACM<digits> and ttyUSB<digits> files, plus by-id targets") {
  const iclap::test::TempDir scratch("serial_list");
  const fs::path root = scratch.path / "dev";
  fs::create_directories(root / "serial" / "by-id");
  for (const char* name : {"ttyACM", "ttyACM1x", "ttyUSB", "ttyUSB0", "ttyACM3", "xttyACM4"})
    std::ofstream(root / name) << "";
  fs::create_directories(root / "ttyACM5");  // a directory is no port
  std::ofstream(root / "serial" / "by-id" / "not-a-link") << "";  // only links count
  fs::create_symlink("../../ttyUSB0", root / "serial" / "by-id" / "usb-bridge-if00");
  const auto ports = list_serial_ports(root.string());
  std::vector<std::string> paths;
  for (const auto& p : ports) paths.push_back(p.path);
  CHECK(paths == std::vector<std::string>{(root / "ttyACM3").string(), (root / "ttyUSB0").string()});
  REQUIRE(ports.size() == 2);
  CHECK(ports[0].by_id.empty());
  CHECK(ports[1].by_id == std::vector<std::string>{(root / "serial" / "by-id" / "usb-bridge-if00").string()});
  CHECK(ports[1].accessible);
}

TEST_CASE("list_serial_ports: by-id names sorted; a device root through a symlink is not listed twice") {
  const iclap::test::TempDir scratch("serial_link");
  const fs::path real = scratch.path / "real";
  fs::create_directories(real / "serial" / "by-id");
  std::ofstream(real / "ttyACM2") << "";
  std::ofstream(real / "ttyS5") << "";  // not a candidate name, but a by-id target
  std::vector<std::string> names = {"usb-e-if00", "usb-d-if00", "usb-c-if00", "usb-b-if00", "usb-a-if00"};
  for (const auto& n : names) fs::create_symlink("../../ttyACM2", real / "serial" / "by-id" / n);
  fs::create_symlink("../../ttyS5", real / "serial" / "by-id" / "usb-console-if00");
  const fs::path root = scratch.path / "dev";  // the root the caller names is a link to `real`
  fs::create_directory_symlink(real, root);

  const auto ports = list_serial_ports(root.string());
  REQUIRE(ports.size() == 2);
  // Paths under the root as given, even though the links resolve under `real`.
  CHECK(ports[0].path == (root / "ttyACM2").string());
  CHECK(ports[1].path == (root / "ttyS5").string());
  std::sort(names.begin(), names.end());
  std::vector<std::string> expected;
  for (const auto& n : names) expected.push_back((root / "serial" / "by-id" / n).string());
  CHECK(ports[0].by_id == expected);
  CHECK(ports[1].by_id == std::vector<std::string>{(root / "serial" / "by-id" / "usb-console-if00").string()});
}

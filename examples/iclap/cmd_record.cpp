// SPDX-License-Identifier: MIT
//
// `iclap record`: records a haptic exploration from the WTS sensor on a
// serial port into a dataset CSV, one flushed row per frame, each paired
// with the pad pose from a pose source.

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/utf8.hpp"
#include "iclap/core/version.hpp"
#include "iclap/data/csv_appender.hpp"
#include "iclap/data/csv_reader.hpp"
#include "iclap/rig/pose_spec.hpp"
#include "iclap/rig/sensor_frame_source.hpp"
#include "iclap/rig/serial_port.hpp"
#include "iclap/rig/wts_sensor.hpp"
#include "stop_signals.hpp"

namespace {

using namespace iclap::cli;
namespace rig = iclap::rig;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Is `path` a regular file holding nothing, or only a UTF-8 byte-order mark
// (an editor's new file)? Then `size` is its size (0 or 3).
bool blank_file(const std::string& path, std::uintmax_t& size) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  size = fs::file_size(path, ec);
  if (ec || (size != 0 && size != 3)) return false;
  if (size == 0) return true;
  char head[3] = {};
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  const bool bom = std::fread(head, 1, 3, f) == 3 && std::string_view(head, 3) == iclap::kUtf8Bom;
  std::fclose(f);
  return bom;
}

const std::string kUsage = std::string(
    "usage: iclap record --port PATH --object NAME --exploration K --out FILE.csv\n"
    "                    [--frames N | --seconds S] [--pose SPEC] [--rate R] [--grid ROWSxCOLS]\n"
    "\n"
    "Records tactile frames from a Weiss WTS sensor on serial port PATH (e.g.\n"
    "/dev/ttyACM0; see `iclap devices`) into the dataset CSV FILE, one row per\n"
    "frame with the pad pose at that moment. Each row is flushed as it is\n"
    "written, so a crash or an unplug loses at most the frame in flight and\n"
    "never leaves a partial row. An existing FILE is appended to (same grid and\n"
    "columns required); frame numbers of an exploration continue where the\n"
    "file left them. A new FILE is created at the first frame: a run that\n"
    "records no frame (a silent sensor, an error before the first frame)\n"
    "leaves no file behind. Stops after N frames or S seconds, when a pose\n"
    "replay ends, or on Ctrl-C; the sensor's stream is stopped in every case.\n"
    "\n"
    "  --port PATH         the sensor's serial port\n"
    "  --object NAME       object name (class label): no commas or quotes\n"
    "  --exploration K     exploration id (integer >= 0)\n"
    "  --out FILE.csv      dataset to create or append to\n"
    "  --frames N          stop after N frames\n"
    "  --seconds S         stop after S seconds of streaming\n"
    "  --rate R            frames per second requested from the sensor (default 5;\n"
    "                      the sensor's delay is 1000/R ms)\n"
    "  --grid ROWSxCOLS    taxel grid, overriding the sensor's matrix info (which\n"
    "                      is read as rows = res_y, columns = res_x)\n"
    "  --pose SPEC         pad pose source (default fixed:0,0,0):\n") +
    iclap::rig::pose_spec_help("                        ") +
    "\n\n"
    "Exit status: 0 done, 1 failure (no frame recorded, write failed), 2 bad input,\n"
    "3 the device was lost (the rows recorded so far are intact), 130 Ctrl-C\n"
    "(the rows recorded so far are intact).";


// One status line on a terminal, refreshed at most 10 times a second.
class StatusLine {
 public:
  StatusLine() : tty_(isatty(2) != 0) {}
  ~StatusLine() { finish(); }
  StatusLine(const StatusLine&) = delete;
  StatusLine& operator=(const StatusLine&) = delete;
  void show(const std::string& text, bool force = false) {
    if (!tty_) return;
    const auto now = Clock::now();
    if (!force && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    std::fprintf(stderr, "\r%s\033[K", text.c_str());
    std::fflush(stderr);
    shown_ = true;
  }
  void finish() {
    if (shown_) std::fprintf(stderr, "\n");
    shown_ = false;
  }

 private:
  bool tty_;
  bool shown_ = false;
  Clock::time_point last_{};
};

std::string drop_summary(const rig::WtsSensor& sensor) {
  const auto s = sensor.stats();
  std::string out = "dropped: " + std::to_string(s.crc_errors) + " bad CRC, " + std::to_string(s.junk_bytes) +
                    " junk bytes, " + std::to_string(s.truncated) + " truncated";
  if (s.frames_wrong_shape) out += ", " + std::to_string(s.frames_wrong_shape) + " of the wrong shape";
  if (s.frames_out_of_range) out += ", " + std::to_string(s.frames_out_of_range) + " with taxels above 4095";
  if (s.oversize) out += ", " + std::to_string(s.oversize) + " oversize headers";
  if (sensor.frames_overflowed()) out += ", " + std::to_string(sensor.frames_overflowed()) + " overflowed";
  return out;
}

// Throws IoError naming `path` unless a new file can be created there (a
// missing directory, no permission): checked before the sensor streams,
// although the file itself is only created at the first frame.
void check_creatable(const std::string& path) {
  // O_EXCL fails on any symbolic link ("File exists"); a dangling one is
  // refused by name rather than followed (removing the file of a run
  // without a row would then remove the link and leave its target).
  std::error_code ec;
  if (fs::is_symlink(path, ec)) {
    const fs::path target = fs::read_symlink(path, ec);
    const std::string to = ec ? std::string() : " to " + iclap::quote_text(target.string());
    throw iclap::IoError(path, "is a dangling symlink" + to +
                                   " (no file there): give --out the path of the file to create, not the link");
  }
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throw iclap::IoError(path, std::string("cannot create: ") + std::strerror(errno));
  ::close(fd);
  ::unlink(path.c_str());
}

// The next free frame number of (object, exploration) in an existing file.
// Throws InvalidArgument if the file has the largest frame number already.
std::int64_t next_frame_index(const std::string& path, const std::string& object, std::int64_t exploration) {
  const iclap::Dataset d = iclap::read_dataset_csv(path);
  std::int64_t next = 0;
  for (const auto& f : d.frames) {
    if (f.object != object || f.exploration != exploration) continue;
    if (f.frame == std::numeric_limits<std::int64_t>::max())
      throw iclap::InvalidArgument(path, object + " exploration " + std::to_string(exploration) + " has frame " +
                                             std::to_string(f.frame) + ", after which no frame number is left");
    next = std::max(next, f.frame + 1);
  }
  return next;
}

int run_record(const Args& args) {
  const Options o(args, {"port", "object", "exploration", "frames", "seconds", "pose", "rate", "grid", "out"});
  o.expect_positional(0, 0, "no positional arguments");
  for (const char* required : {"port", "object", "exploration", "out"})
    if (!o.has(required)) throw UsageError(std::string("missing --") + required);
  const std::string port_path = o.string("port");
  const std::string object = o.string("object");
  const std::string out_path = o.string("out");
  const std::string problem = iclap::detail::object_name_problem(object);
  if (!problem.empty()) throw UsageError("--object: " + iclap::quote_text(object, 60) + " " + problem);
  const std::int64_t exploration = o.integer("exploration", 0, 0);
  if (o.has("frames") && o.has("seconds")) throw UsageError("--frames and --seconds exclude each other");
  // 0: no limit (plain values, not optionals: GCC 12 misreports those).
  const long long max_frames = o.integer("frames", 0, 1);
  const double max_seconds = o.number("seconds", 0, 1e-3, 1e7);
  const double rate = o.number("rate", 5.0);
  rig::delay_ms_for_rate(rate);  // validate before touching the device
  std::optional<rig::Grid> grid_override;
  if (o.has("grid")) grid_override = rig::parse_grid(o.string("grid"), "--grid");
  const std::string pose_spec = o.string("pose", "fixed:0,0,0");
  if (!o.has("pose"))
    std::fprintf(stderr, "iclap record: no --pose given: every frame is recorded at position 0,0,0\n");
  const auto poses = rig::make_pose_source(pose_spec, "--pose");

  // The sensor: stop a stream left over from an earlier run, learn the grid.
  rig::SerialPort port(port_path);
  rig::WtsSensor::Settings settings;
  settings.parser.grid = grid_override;
  rig::WtsSensor sensor(port, settings);
  const StopSignals signals;
  std::optional<rig::MatrixInfo> info;
  try {
    sensor.stop_periodic_frames();
    try {
      info = sensor.query_matrix_info();
    } catch (const rig::WtsTimeout& e) {
      if (!grid_override)
        throw rig::WtsTimeout(std::string(e.what()) +
                              "; is this the WTS sensor? (--grid ROWSxCOLS records without matrix info)");
      std::fprintf(stderr, "iclap record: warning: %s; using --grid %s\n", e.what(),
                   rig::to_string(*grid_override).c_str());
    }
  } catch (const rig::DeviceLost& e) {
    std::fprintf(stderr, "iclap record: %s (before recording started)\n", e.what());
    return kExitDeviceLost;
  }
  if (info && grid_override) {
    const rig::Grid reported = info->grid();
    if (reported.size() != grid_override->size())
      throw UsageError("--grid " + rig::to_string(*grid_override) + " has " + std::to_string(grid_override->size()) +
                       " taxels but the sensor reports res_x=" + std::to_string(info->res_x) +
                       ", res_y=" + std::to_string(info->res_y) + " (" + std::to_string(reported.size()) + ")");
    if (reported != *grid_override)
      std::fprintf(stderr, "iclap record: --grid %s overrides the sensor's %s (res_x=%u, res_y=%u)\n",
                   rig::to_string(*grid_override).c_str(), rig::to_string(reported).c_str(), info->res_x,
                   info->res_y);
  }
  const rig::Grid grid = *sensor.grid();
  if (StopSignals::requested()) {
    std::fprintf(stderr, "iclap record: interrupted before recording started\n");
    return StopSignals::exit_status();
  }

  // The dataset: check and repair an existing one now, before the sensor
  // streams; a new one is created at the first frame (so that a run that
  // records nothing leaves no file), after checking now that it can be.
  std::vector<std::string> comments;
  {
    char pitch[64] = "";
    if (info && info->cell_width > 0)
      std::snprintf(pitch, sizeof pitch, " pitch_m=%.6g", info->cell_width_m());
    comments.push_back("sensor: WTS rows=" + std::to_string(grid.rows) + " cols=" + std::to_string(grid.cols) + pitch);
    if (info)
      comments.push_back("matrix info: res_x=" + std::to_string(info->res_x) + " res_y=" + std::to_string(info->res_y) +
                         " cell_w=" + std::to_string(info->cell_width) + " cell_h=" + std::to_string(info->cell_height) +
                         " full_scale=" + std::to_string(info->full_scale) +
                         (grid_override ? " (grid set by --grid)" : " (rows = res_y, cols = res_x)"));
    char rate_text[32];
    std::snprintf(rate_text, sizeof rate_text, "%g", rate);
    comments.push_back(std::string("recorded by: iclap " ICLAP_VERSION_STRING " record, ") + rate_text +
                       " frames/s; t is the sensor clock in seconds");
    comments.push_back("poses: " + poses->description());
  }
  std::error_code ec;
  const bool existed = fs::exists(out_path, ec);
  // An existing empty file, or one holding only a byte-order mark, is
  // treated as new (it gets the header at the first frame, after the BOM,
  // and is left as it was if no frame comes).
  std::uintmax_t blank_size = 0;
  const bool appending = existed && !blank_file(out_path, blank_size);
  std::optional<iclap::DatasetCsvAppender> appender;
  const auto open_appender = [&] {
    appender.emplace(out_path, grid.rows, grid.cols, /*time=*/true, poses->has_orientation(), comments);
  };
  std::int64_t first_frame = 0;
  std::size_t cut_bytes = 0;  // a partial last row cut off when opening an existing file
  if (appending) {
    open_appender();
    cut_bytes = appender->recovered_bytes();
    if (appender->header_completed())
      std::fprintf(stderr, "iclap record: %s: completed its header, cut short by an earlier run\n", out_path.c_str());
    if (cut_bytes > 0)
      std::fprintf(stderr, "iclap record: %s: cut off a partial last row (%zu bytes) left by an earlier run\n",
                   out_path.c_str(), cut_bytes);
    if (appender->rows_in_file() > 0) {
      first_frame = next_frame_index(out_path, object, exploration);
      std::fprintf(stderr, "iclap record: appending to %s (%zu rows); %s exploration %lld continues at frame %lld\n",
                   out_path.c_str(), appender->rows_in_file(), object.c_str(), static_cast<long long>(exploration),
                   static_cast<long long>(first_frame));
    }
  } else if (!existed) {
    check_creatable(out_path);
  }
  bool opened_here = false;  // the appender was opened at the first frame, on a new or empty file

  // Record.
  rig::SensorFrameSource source(sensor, *poses);
  iclap::Frame row;
  row.object = object;
  row.exploration = exploration;
  long long recorded = 0;
  bool pose_ended = false;
  StatusLine status;
  const auto record_one = [&](const rig::PosedFrame& pf) {
    if (first_frame > std::numeric_limits<std::int64_t>::max() - recorded)
      throw iclap::InvalidArgument(out_path, object + " exploration " + std::to_string(exploration) +
                                                 ": no frame number is left after " +
                                                 std::to_string(first_frame + (recorded - 1)));
    row.frame = first_frame + recorded;
    row.position = pf.pose.position;
    row.orientation = pf.pose.orientation;
    row.time = pf.time;
    row.pressures = pf.pressures;
    if (!appender) {
      opened_here = true;  // before opening: a failed header write may leave an empty file
      open_appender();
    }
    appender->append(row);
    ++recorded;
  };
  // Syncs the file; a file this run created (or an empty or BOM-only one it
  // wrote the header into) that got no row is removed (emptied, back to its
  // BOM), so a failed or silent run leaves no header-only file to block the
  // next one. A file that had content is never removed.
  const auto finish_file = [&] {
    status.finish();
    if (appender) {
      try {
        appender->sync();
      } catch (const iclap::IoError& e) {
        std::fprintf(stderr, "iclap record: warning: %s\n", e.what());
      }
    }
    if (recorded > 0 || !opened_here) return;
    appender.reset();
    std::error_code rm;
    if (existed) fs::resize_file(out_path, blank_size, rm);
    else fs::remove(out_path, rm);
    if (rm)
      std::fprintf(stderr, "iclap record: warning: %s: cannot remove the file this run created without a row: %s\n",
                   out_path.c_str(), rm.message().c_str());
  };
  // What became of the file when no frame was recorded.
  const auto no_frame_note = [&] {
    if (appending && cut_bytes > 0)
      return out_path + " keeps its complete rows; only its partial last row (" + std::to_string(cut_bytes) +
             " bytes) was cut off";
    if (appending && appender && appender->header_completed())
      return out_path + " has no row; only its header, cut short by an earlier run, was completed";
    return out_path + (appending            ? " is unchanged"
                       : blank_size > 0     ? " is left as it was (a byte-order mark only)"
                       : existed            ? " is left empty"
                                            : " was not created");
  };
  const auto summary = [&](const char* how) {
    if (recorded == 0) {
      std::fprintf(stderr, "iclap record: %s: no frame recorded; %s; %s\n", how, no_frame_note().c_str(),
                   drop_summary(sensor).c_str());
      return;
    }
    std::fprintf(stderr, "iclap record: %s: %lld frames recorded to %s (%s exploration %lld, frames %lld..%lld); %s\n",
                 how, recorded, out_path.c_str(), object.c_str(), static_cast<long long>(exploration),
                 static_cast<long long>(first_frame), static_cast<long long>(first_frame + recorded - 1),
                 drop_summary(sensor).c_str());
  };

  const auto start = Clock::now();
  try {
    sensor.start_periodic_frames(rate);
    auto last_frame_at = start;
    bool warned_silent = false;
    std::uint64_t clock_resets = 0;
    rig::PosedFrame pf;
    while (!StopSignals::requested()) {
      if (max_frames > 0 && recorded >= max_frames) break;
      const auto now = Clock::now();
      if (max_seconds > 0 && std::chrono::duration<double>(now - start).count() >= max_seconds) break;
      const auto st = source.next(pf, std::chrono::milliseconds(100));
      if (st == rig::FrameSource::Status::kEnd) {
        pose_ended = true;
        break;
      }
      if (st == rig::FrameSource::Status::kFrame) {
        record_one(pf);
        if (source.clock_resets() != clock_resets) {
          clock_resets = source.clock_resets();
          status.finish();
          std::fprintf(stderr,
                       "iclap record: warning: the sensor clock stepped back before frame %lld (a sensor reset?); "
                       "t continues from the previous frame's time\n",
                       static_cast<long long>(first_frame + recorded - 1));
        }
        last_frame_at = Clock::now();
        const double secs = std::chrono::duration<double>(last_frame_at - start).count();
        std::string line = "recording " + object + " #" + std::to_string(exploration) + ": " +
                           std::to_string(recorded) + (max_frames > 0 ? "/" + std::to_string(max_frames) : "") +
                           " frames";
        if (secs > 0.5) {
          char r[32];
          std::snprintf(r, sizeof r, ", %.1f frames/s", static_cast<double>(recorded) / secs);
          line += r;
        }
        const auto s = sensor.stats();
        const auto dropped = s.crc_errors + s.truncated + s.frames_wrong_shape + s.frames_out_of_range;
        if (dropped) line += ", " + std::to_string(dropped) + " dropped";
        status.show(line);
        continue;
      }
      // Timeout: diagnose silence and hopeless grids.
      const auto s = sensor.stats();
      if (recorded == 0 && s.frames_wrong_shape >= 5)
        throw iclap::Error(port_path + ": the sensor sends frames of " + std::to_string(s.last_wrong_shape_taxels) +
                           " taxels but the grid " + rig::to_string(grid) + " has " + std::to_string(grid.size()) +
                           "; pass --grid ROWSxCOLS");
      if (!warned_silent && Clock::now() - last_frame_at > std::chrono::seconds(3)) {
        status.finish();
        std::fprintf(stderr, "iclap record: warning: no frame from %s for 3 s (still waiting; Ctrl-C stops)\n",
                     port_path.c_str());
        warned_silent = true;
      }
    }
  } catch (const rig::DeviceLost& e) {
    finish_file();
    std::fprintf(stderr, "iclap record: %s\n", e.what());
    summary("device lost");
    return kExitDeviceLost;
  } catch (...) {
    status.finish();
    try {
      sensor.stop_periodic_frames();
    } catch (...) {
    }
    finish_file();
    summary("stopped by an error");
    throw;
  }

  bool stopped = false;
  try {
    stopped = sensor.stop_periodic_frames();
  } catch (const rig::DeviceLost& e) {
    finish_file();
    std::fprintf(stderr, "iclap record: %s (while stopping the stream)\n", e.what());
    summary("device lost");
    return kExitDeviceLost;
  }
  finish_file();
  if (!stopped) std::fprintf(stderr, "iclap record: warning: the sensor did not acknowledge 'stop periodic frames'\n");
  if (StopSignals::requested()) {
    summary("interrupted");
    return StopSignals::exit_status();
  }
  if (recorded == 0) {
    char waited[32];
    std::snprintf(waited, sizeof waited, "%.3g", std::chrono::duration<double>(Clock::now() - start).count());
    std::fprintf(stderr, "iclap record: failed: no frame recorded from %s in %s s%s; %s; %s\n", port_path.c_str(),
                 waited, pose_ended ? " (the pose replay ended)" : " (is the sensor silent?)", no_frame_note().c_str(),
                 drop_summary(sensor).c_str());
    return kExitFailure;
  }
  summary(pose_ended ? "pose replay ended" : "done");
  return kExitOk;
}

}  // namespace

ICLAP_COMMAND("record", "record a dataset from the WTS sensor on a serial port", kUsage, run_record);

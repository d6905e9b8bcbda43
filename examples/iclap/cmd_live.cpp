// SPDX-License-Identifier: MIT
//
// `iclap live`: live recognition. Reads touches from the WTS sensor (with a
// pose source), a replayed dataset or the simulator, updates the ranking of
// the known objects after every touch and stops as soon as the decision is
// confident (the paper's Discussion, "Haptic exploration"). With
// --cross-validate it measures that stop rule against fixed touch counts.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "cli.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/version.hpp"
#include "iclap/data/csv_reader.hpp"
#include "iclap/io/atomic_file.hpp"
#include "iclap/mesh/load.hpp"
#include "iclap/recognition/live_session.hpp"
#include "iclap/rig/dataset_frame_source.hpp"
#include "iclap/rig/pose_spec.hpp"
#include "iclap/rig/sensor_frame_source.hpp"
#include "iclap/rig/serial_port.hpp"
#include "iclap/rig/sim_frame_source.hpp"
#include "iclap/rig/wts_sensor.hpp"
#include "iclap/sim/builtin_objects.hpp"
#include "iclap/sim/objects.hpp"
#include "recognition_setup.hpp"
#include "sim_options.hpp"
#include "stop_signals.hpp"

namespace {

using namespace iclap;
using namespace iclap::cli;
namespace rig = iclap::rig;
namespace fs = std::filesystem;

const std::string kUsage = std::string(
    "usage: iclap live --references TRAIN.csv SOURCE [--method M] [--confidence C]\n"
    "                  [--min-touches N] [--max-touches N] [--top N] [options]\n"
    "       iclap live --references DATA.csv --cross-validate [--method M]\n"
    "                  [--confidence LIST] [--max-touches N] [--fixed LIST] [options]\n"
    "\n"
    "Live recognition: after every touch (a frame with a taxel above the contact\n"
    "threshold; other frames are skipped) the ranking of the objects of TRAIN.csv\n"
    "is updated and one line is printed: touch number, best object, confidence\n"
    "and the top objects with their fused distances. The run stops as soon as\n"
    "the confidence reaches C (after at least --min-touches touches), after\n"
    "--max-touches touches, or when the source runs out, and prints the decision.\n"
    "The confidence is the relative margin 1 - d1/d2 of the best two fused\n"
    "distances (0: a tie; 1: a perfect match); the classifiers' distances are\n"
    "normalised by their L2 norm over the objects (the paper's choice).\n"
    "\n"
    "The references: every touch of TRAIN.csv is described, the codebook is\n"
    "fitted on all of them and each object's touches are its reference. A method\n"
    "with fitted weights (a+b without numbers) gets them by the paper's 0.1 grid,\n"
    "scored by leave-one-exploration-out recognition on TRAIN.csv (each object\n"
    "needs 2 explorations); fixed weights (0.6*iclap+0.2*icp+0.2*bow) are used\n"
    "as written.\n"
    "\n"
    "SOURCE, exactly one of:\n"
    "  --port PATH         the WTS sensor on a serial port (see `iclap devices`), with\n"
    "    [--pose SPEC]     pad pose source (default fixed:0,0,0, useless for shape):\n") +
    rig::pose_spec_help("                          ") +
    "\n"
    "    [--rate R]        frames per second asked of the sensor (default 5)\n"
    "    [--grid RxC]      taxel grid overriding the sensor's matrix info\n"
    "  --replay FILE.csv   the frames of a dataset in file order, or only those of\n"
    "    [--object NAME]   one object and/or\n"
    "    [--exploration K] one exploration id\n"
    "  --simulate OBJECT   an exploration simulated now: a built-in object name (see\n"
    "                      `iclap simulate`) or a mesh file (.obj/.stl/.ply), with\n"
    "    [--unit auto|m|mm] the mesh file's unit (default auto: its scale_to_metres in\n"
    "                      meshes.json beside it, as `iclap simulate --objects DIR`)\n"
    "    [--exploration K] exploration id (default 5: with --sim-seed equal to the\n"
    "                      references' seed, explorations 0-4 are those `iclap simulate`\n"
    "                      writes, so 5 is one the references have not seen)\n"
    "    [--sim-seed S]    simulation seed (default 1)\n"
    "    [--real-time]     deliver frames at the rig's pace (5 frames/s)\n"
    "    [--shift-mm D] [--yaw-deg A] [--frames F] [--sweep-min-mm L] [--sweep-max-mm L]\n"
    "    [--turn-probability P] [--start-candidates K]\n"
    "                      the scene and the operator, as `iclap simulate` (same\n"
    "                      defaults): give the references' options to simulate as they were\n"
    "\n"
    "options:\n"
    "  --method M          fusion method (default iclap+icp+bow); any expression of\n"
    "                      bow, icp, iclap, iclapn, patch, iclap_patch, height,\n"
    "                      height_contact and occupancy with + (weighted sum), *\n"
    "                      (product); the height, patch and occupancy classifiers need\n"
    "                      the pad orientation (qw..qz) in TRAIN.csv and from the source\n"
    "  --confidence C      stop threshold in [0, 1] (default 0.5); with --cross-validate\n"
    "                      a list (default 0.1,0.2,0.3,0.4,0.5,0.6)\n"
    "  --min-touches N     never stop before N touches (default 1)\n"
    "  --max-touches N     stop after N touches (default: no limit; --cross-validate: 20)\n"
    "  --top N             objects listed per touch (default 3)\n"
    "  --seed S            seed of the codebook and of the weight search's draws (default 1)\n"
    "  --weight-repeats N  draws per case of the weight search (default 2)\n"
    "  --zero-weights      let the weight grid give a classifier weight 0 (beyond the paper)\n"
    "  --threads N         worker threads of the weight search (default 0: all cores)\n"
    "\n"
    "--cross-validate: fold f holds out the f-th exploration of every object (as\n"
    "`iclap evaluate`); the codebook, references and weights come from the other\n"
    "explorations (fitted weights on inner folds of those: 3 explorations of every\n"
    "object needed); each held-out exploration is replayed touch by touch in time\n"
    "order. Prints, per confidence threshold, the accuracy at the stop and the mean\n"
    "and median touches used, and the accuracy of fixed numbers of touches:\n"
    "  --fixed LIST        fixed touch counts to compare with (default 5,10,20 without\n"
    "                      the counts above --max-touches; --max-touches itself if all are)\n"
    "  --repeats N         random draws per case for the random-draw rates (default 10)\n"
    "  --inner-codebooks   fit a codebook for every inner fold on its own training\n"
    "                      touches (strictly nested weights; default: the fold's)\n"
    "  --traces FILE.csv   also write the state after every replayed touch: fold, object,\n"
    "                      exploration, touches, recognised, confidence, correct and the\n"
    "                      fused distance d_OBJECT of every object (to study other stop rules)\n"
    "\n"
    "recognition options (as `iclap evaluate`):\n" +
    RecognitionOptions::usage() +
    "\n"
    "Exit status: 0 decided (or the source ran out), 1 failure (e.g. no touch at\n"
    "all), 2 bad input, 3 the device was lost (the touches so far are reported),\n"
    "130 Ctrl-C (the sensor's stream is stopped, the touches so far reported).";


std::string fixed3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

std::string percent(double r) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%.1f%%", 100.0 * r);
  return buf;
}

std::vector<double> parse_confidences(const std::string& text) {
  std::vector<double> out;
  std::set<double> seen;
  for (const auto& item : Options::split(text, ',')) {
    out.push_back(Options::parse_number(item, "--confidence", 0.0, 1.0));
    if (!seen.insert(out.back()).second) throw UsageError("--confidence: " + item + " is listed twice");
  }
  return out;
}

std::vector<int> parse_counts(const std::string& text, const std::string& what, long long max) {
  std::vector<int> out;
  std::set<int> seen;
  for (const auto& item : Options::split(text, ',')) {
    out.push_back(static_cast<int>(Options::parse_integer(item, what, 1, max)));
    if (!seen.insert(out.back()).second) throw UsageError(what + ": " + item + " is listed twice");
  }
  return out;
}

/// Throws UsageError naming `option` and `path` unless a file can be written
/// to `path` (atomically, by AtomicFileWriter): `path` is not a directory,
/// its directory exists and a temporary file can be created in it (tried
/// and removed at once).
void check_output_path(const std::string& path, const std::string& option) {
  const std::string where = option + " " + quote_text(path);
  std::error_code ec;
  if (path.empty()) throw UsageError(option + ": the path is empty");
  if (fs::is_directory(path, ec)) throw UsageError(where + ": is a directory; give a file name");
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::is_directory(parent, ec))
    throw UsageError(where + ": the directory " + quote_text(parent.string()) +
                     (fs::exists(parent, ec) ? " is not a directory" : " does not exist"));
  try {
    AtomicFileWriter probe(path);  // removed again (no commit)
  } catch (const IoError& e) {
    std::string why = e.what();  // "PATH: why"
    if (why.compare(0, path.size() + 2, path + ": ") == 0) why.erase(0, path.size() + 2);
    throw UsageError(where + ": " + why);
  }
}

Dataset read_dataset_with_warnings(const std::string& path) {
  return read_dataset_csv(path, [](const DatasetWarning& w) {
    std::fprintf(stderr, "%s:%zu: warning: %s\n", w.file.c_str(), w.line, w.message.c_str());
  });
}

/// The recognition system the options ask for.
struct Setup {
  RecognitionOptions ro;
  Method method;
  ClassifierFactory factory;
  CrossValidationSettings cv;  ///< seed, normalisation, threads, weight draws
};

/// The descriptor of one frame, as the references' touches were described.
Eigen::VectorXf describe(const Eigen::MatrixXd& pressures, const RecognitionOptions& ro) {
  Dataset one;
  one.rows = pressures.rows();
  one.cols = pressures.cols();
  Frame f;
  f.object = "live";
  f.pressures = pressures;
  one.frames.push_back(std::move(f));
  return cli::make_touch_table(one, ro).touches.features.col(0);
}

// ---------------------------------------------------------------------------
// --cross-validate

int run_cross_validation(const Options& o, const Setup& setup, const std::string& path, const Dataset& dataset,
                         const TouchTable& table) {
  const std::vector<double> confidences = parse_confidences(o.string("confidence", "0.1,0.2,0.3,0.4,0.5,0.6"));
  const auto max_touches = static_cast<Index>(o.integer("max-touches", 20, 1, 100000));
  const auto min_touches = static_cast<Index>(o.integer("min-touches", 1, 1, 100000));
  if (min_touches > max_touches)
    throw UsageError("--min-touches " + std::to_string(min_touches) + " exceeds --max-touches " +
                     std::to_string(max_touches));
  std::vector<int> fixed;
  if (o.has("fixed")) {
    fixed = parse_counts(o.string("fixed"), "--fixed", 100000);
    for (int n : fixed)
      if (n > max_touches)
        throw UsageError("--fixed: " + std::to_string(n) + " exceeds --max-touches " + std::to_string(max_touches));
  } else {  // the default counts that --max-touches allows
    for (int n : {5, 10, 20})
      if (n <= max_touches) fixed.push_back(n);
    if (fixed.empty()) fixed.push_back(static_cast<int>(max_touches));
  }

  LiveEvaluationSettings s;
  s.max_touches = max_touches;
  s.cross_validation = setup.cv;
  s.cross_validation.touches.clear();
  for (int n = 1; n <= max_touches; ++n) s.cross_validation.touches.push_back(n);
  s.cross_validation.repeats = static_cast<int>(o.integer("repeats", s.cross_validation.repeats, 1, 100000));
  s.cross_validation.weight_sweeps = false;
  s.cross_validation.inner_codebooks = o.flag("inner-codebooks");

  std::printf("iclap %s live --cross-validate\ndataset: %s: %zu objects, %zu frames, %ld touches (contact threshold %g)\n",
              ICLAP_VERSION_STRING, path.c_str(), table.objects.size(), dataset.frames.size(),
              static_cast<long>(table.size()), setup.ro.contact_threshold);
  std::printf("method: %s; descriptor %s, k = %ld, transform %s, ICP %s, %s normalisation, seed %llu\n",
              setup.method.name.c_str(), setup.ro.descriptor.c_str(), static_cast<long>(setup.ro.k),
              setup.ro.transform.c_str(), setup.ro.icp_summary(needed_classifiers({setup.method})).c_str(), to_string(s.cross_validation.normalization),
              static_cast<unsigned long long>(s.cross_validation.seed));
  std::fflush(stdout);
  const auto t0 = std::chrono::steady_clock::now();
  LiveEvaluationResult r;
  {
    Progress cv_progress("cross validation (weights, random draws)");
    Progress replay_progress("replaying held-out explorations");
    const ProgressCallback replayed = [&](std::size_t done, std::size_t total) {
      cv_progress.finish();  // its line is complete once the replays start
      replay_progress(done, total);
    };
    r = naming_inputs(path, [&] {
      return evaluate_live_stopping(table, setup.factory, make_quantizer(setup.ro), setup.method, s,
                                    std::ref(cv_progress), replayed);
    });
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%d folds (one exploration of every object held out); %zu held-out explorations replayed in time order, "
              "up to %ld touches each\n",
              r.folds, r.traces.size(), static_cast<long>(max_touches));
  if (setup.method.fit_weights) {
    std::printf("fusion of each fold (weights chosen on its training explorations%s):",
                s.cross_validation.inner_codebooks ? ", every inner fold with a codebook of its own" : "");
    for (std::size_t f = 0; f < r.fold_expressions.size(); ++f) std::printf(" [%zu] %s", f, r.fold_expressions[f].c_str());
    std::printf("\n");
  }

  std::printf("\nconfidence-based stop (at least %ld, at most %ld touches; confidence = 1 - d1/d2 of the fused distances)\n",
              static_cast<long>(min_touches), static_cast<long>(max_touches));
  std::printf("%10s %9s %13s %14s %11s %27s\n", "threshold", "accuracy", "mean touches", "median touches",
              "confident", "fixed count, same touches");
  for (double c : confidences) {
    const LiveStopOutcome out = r.stop(LiveStopRule{c, min_touches, max_touches});
    const auto same = static_cast<Index>(std::min<double>(static_cast<double>(max_touches), std::ceil(out.mean_touches)));
    const LiveFixedOutcome f = r.fixed(std::max<Index>(1, same));
    char fixed_text[64];
    std::snprintf(fixed_text, sizeof fixed_text, "%s at %ld", percent(f.accuracy()).c_str(), static_cast<long>(f.touches));
    std::printf("%10.2f %9s %13.2f %14.1f %10.0f%% %27s\n", c, percent(out.accuracy()).c_str(), out.mean_touches,
                out.median_touches,
                100.0 * static_cast<double>(out.confident) / static_cast<double>(std::max<Index>(1, out.tests)),
                fixed_text);
  }
  std::printf("\nfixed number of touches\n%8s %11s %14s\n", "touches", "time order", "random draws");
  const MethodResult& m = r.random_draws.methods.at(0);
  for (int n : fixed) {
    const LiveFixedOutcome f = r.fixed(n);
    const auto it = std::find(r.random_draws.touches.begin(), r.random_draws.touches.end(), n);
    const std::size_t t = static_cast<std::size_t>(it - r.random_draws.touches.begin());
    std::printf("%8d %11s %14s", n, percent(f.accuracy()).c_str(), percent(m.rate(t)).c_str());
    if (f.short_tests) std::printf("  (%ld explorations had fewer touches and used all)", static_cast<long>(f.short_tests));
    std::printf("\n");
  }
  if (o.has("traces")) {
    const std::string out = o.string("traces");
    AtomicFileWriter w(out);
    auto& f = w.stream();
    f << "fold,object,exploration,touches,recognised,confidence,correct";
    for (const auto& name : r.objects) f << ",d_" << name;
    f << "\n";
    char buf[32];
    for (const auto& t : r.traces)
      for (Index n = 1; n <= t.replayed(); ++n) {
        const auto k = static_cast<std::size_t>(n - 1);
        std::snprintf(buf, sizeof buf, "%.17g", t.confidence[k]);
        f << t.fold << ',' << r.objects[static_cast<std::size_t>(t.object)] << ',' << t.exploration << ',' << n << ','
          << r.objects[static_cast<std::size_t>(t.best[k])] << ',' << buf << ',' << (t.best[k] == t.object ? 1 : 0);
        for (Index j = 0; j < t.fused[k].size(); ++j) {
          std::snprintf(buf, sizeof buf, "%.17g", t.fused[k](j));
          f << ',' << buf;
        }
        f << '\n';
      }
    w.commit();
    std::printf("\nwrote %s: the state after every replayed touch (fused distances d_OBJECT)\n", out.c_str());
  }
  std::printf("\ntime order: the first N touches of each held-out exploration; random draws: %d random sets of N of\n"
              "its touches per exploration (as `iclap evaluate`). Total time %.1f s\n",
              s.cross_validation.repeats, secs);
  return kExitOk;
}

// ---------------------------------------------------------------------------
// Live run

/// A frame source with whatever it needs alive (members are destroyed in
/// reverse order: the source before the sensor and poses it refers to).
struct LiveSource {
  std::unique_ptr<rig::SerialPort> port;
  std::unique_ptr<rig::WtsSensor> sensor;
  std::unique_ptr<rig::PoseSource> poses;
  std::unique_ptr<rig::FrameSource> source;
  std::string truth;  ///< the object explored, when the source knows it
  double rate = 5.0;
  std::string port_path;
};

SimObject simulation_object(const std::string& spec, const std::string& unit, bool unit_given) {
  const auto names = builtin_object_names();
  if (std::find(names.begin(), names.end(), spec) != names.end()) {
    // A built-in object has its own size: a --unit would be ignored.
    if (unit_given)
      throw UsageError("--unit gives the unit of a mesh file; the built-in object " + quote_text(spec) +
                       " has its own size");
    return builtin_object(spec);
  }
  if (is_mesh_file(spec)) {
    // The file first: a path that does not exist (or is no mesh) is named
    // as such, not as a file that meshes.json fails to list.
    TriangleMesh mesh = load_mesh(spec);
    double scale = 1.0;
    if (unit == "auto") {
      const fs::path manifest = fs::path(spec).parent_path() / "meshes.json";
      const std::string file = fs::path(spec).filename().string();
      if (!fs::exists(manifest))
        throw UsageError("--simulate " + quote_text(spec) + ": no " + quote_text(manifest.string()) +
                         " gives its unit; pass --unit m or mm");
      const auto scales = read_mesh_manifest(manifest.string());
      const auto it = scales.find(file);
      if (it == scales.end())
        throw UsageError("--simulate " + quote_text(spec) + ": " + quote_text(manifest.string()) + " does not list " +
                         quote_text(file) + "; pass --unit m or mm");
      scale = it->second;
    } else {
      scale = metres_per_unit(parse_length_unit(unit, "--unit"));
    }
    scale_mesh(mesh, scale);
    return make_sim_object(fs::path(spec).stem().string(), std::move(mesh), true);
  }
  throw UsageError("--simulate: " + quote_text(spec, 80) + " is neither a built-in object (" + Options::join(names, ", ") +
                   ") nor a mesh file (.obj, .stl, .ply)");
}

/// Builds the source from the options, without touching a device yet.
LiveSource make_source(const Options& o) {
  const int kinds = o.has("port") + o.has("replay") + o.has("simulate");
  if (kinds == 0) throw UsageError("no source: give --port PATH, --replay FILE.csv or --simulate OBJECT");
  if (kinds > 1) throw UsageError("--port, --replay and --simulate exclude each other");
  auto only_with = [&](const char* option, const char* source) {
    if (o.has(option) && !o.has(source))
      throw UsageError(std::string("--") + option + " needs --" + source);
  };
  for (const char* opt : {"pose", "rate", "grid"}) only_with(opt, "port");
  only_with("object", "replay");
  for (const char* opt : {"sim-seed", "unit"}) only_with(opt, "simulate");
  for (const auto& opt : simulation_option_names()) only_with(opt.c_str(), "simulate");
  if (o.flag("real-time") && !o.has("simulate")) throw UsageError("--real-time needs --simulate");
  if (o.has("exploration") && !o.has("replay") && !o.has("simulate"))
    throw UsageError("--exploration needs --replay or --simulate");

  LiveSource s;
  if (o.has("replay")) {
    const std::string path = o.string("replay");
    Dataset d = read_dataset_with_warnings(path);
    const bool by_object = o.has("object");
    const std::string object = o.string("object");
    const bool by_exploration = o.has("exploration");
    // Any id the dataset format allows, negative ones too (the reader takes
    // any integer); only a simulated exploration's id must be >= 0.
    const std::int64_t exploration = o.integer("exploration", 0);
    std::vector<Frame> kept;
    for (auto& f : d.frames)
      if ((!by_object || f.object == object) && (!by_exploration || f.exploration == exploration))
        kept.push_back(std::move(f));
    if (kept.empty()) {
      std::string what = by_object ? "object " + quote_text(object, 60) : std::string();
      if (by_exploration) what += std::string(what.empty() ? "" : ", ") + "exploration " + std::to_string(exploration);
      throw UsageError("--replay " + path + " has no frame" + (what.empty() ? std::string() : " of " + what));
    }
    std::set<std::pair<std::string, std::int64_t>> runs;
    std::set<std::string> objects;
    for (const auto& f : kept) {
      runs.emplace(f.object, f.exploration);
      objects.insert(f.object);
    }
    if (runs.size() > 1)
      std::fprintf(stderr,
                   "iclap live: note: the replayed frames hold %zu explorations of %zu object(s), replayed as one "
                   "touch sequence (choose one with --object and --exploration)\n",
                   runs.size(), objects.size());
    if (objects.size() == 1) s.truth = *objects.begin();
    d.frames = std::move(kept);
    std::string name = path;
    if (by_object) name += ", object " + object;
    if (by_exploration) name += ", exploration " + std::to_string(exploration);
    s.source = std::make_unique<rig::DatasetFrameSource>(std::move(d), name);
    return s;
  }
  if (o.has("simulate")) {
    const auto seed = static_cast<std::uint64_t>(o.integer("sim-seed", 1, 0));
    const std::int64_t exploration = o.integer("exploration", 5, 0);
    SimObject object = simulation_object(o.string("simulate"), o.choice("unit", {"auto", "m", "mm"}, "auto"), o.has("unit"));
    s.truth = object.name;
    SimulationSettings simulation;
    parse_simulation_options(o, simulation.exploration);
    rig::SimFrameSource::Settings settings;
    settings.real_time = o.flag("real-time");
    s.source = std::make_unique<rig::SimFrameSource>(std::move(object), simulation, seed, exploration, settings);
    return s;
  }
  s.port_path = o.string("port");
  s.rate = o.number("rate", 5.0);
  rig::delay_ms_for_rate(s.rate);  // validate before touching the device
  std::optional<rig::Grid> grid_override;
  if (o.has("grid")) grid_override = rig::parse_grid(o.string("grid"), "--grid");
  if (!o.has("pose"))
    std::fprintf(stderr, "iclap live: no --pose given: every touch is at position 0,0,0 (only BoW can tell shapes apart)\n");
  s.poses = rig::make_pose_source(o.string("pose", "fixed:0,0,0"), "--pose");
  s.port = std::make_unique<rig::SerialPort>(s.port_path);
  rig::WtsSensor::Settings settings;
  settings.parser.grid = grid_override;
  s.sensor = std::make_unique<rig::WtsSensor>(*s.port, settings);
  return s;
}

/// Prepares the sensor: stops a stream left over from an earlier run,
/// learns the grid (or takes --grid), then wraps it as a frame source.
void connect_sensor(LiveSource& s, const std::optional<rig::Grid>& grid_override) {
  s.sensor->stop_periodic_frames();
  try {
    const rig::MatrixInfo info = s.sensor->query_matrix_info();
    if (grid_override && info.grid().size() != grid_override->size())
      throw UsageError("--grid " + rig::to_string(*grid_override) + " has " + std::to_string(grid_override->size()) +
                       " taxels but the sensor reports res_x=" + std::to_string(info.res_x) +
                       ", res_y=" + std::to_string(info.res_y) + " (" + std::to_string(info.grid().size()) + ")");
  } catch (const rig::WtsTimeout& e) {
    if (!grid_override)
      throw rig::WtsTimeout(std::string(e.what()) + "; is this the WTS sensor? (--grid ROWSxCOLS works without matrix info)");
    std::fprintf(stderr, "iclap live: warning: %s; using --grid %s\n", e.what(), rig::to_string(*grid_override).c_str());
  }
  s.source = std::make_unique<rig::SensorFrameSource>(*s.sensor, *s.poses);
}

/// The options of a live run that need no references: parsed before the
/// references are read and described, so that a bad one is refused at once.
struct LiveOptions {
  LiveStopRule rule;
  std::size_t top = 3;
  std::optional<rig::Grid> grid_override;
};

LiveOptions parse_live_options(const Options& o) {
  LiveOptions l;
  l.rule.confidence = o.number("confidence", 0.5, 0.0, 1.0);
  l.rule.min_touches = static_cast<Index>(o.integer("min-touches", 1, 1, 1000000));
  l.rule.max_touches = static_cast<Index>(o.integer("max-touches", 0, 1, 1000000));
  if (l.rule.max_touches > 0 && l.rule.max_touches < l.rule.min_touches)
    throw UsageError("--min-touches " + std::to_string(l.rule.min_touches) + " exceeds --max-touches " +
                     std::to_string(l.rule.max_touches));
  l.top = static_cast<std::size_t>(o.integer("top", 3, 0, 1000));
  for (const char* opt : {"fixed", "repeats", "traces"})
    if (o.has(opt)) throw UsageError(std::string("--") + opt + " needs --cross-validate");
  if (o.flag("inner-codebooks")) throw UsageError("--inner-codebooks needs --cross-validate");
  if (o.has("grid")) l.grid_override = rig::parse_grid(o.string("grid"), "--grid");
  return l;
}

int run_live(const Options& o, const LiveOptions& live, const Setup& setup, const std::string& path,
             const Dataset& dataset, const TouchTable& table) {
  const LiveStopRule& rule = live.rule;
  const std::size_t top = live.top;
  const std::optional<rig::Grid>& grid_override = live.grid_override;
  LiveSource src = make_source(o);  // validates every source option (opens the port, no traffic yet)
  const std::vector<std::string> needed = needed_classifiers({setup.method});
  {  // Before the references are built and the sensor streams.
    const std::vector<std::string> oriented = orientation_classifiers(needed);
    const bool has = src.sensor ? src.poses->has_orientation() : src.source->has_orientation();
    if (!oriented.empty() && !has)
      throw UsageError("--method " + setup.method.name + ": the " + oriented.front() +
                       " classifier needs the pad orientation, which the source does not give" +
                       (src.sensor ? " (give a --pose with orientation: omni, replay of a file with qw..qz, or "
                                     "fixed:X,Y,Z,QW,QX,QY,QZ)"
                                   : " (" + src.source->description() + " has no qw..qz)"));
  }

  // The references (and the weights) before the sensor streams.
  std::printf("iclap %s live\nreferences: %s: %zu objects, %ld touches (contact threshold %g)\n", ICLAP_VERSION_STRING,
              path.c_str(), table.objects.size(), static_cast<long>(table.size()), setup.ro.contact_threshold);
  Fusion fusion = setup.method.fusion;
  if (setup.method.fit_weights) {
    CrossValidationSettings cvs = setup.cv;
    cvs.touches.clear();
    const Index upto = rule.max_touches > 0 ? std::min<Index>(rule.max_touches, 20) : 20;
    for (Index n = 1; n <= upto; ++n) cvs.touches.push_back(static_cast<int>(n));
    const LiveWeights w = [&] {
      try {
        Progress progress("choosing fusion weights");
        return naming_inputs(path, [&] {
          return choose_live_weights(table, setup.factory, make_quantizer(setup.ro), setup.method, cvs,
                                     std::ref(progress));
        });
      } catch (const InvalidArgument& e) {
        throw UsageError("--method " + setup.method.name + " has fitted weights, chosen by leave-one-exploration-out "
                         "search on the references, which failed: " + std::string(e.what()) +
                         "; give fixed weights instead (e.g. 0.6*iclap+0.2*icp+0.2*bow)");
      }
    }();
    fusion = w.fusion;
    std::printf("method: %s with weights %s, chosen by leave-one-exploration-out grid search on the references "
                "(%d folds, %ld of %ld held-out tests right)\n",
                setup.method.name.c_str(), fusion.to_string().c_str(), w.folds, static_cast<long>(w.correct),
                static_cast<long>(w.total));
  } else {
    std::printf("method: %s\n", fusion.to_string().c_str());
  }
  const LiveReferences<> refs = naming_inputs(path, [&] {
    return LiveReferences<>(table, {}, setup.factory, make_quantizer(setup.ro), fusion, setup.cv.normalization);
  });
  std::printf("codebook: %ld words (%s descriptor); stop at confidence >= %g after >= %ld touch(es)%s\n",
              static_cast<long>(refs.vocabulary()), setup.ro.descriptor.c_str(), rule.confidence,
              static_cast<long>(rule.min_touches),
              rule.max_touches > 0 ? (", or after " + std::to_string(rule.max_touches) + " touches").c_str() : "");

  const StopSignals signals;
  if (src.sensor) {
    try {
      connect_sensor(src, grid_override);
    } catch (const rig::DeviceLost& e) {
      std::fprintf(stderr, "iclap live: %s (before any frame)\n", e.what());
      return kExitDeviceLost;
    }
  }
  const rig::Grid grid = src.source->grid();
  if (grid.rows != dataset.rows || grid.cols != dataset.cols)
    throw UsageError("the source's taxel grid " + rig::to_string(grid) + " differs from the references' " +
                     std::to_string(dataset.rows) + "x" + std::to_string(dataset.cols) +
                     (src.sensor ? " (--grid ROWSxCOLS overrides the sensor's)" : ""));
  const double pitch = naming_inputs(path, [&] { return taxel_pitch_of(dataset); });
  std::printf("source: %s\n", src.source->description().c_str());
  std::fflush(stdout);

  LiveSession session = refs.session(rule);
  std::size_t frames = 0;
  LiveStop stop = LiveStop::kContinue;
  const auto& names = refs.objects();

  auto finish = [&](const std::string& how) {
    if (session.touches() == 0) {
      std::printf("no decision: no touch in %zu frame(s) (%s)\n", frames, how.c_str());
    } else {
      std::printf("decision: %s after %ld touch(es) (%zu frames), confidence %s (%s)\n",
                  names[static_cast<std::size_t>(session.best())].c_str(), static_cast<long>(session.touches()), frames,
                  fixed3(session.confidence()).c_str(), how.c_str());
      if (!src.truth.empty()) {
        const bool known = std::find(names.begin(), names.end(), src.truth) != names.end();
        std::printf("truth: %s (%s)\n", src.truth.c_str(),
                    !known ? "not among the references" : (names[static_cast<std::size_t>(session.best())] == src.truth ? "correct" : "wrong"));
      }
    }
    std::fflush(stdout);
  };
  auto stop_stream = [&]() -> bool {
    if (!src.sensor) return true;
    try {
      if (!src.sensor->stop_periodic_frames())
        std::fprintf(stderr, "iclap live: warning: the sensor did not acknowledge 'stop periodic frames'\n");
      return true;
    } catch (const rig::DeviceLost&) {
      return false;
    }
  };

  std::string how;
  const bool check_positions_of_touches = reads_positions(needed);
  try {
    if (src.sensor) src.sensor->start_periodic_frames(src.rate);
    rig::PosedFrame pf;
    auto last_frame_at = std::chrono::steady_clock::now();
    bool warned_silent = false;
    Frame frame;
    while (!StopSignals::requested()) {
      const auto st = src.source->next(pf, std::chrono::milliseconds(100));
      if (st == rig::FrameSource::Status::kEnd) {
        how = src.sensor ? "the pose source ended" : "the source ran out of frames";
        break;
      }
      if (st == rig::FrameSource::Status::kTimeout) {
        if (src.sensor) {
          const auto stats = src.sensor->stats();
          if (frames == 0 && stats.frames_wrong_shape >= 5)
            throw iclap::Error(src.port_path + ": the sensor sends frames of " +
                               std::to_string(stats.last_wrong_shape_taxels) + " taxels but the grid " +
                               rig::to_string(grid) + " has " + std::to_string(grid.size()) + "; pass --grid ROWSxCOLS");
          if (!warned_silent && std::chrono::steady_clock::now() - last_frame_at > std::chrono::seconds(3)) {
            std::fprintf(stderr, "iclap live: warning: no frame from %s for 3 s (still waiting; Ctrl-C stops)\n",
                         src.port_path.c_str());
            warned_silent = true;
          }
        }
        continue;
      }
      ++frames;
      last_frame_at = std::chrono::steady_clock::now();
      frame.pressures = pf.pressures;
      if (!is_contact(frame, setup.ro.contact_threshold)) continue;
      Eigen::VectorXf feature = describe(pf.pressures, setup.ro);
      const Index word = refs.word(feature);
      frame.position = pf.pose.position;
      frame.orientation = pf.pose.orientation;
      if (check_positions_of_touches) {
        const std::string problem = position_problem(frame.position, setup.ro, needed);
        if (!problem.empty()) {
          // A dataset's row by its labels (as the references' check);
          // otherwise the count of frames received.
          const auto* replay = dynamic_cast<const rig::DatasetFrameSource*>(src.source.get());
          const std::string which =
              replay ? "object " + quote_text(replay->last_frame().object, 60) + " exploration " +
                           std::to_string(replay->last_frame().exploration) + " frame " +
                           std::to_string(replay->last_frame().frame)
                     : "frame " + std::to_string(frames) + " received";
          throw InvalidArgument(src.source->description(), which + ": " + problem);
        }
      }
      stop = session.add_touch(live_touch_of(frame, setup.ro.contact_threshold, pitch, std::move(feature), word));
      std::printf("touch %ld (frame %zu): %s, confidence %s", static_cast<long>(session.touches()), frames,
                  names[static_cast<std::size_t>(session.best())].c_str(), fixed3(session.confidence()).c_str());
      if (top > 0) {
        std::printf(" |");
        for (std::size_t r = 0; r < std::min(top, session.ranking().size()); ++r) {
          const Index j = session.ranking()[r];
          std::printf("%s %s %s", r ? "," : "", names[static_cast<std::size_t>(j)].c_str(),
                      fixed3(session.fused()(j)).c_str());
        }
      }
      std::printf("\n");
      std::fflush(stdout);
      if (stop != LiveStop::kContinue) {
        how = stop == LiveStop::kConfident ? "confident" : "touch limit";
        break;
      }
    }
  } catch (const rig::DeviceLost& e) {
    std::fprintf(stderr, "iclap live: %s\n", e.what());
    finish("device lost");
    std::fprintf(stderr, "iclap live: device lost after %zu frames, %ld touches\n", frames,
                 static_cast<long>(session.touches()));
    return kExitDeviceLost;
  } catch (...) {
    stop_stream();
    throw;
  }
  if (!stop_stream()) {
    std::fprintf(stderr, "iclap live: device lost while stopping the stream\n");
    finish(StopSignals::requested() ? "interrupted" : how);
    return kExitDeviceLost;
  }
  if (StopSignals::requested()) {
    finish("interrupted");
    return StopSignals::exit_status();
  }
  finish(how);
  return session.touches() > 0 ? kExitOk : kExitFailure;
}

int run_live_command(const Args& args) {
  auto value_options = RecognitionOptions::value_options();
  for (const char* v : {"references", "method", "confidence", "min-touches", "max-touches", "top",
                        "seed", "weight-repeats", "threads", "port", "pose", "rate", "grid", "replay", "object",
                        "exploration", "simulate", "sim-seed", "unit", "fixed", "repeats", "traces"})
    value_options.insert(v);
  for (const auto& v : simulation_option_names()) value_options.insert(v);
  const Options o(args, value_options, {"cross-validate", "real-time", "zero-weights", "inner-codebooks"});
  o.expect_positional(0, 0, "no positional arguments (the references are --references FILE.csv)");
  if (!o.has("references")) throw UsageError("missing --references TRAIN.csv");
  Setup setup{RecognitionOptions{}, [&] {
                  try {
                    return parse_method(o.string("method", "iclap+icp+bow"));
                  } catch (const InvalidArgument& e) {
                    throw UsageError(std::string("--method: ") + e.what());
                  }
                }(),
               {}, {}};
  setup.ro.parse(o);
  if (setup.ro.trim_auto || !setup.ro.trim_auto_by_name.empty())
    throw UsageError("--trim auto is chosen by iclap evaluate's cross validation; live recognition needs fixed "
                     "fractions (--trim F or NAME=F)");
  if (setup.ro.height_is_auto())
    throw UsageError("lists of --tilt-scale or --contact-scale values are chosen by iclap evaluate's cross "
                     "validation; live recognition needs one value of each");
  if (setup.ro.occupancy_is_auto())
    throw UsageError("lists of --occupancy-* values are chosen by iclap evaluate's cross validation; live "
                     "recognition needs one value of each");
  setup.cv.seed = static_cast<std::uint64_t>(o.integer("seed", static_cast<long long>(setup.cv.seed), 0));
  setup.ro.codebook_seed = setup.cv.seed;
  setup.cv.weight_repeats = static_cast<int>(o.integer("weight-repeats", setup.cv.weight_repeats, 1, 100000));
  setup.cv.zero_weights = o.flag("zero-weights");
  setup.cv.threads = static_cast<int>(o.integer("threads", setup.cv.threads, 0, 4096));
  const std::vector<std::string> needed = needed_classifiers({setup.method});
  setup.ro.check_trim_names(needed);
  RecognitionOptions::check_options_used(o, needed);
  const RecognitionOptions ro = setup.ro;
  setup.factory = [ro, needed] { return make_classifiers(ro, needed); };
  {
    Recognizer probe(setup.factory(), setup.cv.normalization);
    try {
      probe.check({setup.method});
    } catch (const InvalidArgument& e) {
      throw UsageError(std::string("--method: ") + e.what());
    }
  }
  const bool cross_validate = o.flag("cross-validate");
  if (cross_validate) {
    // The sources and their options: the references are the source.
    std::set<std::string> sources = simulation_option_names();
    sources.insert({"port", "replay", "simulate", "top", "pose", "rate", "grid", "object", "exploration", "sim-seed", "unit"});
    for (const auto& opt : sources)
      if (o.has(opt)) throw UsageError("--cross-validate takes no --" + opt + " (it replays the references)");
    if (o.flag("real-time")) throw UsageError("--cross-validate takes no --real-time (it replays the references)");
    // The traces' path, checked before the (long) computation.
    if (o.has("traces")) {
      check_output_path(o.string("traces"), "--traces");
      // The traces would replace the dataset they are computed from.
      std::error_code ec;
      if (fs::equivalent(o.string("traces"), o.string("references"), ec))
        throw UsageError("--traces " + quote_text(o.string("traces")) + " is the --references file " +
                         quote_text(o.string("references")) + ", which the traces would replace");
    }
  } else if (o.has("confidence") && o.string("confidence").find(',') != std::string::npos) {
    throw UsageError("--confidence: a list of thresholds needs --cross-validate");
  }
  std::optional<LiveOptions> live;
  if (!cross_validate) live = parse_live_options(o);

  const std::string path = o.string("references");
  const Dataset dataset = read_dataset_with_warnings(path);
  TouchTable table;
  {
    Progress progress("describing reference touches");
    table = naming_inputs(path, [&] { return cli::make_touch_table(dataset, setup.ro, std::ref(progress)); });
  }
  check_orientation(needed, table, path, /*every_frame=*/true);
  check_positions(needed, table, setup.ro, path);
  // References of one object: the library refuses them (LiveReferences,
  // CrossValidation), but only after the banner and, for fitted weights,
  // inside the weight search, whose failure reads as the method's; named
  // here as the data error it is.
  naming_inputs(path, [&] { check_objects_to_choose_among(table.objects, "table"); });
  return cross_validate ? run_cross_validation(o, setup, path, dataset, table)
                        : run_live(o, *live, setup, path, dataset, table);
}

}  // namespace

ICLAP_COMMAND("live", "recognise an object live, touch by touch, stopping when confident", kUsage, run_live_command);

// SPDX-License-Identifier: MIT
//
// `iclap evaluate [FILE.csv]`: the paper's recognition experiment (Section
// VI), the project's main job.

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "cli.hpp"
#include "iclap/core/version.hpp"
#include "iclap/data/csv_reader.hpp"
#include "iclap/data/csv_writer.hpp"
#include "iclap/data/overlap.hpp"
#include "iclap/data/ply_cloud.hpp"
#include "iclap/io/atomic_file.hpp"
#include "iclap/recognition/cross_validation.hpp"
#include "iclap/sim/builtin_objects.hpp"
#include "iclap/sim/simulator.hpp"
#include "recognition_setup.hpp"
#include "svg_plot.hpp"
#include "touch_counts.hpp"

#ifndef ICLAP_SIM_FINGERPRINT
#define ICLAP_SIM_FINGERPRINT "unknown"
#endif

namespace {

using namespace iclap;
using namespace iclap::cli;
namespace fs = std::filesystem;

const std::string kUsage = std::string(
    "usage: iclap evaluate [FILE.csv] [options]\n"
    "\n"
    "Runs the iCLAP paper's experiment: leave-one-exploration-out cross validation\n"
    "of every method, recognition rate against the number of touches. The codebook,\n"
    "the reference clouds and the fusion weights come from the training folds only\n"
    "(weights by the paper's 0.1 grid, chosen on inner folds of the training\n"
    "explorations). Without FILE, the built-in 20-object rig simulation is used\n"
    "(simulated once, then cached).\n"
    "\n"
    "Writes to --out DIR: results.csv (method,touches,rate,...), weights.csv,\n"
    "confusion.csv, sweeps.csv and SVG figures (fig_*.svg) like the paper's.\n"
    "\n"
    "options:\n"
    "  --touches LIST          numbers of touches: 1,5,10,20 or 1..20 (default 1..20); a count\n"
    "                          above 20 may not exceed the touches of the largest held-out\n"
    "                          exploration (every draw would use all of them)\n"
    "  --methods LIST|paper|all   comma-separated methods (default paper: bow, icp,\n"
    "                          iclap, icp+bow, icp*bow, iclap+icp, iclap*icp, iclap+bow,\n"
    "                          iclap*bow, iclap+icp+bow, iclap*icp*bow; all adds iclapn,\n"
    "                          patch, iclap_patch (contact-patch ICP, beyond the paper),\n"
    "                          iclap_patch+patch+bow, iclap_patch*patch*bow, height\n"
    "                          (heights and tilts of the touches, no registration, beyond\n"
    "                          the paper), height_contact (height with the size of\n"
    "                          each contact patch) and occupancy (where the pad felt the\n"
    "                          object and where it did not, with a bounded search of the\n"
    "                          object's placement, beyond the paper; needs the pad\n"
    "                          orientation, columns qw..qz; options --occupancy-*,\n"
    "                          --placement-*)).\n"
    "                          '+' sums with fitted weights, '*' products, or fixed\n"
    "                          weights such as 0.6*iclap+0.2*icp+0.2*bow; a method given\n"
    "                          twice, also spelt otherwise (bow+icp for icp+bow), is refused\n"
    "  --repeats N             random draws per object and number of touches (default 10)\n"
    "  --weight-repeats N      draws per case on the inner folds for the weights (default 2)\n"
    "  --zero-weights          let the weight grid give a classifier weight 0, i.e. drop it\n"
    "                          (beyond the paper, whose grid gives each at least 0.1)\n"
    "  --inner-codebooks       fit a codebook for every inner fold on its own training\n"
    "                          touches (strictly nested; default: the outer fold's)\n"
    "  --seed S                seed of the touch draws and the codebook (default 1)\n"
    "  --normalization l2|minmax|zscore   distance normalisation (default l2, the paper's)\n"
    "  --threads N             worker threads (default 0: all cores); results do not depend on it\n"
    "  --out DIR               output directory (default results; created, with missing\n"
    "                          parents, if needed, and checked before the run); the files\n"
    "                          are moved into it only once all of them are written, and a\n"
    "                          run that fails leaves it as it was\n"
    "  --sim-seed S            seed of the built-in simulation (default 1; not with a FILE)\n"
    "  --export-ply            also write each object's reference cloud (all its touches,\n"
    "                          label = word of a codebook fitted on all touches) as\n"
    "                          DIR/references/OBJECT.ply (bytes other than letters,\n"
    "                          digits, - and _ written as %XX)\n") +
    RecognitionOptions::usage();

std::vector<Method> parse_methods(const std::string& text) {
  std::vector<Method> out = paper_methods();
  if (text == "paper") return out;
  if (text == "all") {
    for (const char* m :
         {"iclapn", "patch", "iclap_patch", "iclap_patch+patch+bow", "iclap_patch*patch*bow", "height", "height_contact",
          "occupancy"})
      out.push_back(parse_method(m));
    return out;
  }
  out.clear();
  // A method given twice, also under another spelling ("bow+icp" after
  // "icp+bow", "icp * iclap" after "iclap*icp"), would run twice and fill
  // two columns with one method's results.
  std::map<std::string, std::size_t> seen;  // method_key -> index of its item
  for (const auto& spec : Options::split(text, ',')) {
    // The parser names its argument "method" ("method: '': ..."); the user
    // gave --methods.
    Method m = [&] {
      try {
        return parse_method(spec);
      } catch (const InvalidArgument& e) {
        throw UsageError("--methods: item " + std::to_string(out.size() + 1) + ": " +
                         (e.argument() == "method" ? e.reason() : std::string(e.what())));
      }
    }();
    const auto [it, added] = seen.emplace(method_key(m), out.size());
    if (!added) {
      const Method& first = out[it->second];
      throw UsageError("--methods: " + quote_text(m.name) + " (item " + std::to_string(out.size() + 1) +
                       ") is the same method as " + quote_text(first.name) + " (item " +
                       std::to_string(it->second + 1) + ")");
    }
    out.push_back(std::move(m));
  }
  return out;
}

std::string cache_directory() {
  if (const char* d = std::getenv("ICLAP_CACHE_DIR"); d && *d) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/iclap";
  if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.cache/iclap";
  return ".iclap-cache";
}

/// The built-in 20-object dataset: read from the cache, or simulated and
/// cached. The cache key holds the seed and a fingerprint of the simulator's
/// source, so a changed simulator never reuses an old file.
Dataset builtin_dataset(std::uint64_t seed, int threads, std::string& origin) {
  const std::string dir = cache_directory();
  const std::string path = dir + "/builtin-seed" + std::to_string(seed) + "-" + ICLAP_SIM_FINGERPRINT + ".csv";
  std::string stale;
  if (fs::exists(path)) {
    try {
      Dataset cached = read_dataset_csv(path);
      origin = "built-in simulation (cached: " + path + ")";
      return cached;
    } catch (const std::exception& e) {  // damaged cache: simulate again and replace it
      stale = std::string("; the cache was unreadable: ") + e.what();
    }
  }
  SimulationSettings settings;
  settings.threads = static_cast<unsigned>(threads);
  Progress progress("simulating the built-in objects");
  const auto start = std::chrono::steady_clock::now();
  Dataset ds = simulate_dataset(builtin_objects(), settings, seed, std::ref(progress));
  progress.finish();
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  origin = "built-in simulation (seed " + std::to_string(seed) + ", simulated in " +
           format_value(std::round(secs * 10) / 10) + " s";
  std::error_code ec;
  fs::create_directories(dir, ec);
  try {
    write_dataset_csv(path, ds);
    origin += ", cached: " + path + stale + ")";
    // Files of the same seed from older simulators can never be used again.
    const std::string prefix = "builtin-seed" + std::to_string(seed) + "-";
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind(prefix, 0) == 0 && name.size() == prefix.size() + 12 + 4 &&
          name.compare(name.size() - 4, 4, ".csv") == 0 && entry.path() != fs::path(path))
        fs::remove(entry.path(), ec);
    }
  } catch (const IoError& e) {
    origin += ", not cached: " + std::string(e.what()) + ")";
  }
  return ds;
}

std::string percent(double r) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%5.1f", 100.0 * r);
  return buf;
}

// Writes one output file into the staging directory of StagedOutput. The
// content reaches storage; the staging directory's entries need not, since
// StagedOutput::commit moves the file on and syncs the directory it lands in.
void write_file(const fs::path& path, const std::string& content) {
  AtomicFileWriter w(path.string());
  w.stream() << content;
  w.commit(AtomicFileWriter::DirectorySync::no);
}

double fold_std(const MethodResult& m, std::size_t t) {
  std::vector<double> rates;
  for (std::size_t f = 0; f < m.fold_total.size(); ++f)
    if (m.fold_total[f][t] > 0)
      rates.push_back(static_cast<double>(m.fold_correct[f][t]) / static_cast<double>(m.fold_total[f][t]));
  if (rates.size() < 2) return 0.0;
  double mean = 0;
  for (double r : rates) mean += r;
  mean /= static_cast<double>(rates.size());
  double var = 0;
  for (double r : rates) var += (r - mean) * (r - mean);
  return std::sqrt(var / static_cast<double>(rates.size() - 1));
}

/// The paper's figures that the evaluated methods allow.
void write_figures(const fs::path& out, const CrossValidationResult& r, std::vector<std::string>& written) {
  std::map<std::string, const MethodResult*> by_name;
  for (const auto& m : r.methods) by_name[m.name] = &m;
  auto series_of = [&](const std::string& name, bool dashed = false) {
    PlotSeries s;
    s.name = name;
    s.dashed = dashed;
    const MethodResult& m = *by_name.at(name);
    for (std::size_t t = 0; t < r.touches.size(); ++t) {
      s.x.push_back(r.touches[t]);
      s.y.push_back(m.rate(t));
    }
    return s;
  };
  struct Figure {
    const char* file;
    const char* title;
    std::vector<std::string> methods;
  };
  const std::vector<Figure> figures = {
      {"fig_single.svg", "Single pipelines and iCLAP (paper Fig. 5)", {"bow", "icp", "iclap"}},
      {"fig_decision_fusion.svg", "Decision fusion of ICP and BoW vs iCLAP", {"iclap", "icp+bow", "icp*bow"}},
      {"fig_hybrid_icp.svg", "Hybrid fusion of iCLAP and ICP", {"iclap", "iclap+icp", "iclap*icp"}},
      {"fig_hybrid_bow.svg", "Hybrid fusion of iCLAP and BoW", {"iclap", "iclap+bow", "iclap*bow"}},
      {"fig_hybrid_all.svg", "Hybrid fusion of iCLAP, ICP and BoW", {"iclap", "iclap+icp+bow", "iclap*icp*bow"}},
  };
  for (const auto& f : figures) {
    Plot p;
    p.title = f.title;
    p.x_label = "number of touches";
    p.x_integer = true;
    p.y_label = "recognition rate";
    for (const auto& name : f.methods)
      if (by_name.count(name)) p.series.push_back(series_of(name, name == "iclap" && f.methods.front() == "iclap"));
    if (p.series.size() < 2) continue;
    write_file(out / f.file, render_svg(p));
    written.push_back(f.file);
  }
  {
    Plot p;
    p.title = "All evaluated methods";
    p.x_label = "number of touches";
    p.x_integer = true;
    p.y_label = "recognition rate";
    for (const auto& m : r.methods) p.series.push_back(series_of(m.name));
    write_file(out / "fig_all_methods.svg", render_svg(p));
    written.push_back("fig_all_methods.svg");
  }
  // Rate against the fusion weights on the test folds (the paper's weight
  // figures): two terms, one line per weight; three terms, the rate at the
  // largest number of touches against the first weight, one line per second.
  for (const auto& sw : r.sweeps) {
    Plot p;
    p.y_label = "recognition rate";
    std::string safe;
    for (char c : sw.method) safe += (c == '+' ? 'p' : (c == '*' ? 'x' : c));
    const std::string file = "fig_weights_" + safe + ".svg";
    if (sw.terms.size() == 2) {
      p.title = sw.method + ": rate with weight w on " + sw.terms[0];
      p.x_label = "number of touches";
      p.x_integer = true;
      for (std::size_t g = 0; g < sw.grid.size(); ++g) {
        PlotSeries s;
        s.name = "w = " + format_value(sw.grid[g][0]);
        for (std::size_t t = 0; t < r.touches.size(); ++t) {
          s.x.push_back(r.touches[t]);
          s.y.push_back(sw.total[t] ? static_cast<double>(sw.correct[g][t]) / static_cast<double>(sw.total[t]) : 0);
        }
        p.series.push_back(std::move(s));
      }
    } else if (sw.terms.size() == 3) {
      const std::size_t t = r.touches.size() - 1;
      p.title = sw.method + ": rate at " + std::to_string(r.touches[t]) + " touches";
      p.x_label = "weight on " + sw.terms[1];
      // One line per value of the third weight. The grid makes the last
      // weight 1 minus the others, so equal values can differ in the last
      // bits; keyed by the value rounded to 1e-9 (grid steps are far coarser).
      std::map<long long, PlotSeries> lines;
      for (std::size_t g = 0; g < sw.grid.size(); ++g) {
        PlotSeries& s = lines[std::llround(sw.grid[g][2] * 1e9)];
        s.name = "w(" + sw.terms[2] + ") = " + format_value(sw.grid[g][2]);
        s.x.push_back(sw.grid[g][1]);
        s.y.push_back(sw.total[t] ? static_cast<double>(sw.correct[g][t]) / static_cast<double>(sw.total[t]) : 0);
      }
      for (auto& kv : lines) p.series.push_back(kv.second);
    } else {
      continue;
    }
    write_file(out / file, render_svg(p));
    written.push_back(file);
  }
}

/// The tables write_tables writes into OUT, in the order they are listed.
const std::vector<std::string> kTableFiles = {"results.csv", "weights.csv", "confusion.csv", "sweeps.csv"};

void write_tables(const fs::path& out, const CrossValidationResult& r) {
  std::string results = "method,touches,rate,correct,total,fold_rate_std\n";
  for (const auto& m : r.methods)
    for (std::size_t t = 0; t < r.touches.size(); ++t)
      results += m.name + "," + std::to_string(r.touches[t]) + "," + format_value(m.rate(t)) + "," +
                 std::to_string(m.correct[t]) + "," + std::to_string(m.total[t]) + "," + format_value(fold_std(m, t)) +
                 "\n";
  write_file(out / "results.csv", results);

  std::string weights = "method,fold,fusion\n";
  for (const auto& m : r.methods)
    for (std::size_t f = 0; f < m.fold_expressions.size(); ++f)
      weights += m.name + "," + std::to_string(f) + "," + m.fold_expressions[f] + "\n";
  write_file(out / "weights.csv", weights);

  std::string confusion = "method,touches,true_object,recognised_object,count\n";
  for (const auto& m : r.methods)
    for (std::size_t t = 0; t < r.touches.size(); ++t)
      for (Index a = 0; a < m.confusion[t].rows(); ++a)
        for (Index b = 0; b < m.confusion[t].cols(); ++b)
          if (m.confusion[t](a, b) > 0)
            confusion += m.name + "," + std::to_string(r.touches[t]) + "," + r.objects[static_cast<std::size_t>(a)] +
                         "," + r.objects[static_cast<std::size_t>(b)] + "," + std::to_string(m.confusion[t](a, b)) + "\n";
  write_file(out / "confusion.csv", confusion);

  std::string sweeps = "method,weights,touches,rate\n";
  for (const auto& sw : r.sweeps)
    for (std::size_t g = 0; g < sw.grid.size(); ++g) {
      std::string w;
      for (std::size_t i = 0; i < sw.grid[g].size(); ++i) w += (i ? "+" : "") + format_value(sw.grid[g][i]) + "*" + sw.terms[i];
      for (std::size_t t = 0; t < r.touches.size(); ++t)
        sweeps += sw.method + "," + w + "," + std::to_string(r.touches[t]) + "," +
                  format_value(sw.total[t] ? static_cast<double>(sw.correct[g][t]) / static_cast<double>(sw.total[t]) : 0) +
                  "\n";
    }
  write_file(out / "sweeps.csv", sweeps);
}

// An object name as a file name, one to one: letters, digits, '-' and '_'
// stay, every other byte becomes %XX ("a b" -> "a%20b", "a%b" -> "a%25b"),
// so distinct objects never share a file.
std::string file_name_of(const std::string& object) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (char c : object) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isalnum(u) || c == '-' || c == '_') {
      out += c;
    } else {
      out += '%';
      out += hex[u >> 4];
      out += hex[u & 15];
    }
  }
  return out;
}

// Creates `dir` and its missing ancestors, one at a time, and appends each
// directory it created to `created` (outermost first). Errors name `what`
// (the user's --out) and the part of the path that failed.
void create_directories_noting(const fs::path& dir, const fs::path& what, std::vector<fs::path>& created) {
  std::vector<fs::path> missing;  // innermost first
  for (fs::path p = dir; !p.empty();) {
    std::error_code ec;
    const fs::file_status st = fs::status(p, ec);
    if (st.type() != fs::file_type::not_found) {
      if (ec) throw IoError(what.string(), "cannot create the output directory: " + p.string() + ": " + ec.message());
      if (!fs::is_directory(st))
        throw IoError(what.string(), "cannot create the output directory: " + p.string() + " is not a directory");
      break;
    }
    missing.push_back(p);
    fs::path parent = p.parent_path();
    if (parent == p) break;
    p = std::move(parent);
  }
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    std::error_code ec;
    if (fs::create_directory(*it, ec)) {
      created.push_back(*it);
    } else if (ec) {
      throw IoError(what.string(), "cannot create the output directory: cannot create " + it->string() + ": " +
                                       ec.message());
    }
  }
}

// Removes the directories create_directories_noting made, innermost first,
// each only if it is empty.
void remove_created_directories(std::vector<fs::path>& created) {
  for (auto it = created.rbegin(); it != created.rend(); ++it) {
    std::error_code ec;
    fs::remove(*it, ec);
  }
  created.clear();
}

// Writes a run's output files all or nothing: they go to a new directory
// beside OUT (OUT.partial-PID-N) first; commit() moves them into OUT
// (created if missing; its other files are kept). commit() first checks that
// every file can take its place, then replaces the files one by one, keeping
// each old file (a hard link, or the file itself moved aside) until all are
// in place; if a step fails it puts every old file back, so a failed run
// leaves OUT as it was. Destroyed without a commit (a write failed), it
// removes the staging directory and the parents of OUT it created.
class StagedOutput {
 public:
  /// Creates the staging directory beside OUT, and OUT's missing parent
  /// directories. Errors name OUT as given.
  explicit StagedOutput(fs::path out) : out_(std::move(out)) {
    // "results/" -> "results"
    while (out_.has_relative_path() && out_.filename().empty()) out_ = out_.parent_path();
    {
      std::error_code ec;
      const fs::file_status st = fs::status(out_, ec);
      if (fs::exists(st) && !fs::is_directory(st)) throw IoError(out_.string(), "exists and is not a directory");
      // A link to a missing path passed as "missing" here, and the run's
      // end then failed to create OUT, after the whole run.
      if (!fs::exists(st) && fs::is_symlink(fs::symlink_status(out_, ec)))
        throw IoError(out_.string(), "is a symbolic link to " + fs::read_symlink(out_, ec).string() +
                                         ", which does not exist; create it or name another directory");
      if (fs::is_directory(st) && ::access(out_.c_str(), W_OK | X_OK) != 0)
        throw IoError(out_.string(), std::string("cannot write into the output directory: ") + std::strerror(errno));
    }
    create_directories_noting(out_.parent_path(), out_, created_);
    for (int n = 0;; ++n) {
      stage_ = out_;
      stage_ += ".partial-" + std::to_string(::getpid()) + "-" + std::to_string(n);
      std::error_code ec;
      if (fs::create_directory(stage_, ec)) break;
      if (ec || n == 100) {
        remove_created_directories(created_);
        throw IoError(out_.string(), "cannot create a staging directory beside it (" + stage_.string() +
                                         "): " + (ec ? ec.message() : std::string("100 names taken")));
      }
    }
  }
  StagedOutput(const StagedOutput&) = delete;
  StagedOutput& operator=(const StagedOutput&) = delete;
  ~StagedOutput() {
    if (committed_) return;
    std::error_code ec;
    if (!keep_stage_) fs::remove_all(stage_, ec);
    remove_created_directories(created_);
  }

  /// Checks, before a run, that OUT can take these files (paths relative to
  /// OUT) and that OUT/dirs[i] are directories where they exist.
  void check(const std::vector<fs::path>& files, const std::vector<fs::path>& dirs) const {
    for (const auto& f : files) check_target(f);
    for (const auto& d : dirs) check_directory(out_ / d);
  }

  /// Runs `write(dir)`, which writes the files into `dir`; an error naming a
  /// file of the staging directory is thrown again naming its place in OUT.
  template <typename F>
  void write(F&& write) const {
    try {
      write(stage_);
    } catch (const WriteError& e) {
      throw WriteError(in_out(e.path()), "write failed; " + out_.string() + " was left as it was");
    } catch (const IoError& e) {
      throw IoError(in_out(e.path()), strip_path(e) + "; " + out_.string() + " was left as it was");
    } catch (const fs::filesystem_error& e) {
      throw IoError(in_out(e.path1().string()), e.code().message() + "; " + out_.string() + " was left as it was");
    }
  }

  void commit() {
    std::vector<fs::path> files;  // relative to the staging directory
    for (auto it = fs::recursive_directory_iterator(stage_); it != fs::recursive_directory_iterator(); ++it)
      if (!it->is_directory()) files.push_back(it->path().lexically_relative(stage_));
    std::sort(files.begin(), files.end());
    // Everything that can be checked is checked before OUT is touched.
    for (const auto& f : files) check_target(f);

    struct Replaced {
      fs::path target, backup;  // backup empty: the target did not exist
    };
    std::vector<Replaced> done;
    std::vector<fs::path> created;  // OUT and its subdirectories
    try {
      create_directories_noting(out_, out_, created);
      for (const auto& f : files) {
        const fs::path target = out_ / f;
        create_directories_noting(target.parent_path(), out_, created);
        std::error_code ec;
        Replaced r{target, {}};
        if (fs::exists(fs::symlink_status(target, ec))) {
          r.backup = stage_ / ".replaced" / f;
          fs::create_directories(r.backup.parent_path(), ec);
          // A second name for the old file keeps it while the new one
          // replaces it in one rename; without hard links it is moved aside.
          if (!ec) fs::create_hard_link(target, r.backup, ec);
          if (ec) {
            ec.clear();
            fs::rename(target, r.backup, ec);
          }
          if (ec) throw IoError(target.string(), "cannot keep the old file while replacing it: " + ec.message());
        }
        done.push_back(r);
        fs::rename(stage_ / f, target, ec);
        if (ec) throw IoError(target.string(), "cannot move into place: " + ec.message());
      }
    } catch (const IoError& e) {
      // Put every old file back, newest first.
      std::string lost;
      for (auto it = done.rbegin(); it != done.rend(); ++it) {
        std::error_code ec;
        if (it->backup.empty())
          fs::remove(it->target, ec);
        else
          fs::rename(it->backup, it->target, ec);
        if (ec) {
          lost += "; cannot restore " + it->target.string() + " (" + ec.message() + ")";
          if (!it->backup.empty()) lost += ", its old content is kept as " + it->backup.string();
        }
      }
      remove_created_directories(created);
      if (!lost.empty()) {
        keep_stage_ = true;
        throw IoError(e.path(), strip_path(e) + lost);
      }
      throw IoError(e.path(), strip_path(e) + "; " + out_.string() + " was left as it was");
    }
    committed_ = true;
    std::error_code ec;
    fs::remove_all(stage_, ec);
    // The renames reach storage too (each file's content already did, by
    // AtomicFileWriter): every directory of OUT that received a file, and
    // the parent of every directory this run created.
    std::set<fs::path> dirs;
    for (const auto& f : files) dirs.insert((out_ / f).parent_path());
    for (const auto* made : {&created_, &created})
      for (const auto& d : *made) dirs.insert(directory_of(d));
    for (const auto& d : dirs)
      if (const int err = sync_directory(d.string()))
        throw WriteError(d.string(), std::string("the output files are in place, but the fsync of this directory "
                                                 "failed, so a power loss may undo their move: ") +
                                         std::strerror(err));
  }

 private:
  static std::string strip_path(const IoError& e) {
    const std::string what = e.what();
    return what.rfind(e.path() + ": ", 0) == 0 ? what.substr(e.path().size() + 2) : what;
  }

  // A path of the staging directory as its place in OUT.
  std::string in_out(const std::string& staged) const {
    if (staged.empty()) return out_.string();
    const fs::path rel = fs::path(staged).lexically_relative(stage_);
    if (rel.empty() || *rel.begin() == "..") return staged;
    return (rel == "." ? out_ : out_ / rel).string();
  }

  // A directory of OUT that is to receive files: missing, or a directory we
  // may write into.
  void check_directory(const fs::path& dir) const {
    std::error_code ec;
    const fs::file_status st = fs::status(dir, ec);
    if (st.type() == fs::file_type::not_found) return;
    if (ec) throw IoError(dir.string(), ec.message() + "; " + out_.string() + " was left as it was");
    if (!fs::is_directory(st))
      throw IoError(dir.string(), "is not a directory; " + out_.string() + " was left as it was");
    if (::access(dir.c_str(), W_OK | X_OK) != 0)
      throw IoError(dir.string(), std::string("cannot write into it: ") + std::strerror(errno) + "; " + out_.string() +
                                      " was left as it was");
  }

  // Can the staged file `rel` take its place in OUT?
  void check_target(const fs::path& rel) const {
    fs::path dir = out_;
    check_directory(dir);
    for (const auto& part : rel.parent_path()) check_directory(dir /= part);
    const fs::path target = out_ / rel;
    std::error_code ec;
    if (fs::is_directory(fs::symlink_status(target, ec)))
      throw IoError(target.string(), "is a directory, which the new " + rel.filename().string() +
                                         " cannot replace; " + out_.string() + " was left as it was");
  }

  fs::path out_, stage_;
  std::vector<fs::path> created_;  // parents of OUT made by the constructor
  bool committed_ = false;
  bool keep_stage_ = false;  // it holds old files that could not be restored
};

void export_reference_clouds(const fs::path& out, const TouchTable& table, const RecognitionOptions& options) {
  KMeansQuantizer<float> q = make_quantizer(options);
  q.fit(table.touches.features);
  const WordIds words = assign_words(q, table.touches.features);
  fs::create_directories(out / "references");
  for (Index o = 0; o < static_cast<Index>(table.objects.size()); ++o) {
    std::vector<Index> idx;
    for (Index i = 0; i < table.size(); ++i)
      if (table.object[static_cast<std::size_t>(i)] == o) idx.push_back(i);
    Eigen::Matrix3Xd p(3, static_cast<Index>(idx.size()));
    std::vector<long long> labels;
    for (std::size_t j = 0; j < idx.size(); ++j) {
      p.col(static_cast<Index>(j)) = table.touches.positions.col(idx[j]);
      labels.push_back(words(idx[j]));
    }
    write_labeled_cloud_ply((out / "references" / (file_name_of(table.objects[static_cast<std::size_t>(o)]) + ".ply")).string(),
                            p, labels);
  }
}

/// Throws InvalidArgument naming --export-ply when an object's cloud,
/// OBJECT.ply (file_name_of: %XX triples the bytes of a non-ASCII name),
/// would have a file name longer than 255 bytes (NAME_MAX on Linux and
/// macOS): checked before the run, since moving the files into OUT fails
/// at its end and keeps nothing of it.
void check_cloud_file_names(const std::vector<std::string>& objects) {
  for (const auto& object : objects) {
    const std::string file = file_name_of(object) + ".ply";
    if (file.size() > 255)
      throw InvalidArgument("--export-ply", "object " + quote_text(object, 60) + " would be written to a file name of " +
                                                std::to_string(file.size()) + " bytes (" + quote_text(file, 60) +
                                                "), longer than a file name may be (255)");
  }
}

/// The paper's range of touches (1..20, the default): always evaluated.
constexpr int kPaperTouches = 20;

/// Throws InvalidArgument naming --touches for counts above both the
/// paper's 20 and `largest`, the most touches of a held-out exploration of
/// `dataset`: every draw of such a count uses all the touches of its
/// exploration, as at `largest` touches, so each such row repeats that
/// work (--touches 1..100000 on a small dataset ran for 33 s, and far
/// longer in a debug build, to fill rows that all mean "every touch").
void check_touch_counts(const std::vector<int>& touches, std::size_t largest, const std::string& dataset) {
  const auto limit = static_cast<int>(std::max<std::size_t>(largest, kPaperTouches));
  std::vector<int> over;
  for (int t : touches)
    if (t > limit) over.push_back(t);
  if (over.empty()) return;
  const int most = *std::max_element(over.begin(), over.end());
  const std::string counts = over.size() == 1 ? std::to_string(most) + " is"
                                              : std::to_string(over.size()) + " counts, up to " + std::to_string(most) +
                                                    ", are";
  throw InvalidArgument("--touches", counts + " more than the " + std::to_string(largest) +
                                         " touches of the largest held-out exploration of " + dataset +
                                         ": every draw would use all the touches of its exploration, as at " +
                                         std::to_string(largest) + ", repeating that work; ask for at most " +
                                         std::to_string(largest) +
                                         (largest < kPaperTouches ? " (counts up to 20, the paper's range, are allowed)" : ""));
}

/// Whether `name` is a figure's file name as the runs write them (fig_*.svg).
bool is_figure_name(const std::string& name) {
  return name.size() > 8 && name.compare(0, 4, "fig_") == 0 && name.compare(name.size() - 4, 4, ".svg") == 0;
}

/// Throws UsageError when the dataset `input` is a file the run writes into
/// OUT (a table or a figure): committing the results would replace it. A
/// link is followed: what it leads to is what would be lost.
void check_input_not_replaced(const std::string& input, const fs::path& out) {
  std::error_code ec;
  const fs::path real = fs::canonical(input, ec);
  if (ec) return;  // a missing or unreadable FILE is named by the reader
  if (!fs::equivalent(real.parent_path(), out, ec)) return;
  const std::string name = real.filename().string();
  const bool table = std::find(kTableFiles.begin(), kTableFiles.end(), name) != kTableFiles.end();
  if (table || is_figure_name(name))
    throw UsageError("--out " + quote_text(out.string()) + " would replace the dataset " + quote_text(input) +
                     " with the run's " + name + "; give another --out or move the dataset");
}

/// The outputs of an earlier run in `out` that this run did not write (its
/// figures are `figures`; `exported`: it wrote references/): figures of
/// methods it did not run and clouds it did not export, which would
/// otherwise pass for its own. Sorted; they are kept, not removed.
std::vector<std::string> stale_outputs(const fs::path& out, const std::vector<std::string>& figures, bool exported) {
  std::vector<std::string> stale;
  std::error_code ec;
  for (fs::directory_iterator it(out, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (is_figure_name(name) && std::find(figures.begin(), figures.end(), name) == figures.end()) stale.push_back(name);
    if (name == "references" && !exported) stale.push_back("references/");
  }
  std::sort(stale.begin(), stale.end());
  return stale;
}

int run_evaluate(const Args& args) {
  auto value_options = RecognitionOptions::value_options();
  for (const char* o : {"touches", "methods", "repeats", "weight-repeats", "seed", "normalization", "threads", "out",
                        "sim-seed"})
    value_options.insert(o);
  const Options opt(args, value_options, {"export-ply", "zero-weights", "inner-codebooks"});
  opt.expect_positional(0, 1, "at most one dataset FILE.csv");
  RecognitionOptions ro;
  ro.parse(opt);
  CrossValidationSettings s;
  s.touches = parse_touches(opt.string("touches", "1..20"));
  s.repeats = static_cast<int>(opt.integer("repeats", s.repeats, 1, 100000));
  s.weight_repeats = static_cast<int>(opt.integer("weight-repeats", s.weight_repeats, 1, 100000));
  s.zero_weights = opt.flag("zero-weights");
  s.inner_codebooks = opt.flag("inner-codebooks");
  s.seed = static_cast<std::uint64_t>(opt.integer("seed", static_cast<long long>(s.seed), 0));
  ro.codebook_seed = s.seed;
  s.normalization = parse_normalization(opt.choice("normalization", {"l2", "minmax", "zscore"}, "l2"));
  s.threads = static_cast<int>(opt.integer("threads", s.threads, 0, 4096));
  const std::vector<Method> named = parse_methods(opt.string("methods", "paper"));
  const fs::path out = opt.string("out", "results");
  {
    std::error_code ec;
    if (fs::exists(out, ec) && !fs::is_directory(out, ec))
      throw UsageError("--out: '" + out.string() + "' exists and is not a directory");
    // A bad OUT fails now, not after the run: its parents can be created
    // (they are removed again; the run's end creates them for good), a
    // staging directory can be made beside it, and the tables can take their
    // places. Figures are checked when the run knows them, still before OUT
    // is touched.
    StagedOutput probe(out);
    std::vector<fs::path> dirs;
    if (opt.flag("export-ply")) dirs.emplace_back("references");
    probe.check(std::vector<fs::path>(kTableFiles.begin(), kTableFiles.end()), dirs);
  }
  if (!opt.positional().empty()) check_input_not_replaced(opt.positional()[0], out);
  const auto sim_seed = static_cast<std::uint64_t>(opt.integer("sim-seed", 1, 0));
  // Nothing is simulated for a dataset FILE: a seed given with one would be
  // ignored without a word.
  if (opt.has("sim-seed") && !opt.positional().empty())
    throw UsageError("--sim-seed seeds the built-in simulation; it does not apply to a dataset FILE");

  const std::vector<std::string> needed = needed_classifiers(named);
  ro.check_trim_names(needed);
  RecognitionOptions::check_options_used(opt, needed);
  // --trim auto (one classifier variant per fraction) and lists of occupancy
  // settings (one per combination): variants chosen like the weights.
  const std::vector<Method> methods = ro.expand_choices(named, needed);
  const std::vector<std::string> built = ro.expand_choices(needed);
  // Methods the normalisation cannot fuse (products of z-scores or of
  // min-max distances) are an option error, named now: not as the
  // dataset's, after reading (or simulating) it.
  if (s.normalization != Normalization::L2) {
    const Recognizer probe(make_classifiers(ro, built), s.normalization);
    try {
      probe.check(methods);
    } catch (const InvalidArgument& e) {
      throw UsageError(std::string("--normalization ") + to_string(s.normalization) + ": " + e.reason());
    }
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::string origin;
  Dataset dataset;
  if (opt.positional().empty()) {
    dataset = builtin_dataset(sim_seed, s.threads, origin);
  } else {
    origin = opt.positional()[0];
    dataset = read_dataset_csv(origin, [](const DatasetWarning& w) {
      std::fprintf(stderr, "%s:%zu: warning: %s\n", w.file.c_str(), w.line, w.message.c_str());
    });
  }
  TouchTable table;
  {
    Progress progress("describing touches");
    table = naming_inputs(origin, [&] { return make_touch_table(dataset, ro, std::ref(progress)); });
  }
  check_orientation(needed, table, origin);
  check_positions(needed, table, ro, origin);
  if (opt.flag("export-ply")) check_cloud_file_names(table.objects);

  const ClassifierFactory factory = [ro, built] { return make_classifiers(ro, built); };

  // What the dataset's explorations do not allow names the file.
  CrossValidation<> cv =
      naming_inputs(origin, [&] { return CrossValidation<>(table, factory, make_quantizer(ro), methods, s); });
  // What the run would find only at some fold, refused before anything is
  // printed: a codebook larger than a fold's training touches, counts of
  // touches that only repeat the largest exploration's.
  naming_inputs(origin, [&] { cv.check_codebooks(); });
  check_touch_counts(s.touches, cv.largest_held_out(), origin);
  const unsigned threads = s.threads > 0 ? static_cast<unsigned>(s.threads) : std::max(1u, std::thread::hardware_concurrency());
  std::printf("iclap %s evaluate\ndataset: %s\n", ICLAP_VERSION_STRING, origin.c_str());
  std::printf("%zu objects, %zu frames, %ld touches (contact threshold %g), %d folds (one exploration of every object held out)\n",
              table.objects.size(), dataset.frames.size(), static_cast<long>(table.size()), ro.contact_threshold,
              cv.folds());
  {  // How much a held-out exploration can be matched at all (README, "How the operator moves").
    std::size_t contacts = 0, near = 0;
    for (const auto& e : exploration_overlap(dataset, 0.005, ro.contact_threshold)) {
      contacts += e.contacts;
      near += e.near;
    }
    if (contacts > 0)
      std::printf("overlap: %.1f%% of the touches lie within 5 mm of a touch of another exploration of the same object\n",
                  100.0 * static_cast<double>(near) / static_cast<double>(contacts));
  }
  std::printf("descriptor %s, k = %ld, transform %s, label scale %g m/word, %s ICP (%s; %s), %d draws per case, seed %llu, %u threads\n\n",
              ro.descriptor.c_str(), static_cast<long>(ro.k), ro.transform.c_str(), ro.label_scale, ro.scalar.c_str(),
              ro.search.c_str(), ro.icp_summary(needed).c_str(), s.repeats, static_cast<unsigned long long>(s.seed), threads);
  for (const char* h : {"height", "height_contact"})
    if (std::find(needed.begin(), needed.end(), h) != needed.end())
      std::printf("%s: %s\n\n", h, ro.height_summary(h).c_str());
  if (std::find(needed.begin(), needed.end(), "occupancy") != needed.end())
    std::printf("occupancy: %s\n\n", ro.occupancy_summary().c_str());
  std::fflush(stdout);
  CrossValidationResult r;
  {
    Progress progress("recognising test touch sets");
    r = naming_inputs(origin, [&] { return cv.run(std::ref(progress)); });
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // Table of rates.
  std::printf("recognition rate (%%) against the number of touches\n%7s", "touches");
  for (const auto& m : r.methods) std::printf(" %*s", std::max<int>(6, static_cast<int>(m.name.size())), m.name.c_str());
  std::printf("\n");
  for (std::size_t t = 0; t < r.touches.size(); ++t) {
    std::printf("%7d", r.touches[t]);
    for (const auto& m : r.methods)
      std::printf(" %*s", std::max<int>(6, static_cast<int>(m.name.size())), percent(m.rate(t)).c_str());
    std::printf("\n");
  }
  const bool any_alternatives =
      std::any_of(methods.begin(), methods.end(), [](const Method& m) { return !m.alternatives.empty(); });
  // The methods whose fusion (weights or variants) the training folds chose;
  // without one the heading would stand over nothing.
  auto chosen = [&](std::size_t i) { return methods[i].chosen_in_training() && !r.methods[i].fold_expressions.empty(); };
  bool any_chosen = false;
  for (std::size_t i = 0; i < r.methods.size(); ++i) any_chosen = any_chosen || chosen(i);
  if (any_chosen)
    std::printf(any_alternatives ? "\nfusions chosen on the training folds (fold: fusion%s):\n"
                                 : "\nfusion weights chosen on the training folds (fold: weights%s):\n",
                (std::string(s.zero_weights ? "; the grid allows 0" : "") +
                 (s.inner_codebooks ? "; every inner fold with a codebook of its own" : ""))
                    .c_str());
  for (std::size_t i = 0; i < r.methods.size(); ++i) {
    const MethodResult& m = r.methods[i];
    if (!chosen(i)) continue;
    std::printf("  %s:", m.name.c_str());
    for (std::size_t f = 0; f < m.fold_expressions.size(); ++f) std::printf(" [%zu] %s", f, m.fold_expressions[f].c_str());
    std::printf("\n");
  }
  std::printf("\ntime per recognition (one test set against all %zu objects, CPU):", r.objects.size());
  for (std::size_t c = 0; c < r.classifiers.size(); ++c) {
    const std::size_t n = r.classifier_tests[c];
    if (n == 0)
      std::printf(" %s not chosen in any fold", r.classifiers[c].c_str());
    else
      std::printf(" %s %.3f ms", r.classifiers[c].c_str(), 1e3 * r.classifier_seconds[c] / static_cast<double>(n));
    if (n != 0 && n != r.tests) std::printf(" (on %zu of %zu test sets)", n, r.tests);
    std::printf("%s", c + 1 < r.classifiers.size() ? "," : "");
  }
  std::printf("\n");
  if (r.capped_draws) std::printf("note: %zu draws asked for more touches than their exploration had and used all of them\n", r.capped_draws);

  StagedOutput staged(out);
  std::vector<std::string> figures;
  staged.write([&](const fs::path& dir) {
    write_tables(dir, r);
    write_figures(dir, r, figures);
    if (opt.flag("export-ply")) export_reference_clouds(dir, table, ro);
  });
  staged.commit();
  std::printf("\nwrote %s: %s", out.string().c_str(), Options::join(kTableFiles, ", ").c_str());
  for (const auto& f : figures) std::printf(", %s", f.c_str());
  if (opt.flag("export-ply")) std::printf(", references/*.ply");
  const std::vector<std::string> stale = stale_outputs(out, figures, opt.flag("export-ply"));
  if (!stale.empty())
    std::printf("\nnote: %s also holds %s from an earlier run, which this run did not write", out.string().c_str(),
                Options::join(stale, ", ").c_str());
  std::printf("\ntotal time %.1f s\n", secs);
  return kExitOk;
}

}  // namespace

ICLAP_COMMAND("evaluate", "run the paper's recognition experiment (main job)", kUsage, run_evaluate);

// SPDX-License-Identifier: MIT
//
// The speed/accuracy trade of iCLAP recognition, measured: the paper's
// leave-one-exploration-out experiment (5 folds, random subsets of 5, 10 and
// 20 touches of the held-out exploration) over a grid of settings, each one
// varied from a baseline, single-threaded. For each setting: recognition rate
// at 5, 10, 20 touches and the CPU time per recognition (one test touch set
// against all objects). Writes trade_study.csv and trade_study.svg (accuracy
// against time, Pareto front marked) and names the fast, balanced and
// accurate recommendations. The "fusion" rows fuse two classifiers (weights
// chosen on the training folds); their time is both classifiers' distances.
//
//   build/release/benchmarks/trade_study [DATASET.csv] [--out DIR] [--repeats N] [--only GROUP,...]
// Without a dataset, the built-in 20-object simulation (seed 1). --only runs
// the named groups (e.g. fusion) and the baseline, whose time the others are
// compared with in the same run.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "iclap/data/csv_reader.hpp"
#include "iclap/io/atomic_file.hpp"
#include "iclap/recognition/recognition.hpp"
#include "iclap/sim/builtin_objects.hpp"
#include "iclap/sim/simulator.hpp"
#include "iclap/tactile/moments.hpp"
#include "iclap/tactile/raw_pressures.hpp"
#include "iclap/tactile/tactile_sift.hpp"
#include "cli.hpp"
#include "csv_field.hpp"
#include "study_output.hpp"
#include "svg_plot.hpp"

namespace {

using namespace iclap;

/// Recognition by a pruned decision, seen as a classifier: distance 0 for
/// the decided object, 1 for the others, so the cross validation's argmin is
/// the pruned decision and its timing is the pruned cost.
template <typename Inner>
class PrunedVote final : public Classifier {
 public:
  PrunedVote(Inner inner, PruningSettings p) : inner_(std::move(inner)), pruning_(p) {}
  std::string name() const override { return inner_.name(); }
  void fit(const std::vector<TouchSet>& objects, Index vocabulary) override { inner_.fit(objects, vocabulary); }
  void distances(const TouchSet& test, Eigen::Ref<Eigen::VectorXd> out) const override {
    const PrunedDecision d = inner_.decide(test, pruning_);
    out.setOnes();
    out(d.object) = 0;
  }
  Index objects() const override { return inner_.objects(); }

 private:
  Inner inner_;
  PruningSettings pruning_;
};

/// One point of the grid.
struct Setting {
  std::string group;  ///< what was varied
  std::string name;   ///< the value
  std::string descriptor = "sift";
  Index k = 50;
  std::function<std::unique_ptr<Classifier>()> make;
  /// A second classifier and the fusion of the two (fitted weights, chosen on
  /// the training folds); empty for the single-classifier rows.
  std::function<std::unique_ptr<Classifier>()> also = nullptr;
  std::string method = "";
};

template <typename C>
void configure(C& c, int max_iterations = 50, double rel = 1e-6) {
  c.icp.termination.max_iterations = max_iterations;
  c.icp.termination.relative_tolerance = static_cast<decltype(c.icp.termination.relative_tolerance)>(rel);
}

std::vector<Setting> grid() {
  std::vector<Setting> s;
  auto iclap = [](auto tweak) {
    return [tweak]() -> std::unique_ptr<Classifier> {
      auto c = std::make_unique<IclapClassifier<float, Planar>>();
      tweak(*c);
      return c;
    };
  };
  s.push_back({"baseline", "iclap planar float auto-search label 1mm k50 sift", "sift", 50, iclap([](auto&) {})});
  for (int it : {3, 5, 10, 20})
    s.push_back({"max iterations", std::to_string(it), "sift", 50, iclap([it](auto& c) { configure(c, it); })});
  for (double rel : {1e-4, 1e-3, 1e-2})
    s.push_back({"relative tolerance", std::to_string(rel).substr(0, 6), "sift", 50,
                 iclap([rel](auto& c) { configure(c, 50, rel); })});
  s.push_back({"search", "kd-tree", "sift", 50,
               iclap([](auto& c) { c.search_settings.brute_force_max_coordinates = 0; })});
  s.push_back({"search", "brute force", "sift", 50,
               [] { return std::unique_ptr<Classifier>(std::make_unique<IclapClassifier<float, Planar, BruteForceSearch<float, 4>>>()); }});
  s.push_back({"scalar", "double", "sift", 50,
               [] { return std::unique_ptr<Classifier>(std::make_unique<IclapClassifier<double, Planar>>()); }});
  for (Index m : {200, 100, 50})
    s.push_back({"reference points", "at most " + std::to_string(m), "sift", 50,
                 iclap([m](auto& c) { c.max_reference_points = m; })});
  for (double l : {0.0001, 0.0003, 0.003, 0.01})
    s.push_back({"label scale", std::to_string(l * 1000).substr(0, 4) + " mm/word", "sift", 50,
                 iclap([l](auto& c) { c.embedding.label_scale = l; })});
  for (Index k : {10, 25, 100}) s.push_back({"codebook k", std::to_string(k), "sift", k, iclap([](auto&) {})});
  s.push_back({"descriptor", "raw pressures", "raw", 50, iclap([](auto&) {})});
  s.push_back({"descriptor", "moments", "moments", 50, iclap([](auto&) {})});
  s.push_back({"transform", "full rigid (paper)", "sift", 50,
               [] { return std::unique_ptr<Classifier>(std::make_unique<IclapClassifier<float, FullRigid>>()); }});
  s.push_back({"transform", "spatial rigid", "sift", 50,
               [] { return std::unique_ptr<Classifier>(std::make_unique<IclapClassifier<float, SpatialRigid>>()); }});
  s.push_back({"transform", "translation", "sift", 50,
               [] { return std::unique_ptr<Classifier>(std::make_unique<IclapClassifier<float, Translation>>()); }});
  s.push_back({"points", "3-D ICP (no label)", "sift", 50,
               [] { return std::unique_ptr<Classifier>(std::make_unique<IcpClassifier<float, Planar>>()); }});
  for (double ds : {0.003, 0.01, 0.03})
    s.push_back({"points", "iCLAP-N, descriptor " + std::to_string(ds * 100).substr(0, 3) + " cm/unit", "sift", 50,
                 [ds] {
                   auto c = std::make_unique<IclapNClassifier<72, float, Planar>>();
                   c->embedding.descriptor_scale = ds;
                   return std::unique_ptr<Classifier>(std::move(c));
                 }});
  // Contact patches (beyond the paper): every pressed taxel a point.
  auto patch = [](Index per_touch, double voxel, int max_iterations, float trim = 1) {
    return [=]() -> std::unique_ptr<Classifier> {
      auto c = std::make_unique<PatchClassifier<float, Planar>>();
      c->embedding.test_points_per_touch = per_touch;
      c->embedding.reference_voxel = voxel;
      configure(*c, max_iterations);
      c->icp.rejection.trim_fraction = trim;
      return c;
    };
  };
  s.push_back({"contact patch", "patch ICP, 8 pts/touch, 2 mm voxel", "sift", 50, patch(8, 0.002, 50)});
  s.push_back({"contact patch", "patch ICP, 4 pts/touch, 4 mm voxel", "sift", 50, patch(4, 0.004, 50)});
  s.push_back({"contact patch", "patch ICP, 4 pts/touch, 4 mm, max-it 10", "sift", 50, patch(4, 0.004, 10)});
  s.push_back({"contact patch", "patch ICP, 16 pts/touch, 1 mm voxel", "sift", 50, patch(16, 0.001, 50)});
  s.push_back({"contact patch", "iCLAP patch, 8 pts/touch, 2 mm voxel", "sift", 50,
               [] { return std::unique_ptr<Classifier>(std::make_unique<IclapPatchClassifier<float, Planar>>()); }});
  // Trimmed ICP (Chetverikov et al.): the motion and the distance use the
  // closest fraction of the pairs.
  for (float f : {0.7f, 0.5f, 0.3f})
    s.push_back({"trimmed", "iCLAP, closest " + std::to_string(static_cast<int>(std::lround(100 * f))) + "% of pairs",
                 "sift", 50, iclap([f](auto& c) { c.icp.rejection.trim_fraction = f; })});
  s.push_back({"trimmed", "patch ICP (default), closest 50% of pairs", "sift", 50, patch(8, 0.002, 50, 0.5f)});
  s.push_back({"trimmed", "patch ICP, 4 pts, 4 mm, max-it 10, 50%", "sift", 50, patch(4, 0.004, 10, 0.5f)});
  s.push_back({"trimmed", "patch ICP, 16 pts, 1 mm voxel, 50%", "sift", 50, patch(16, 0.001, 50, 0.5f)});
  s.push_back({"multi-start", "yaw -15,0,15", "sift", 50,
               iclap([](auto& c) { c.yaw_starts_deg = {-15, 0, 15}; })});
  s.push_back({"multi-start", "yaw -30..30 step 15", "sift", 50,
               iclap([](auto& c) { c.yaw_starts_deg = {-30, -15, 0, 15, 30}; })});
  for (auto schedule : {PruningSettings::Schedule::Bound, PruningSettings::Schedule::Halving}) {
    PruningSettings p;
    p.schedule = schedule;
    s.push_back({"pruning", schedule == PruningSettings::Schedule::Bound ? "lower bound (exact)" : "successive halving",
                 "sift", 50, [p] {
                   return std::unique_ptr<Classifier>(
                       std::make_unique<PrunedVote<IclapClassifier<float, Planar>>>(IclapClassifier<float, Planar>{}, p));
                 }});
  }
  // The exact bound also holds for trimmed ICP (the smallest per-point bounds).
  s.push_back({"pruning", "lower bound, trimmed patch ICP 50%", "sift", 50, [] {
                 PatchClassifier<float, Planar> c;
                 c.icp.rejection.trim_fraction = 0.5f;
                 return std::unique_ptr<Classifier>(
                     std::make_unique<PrunedVote<PatchClassifier<float, Planar>>>(std::move(c), PruningSettings{}));
               }});
  // No registration (beyond the paper): each touch's height and pad tilt,
  // and with the size of its contact patch (1 m of height per m of extent).
  auto height = [](double contact_scale) {
    return [contact_scale] {
      auto c = std::make_unique<HeightClassifier>();
      c->contact_scale = contact_scale;
      return std::unique_ptr<Classifier>(std::move(c));
    };
  };
  s.push_back({"no registration", "height and tilt, 1 cm/rad", "sift", 50, height(0)});
  s.push_back({"no registration", "height, tilt and contact extents", "sift", 50, height(1)});
  // Where the pad felt the object and where it did not (beyond the paper):
  // the occupancy classifier with its defaults, a finer and a coarser
  // placement grid, no placement search, and without the free points.
  auto occupancy = [](auto tweak) {
    return [tweak] {
      auto c = std::make_unique<OccupancyClassifier>();
      tweak(*c);
      return std::unique_ptr<Classifier>(std::move(c));
    };
  };
  constexpr double kDeg = 3.14159265358979323846 / 180;
  // The label counts the grid's placements (PlanarPlacements::grid) with
  // the default bounds, 10 mm and 10 degrees.
  for (const auto& [shift_step, yaw_step_deg] : {std::pair{4e-3, 5.0}, {2e-3, 2.5}, {5e-3, 10.0}}) {
    PlanarPlacements p;
    p.shift_step = shift_step;
    p.yaw_step = yaw_step_deg * kDeg;
    char label[96];
    std::snprintf(label, sizeof label, "occupancy, %ld placements (%g mm, %g deg%s)", static_cast<long>(p.grid().cols()),
                  shift_step * 1e3, yaw_step_deg, shift_step == 4e-3 ? "; default" : "");
    s.push_back({"occupancy", label, "sift", 50, occupancy([p](OccupancyClassifier& c) { c.placements = p; })});
  }
  s.push_back({"occupancy", "occupancy, no placement search", "sift", 50, occupancy([](OccupancyClassifier& c) {
                 c.placements.max_shift = 0;
                 c.placements.max_yaw = 0;
               })});
  s.push_back({"occupancy", "occupancy, no free points (conflict 0)", "sift", 50,
               occupancy([](OccupancyClassifier& c) { c.conflict_weight = 0; })});
  // Fusion (beyond the paper): either with trimmed patch ICP, the weights
  // chosen on the training folds (0 allowed); the time is both classifiers'
  // distances.
  for (const double contact_scale : {0.0, 1.0})
    for (const char* op : {"+", "*"}) {
      const std::string name = height(contact_scale)()->name();  // the classifier's own name
      s.push_back({"fusion", name + op + "patch ICP 50%", "sift", 50, height(contact_scale), patch(8, 0.002, 50, 0.5f),
                   name + op + "patch"});
    }
  for (const char* op : {"+", "*"})
    s.push_back({"fusion", std::string("occupancy") + op + "height_contact", "sift", 50,
                 occupancy([](OccupancyClassifier&) {}), height(1), std::string("occupancy") + op + "height_contact"});
  return s;
}

TouchTable touches_for(const Dataset& ds, const std::string& descriptor) {
  if (descriptor == "raw") return make_touch_table(ds, RawPressures<float>{});
  if (descriptor == "moments") return make_touch_table(ds, MomentsDescriptor<float>{});
  return make_touch_table(ds, TactileSift<float>{});
}

struct Row {
  const Setting* setting;
  double rate[3];
  double ms;
  double accuracy() const { return (rate[0] + rate[1] + rate[2]) / 3; }
};

const char* const kUsage = "usage: trade_study [DATASET.csv] [--out DIR] [--repeats N] [--only GROUP,...]\n";

}  // namespace

int main(int argc, char** argv) {
  std::string dataset_path, out;
  int repeats = 5;
  std::vector<std::string> only;  // groups to run besides the baseline (empty: all)
  try {  // usage errors exit 2 naming the option, before the study runs
    const cli::Options opt(cli::Args(argv + 1, argv + argc), {"out", "repeats", "only"});
    opt.expect_positional(0, 1, "at most one DATASET.csv");
    if (!opt.positional().empty()) dataset_path = opt.positional()[0];
    out = opt.string("out", "trade_study");
    repeats = static_cast<int>(opt.integer("repeats", repeats, 1, 1000));
    if (opt.has("only")) only = cli::Options::split(opt.string("only"), ',');
    bench::check_out_dir(out);
  } catch (const cli::HelpRequested&) {  // --help or -h
    std::printf("%s", kUsage);
    return 0;
  } catch (const cli::UsageError& e) {
    std::fprintf(stderr, "trade_study: %s\n%s", e.what(), kUsage);
    return 2;
  }
  std::vector<Setting> settings = grid();
  for (const auto& g : only)
    if (std::none_of(settings.begin(), settings.end(), [&](const Setting& s) { return s.group == g; })) {
      std::fprintf(stderr, "trade_study: --only: no group '%s' in the grid\n%s", g.c_str(), kUsage);
      return 2;
    }
  if (!only.empty())  // the baseline stays: times are compared within one run
    settings.erase(std::remove_if(settings.begin(), settings.end(),
                                  [&](const Setting& s) {
                                    return s.group != "baseline" && std::find(only.begin(), only.end(), s.group) == only.end();
                                  }),
                   settings.end());
  Dataset ds;
  try {
    if (dataset_path.empty()) {
      SimulationSettings sim;
      sim.threads = 0;
      ds = simulate_dataset(builtin_objects(), sim, 1);
      dataset_path = "built-in simulation, seed 1";
    } else {
      ds = read_dataset_csv(dataset_path);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "trade_study: %s\n", e.what());
    return 2;
  }
  std::printf("trade study on %s: 5-fold leave-one-exploration-out, %d draws per object and touch count, 1 thread\n\n",
              dataset_path.c_str(), repeats);
  std::printf("%-20s %-44s %6s %6s %6s %10s\n", "varied", "setting", "@5", "@10", "@20", "ms/recog.");
  std::map<std::string, TouchTable> tables;
  std::vector<Row> rows;
  for (const auto& s : settings) {
    if (!tables.count(s.descriptor)) tables[s.descriptor] = touches_for(ds, s.descriptor);
    CrossValidationSettings cv;
    cv.touches = {5, 10, 20};
    cv.repeats = repeats;
    cv.threads = 1;
    cv.weight_sweeps = false;
    KMeansQuantizer<float> q;
    q.settings.k = s.k;
    q.settings.seed = 1;
    cv.zero_weights = true;
    auto make = s.make, also = s.also;
    const ClassifierFactory factory = [make, also] {
      std::vector<std::unique_ptr<Classifier>> v;
      v.push_back(make());
      if (also) v.push_back(also());
      return v;
    };
    const std::string name = s.method.empty() ? make()->name() : s.method;
    CrossValidation<> run(tables.at(s.descriptor), factory, q, {parse_method(name)}, cv);
    const auto r = run.run();
    double seconds = 0;
    for (const double c : r.classifier_seconds) seconds += c;
    Row row{&s, {r.methods[0].rate(0), r.methods[0].rate(1), r.methods[0].rate(2)},
            1e3 * seconds / static_cast<double>(r.tests)};
    rows.push_back(row);
    std::printf("%-20s %-44s %5.1f%% %5.1f%% %5.1f%% %10.3f\n", s.group.c_str(), s.name.c_str(), 100 * row.rate[0],
                100 * row.rate[1], 100 * row.rate[2], row.ms);
    std::fflush(stdout);
  }

  // Pareto front on (mean rate over 5, 10, 20 touches; time).
  std::vector<bool> front(rows.size(), true);
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < rows.size(); ++j)
      if (j != i && rows[j].accuracy() >= rows[i].accuracy() && rows[j].ms <= rows[i].ms &&
          (rows[j].accuracy() > rows[i].accuracy() || rows[j].ms < rows[i].ms))
        front[i] = false;
  std::vector<std::size_t> on_front;
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (front[i]) on_front.push_back(i);
  std::sort(on_front.begin(), on_front.end(), [&](std::size_t a, std::size_t b) { return rows[a].ms < rows[b].ms; });
  // Recommendations from the front: accurate = the most accurate; fast = the
  // fastest; balanced = the cheapest whose mean rate is at least 95% of the
  // most accurate one's (the knee: most of the accuracy for a fraction of the
  // time).
  const std::size_t accurate = on_front.back();
  const std::size_t fast = on_front.front();
  std::size_t balanced = accurate;
  for (std::size_t i : on_front)
    if (rows[i].accuracy() >= 0.95 * rows[accurate].accuracy()) {
      balanced = i;
      break;
    }
  std::printf("\nPareto front (mean rate over 5/10/20 touches against time):\n");
  for (std::size_t i : on_front)
    std::printf("  %-20s %-44s mean %5.1f%%  %8.3f ms\n", rows[i].setting->group.c_str(), rows[i].setting->name.c_str(),
                100 * rows[i].accuracy(), rows[i].ms);
  auto describe = [&](const char* label, std::size_t i) {
    std::printf("%-9s %s: %s (mean %.1f%%, %.3f ms per recognition)\n", label, rows[i].setting->group.c_str(),
                rows[i].setting->name.c_str(), 100 * rows[i].accuracy(), rows[i].ms);
  };
  std::printf("\nrecommended (from the front):\n");
  describe("fast", fast);
  describe("balanced", balanced);
  describe("accurate", accurate);

  cli::Plot p;
  p.title = "iCLAP recognition: accuracy against time per recognition";
  p.x_label = "CPU time per recognition (ms, one test set against all objects, log scale)";
  p.y_label = "mean rate at 5/10/20 touches";
  p.x_log = true;
  p.y_auto = true;
  cli::PlotSeries all, pf;
  all.name = "settings";
  all.markers_only = true;
  pf.name = "Pareto front";
  pf.highlight = true;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    all.x.push_back(rows[i].ms);
    all.y.push_back(rows[i].accuracy());
    all.point_labels.push_back(front[i] ? rows[i].setting->name : "");
  }
  for (std::size_t i : on_front) {
    pf.x.push_back(rows[i].ms);
    pf.y.push_back(rows[i].accuracy());
  }
  p.series = {all, pf};
  // The plot is rendered before either file is written: a throw there
  // leaves no CSV behind without its SVG.
  const std::string svg_text = cli::render_svg(p);
  try {
    std::filesystem::create_directories(out);
    {
      AtomicFileWriter w(out + "/trade_study.csv");
      w.stream() << "group,setting,rate5,rate10,rate20,mean_rate,ms_per_recognition,pareto\n";
      for (std::size_t i = 0; i < rows.size(); ++i)
        w.stream() << bench::csv_field(rows[i].setting->group) << "," << bench::csv_field(rows[i].setting->name) << ","
                   << rows[i].rate[0] << "," << rows[i].rate[1] << "," << rows[i].rate[2] << "," << rows[i].accuracy()
                   << "," << rows[i].ms << "," << (front[i] ? 1 : 0) << "\n";
      w.commit();
    }
    AtomicFileWriter svg(out + "/trade_study.svg");
    svg.stream() << svg_text;
    svg.commit();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "trade_study: %s\n", e.what());
    return 1;
  }
  std::printf("\nwrote %s/trade_study.csv and %s/trade_study.svg\n", out.c_str(), out.c_str());
  return 0;
}

// SPDX-License-Identifier: MIT
//
// How well the touches of the simulated explorations could recognise the
// objects if the references were the objects' whole shapes rather than what
// four training explorations touched: an upper bound on what better
// coverage of the references can give, measured with the library's own
// classifier and protocol.
//
// Why: recognition on the simulated data stays short of the 95% goal at 20
// touches, and the README blames coverage (a held-out exploration mostly
// touches surface the training explorations never touched). If that is the
// limit, the same test touches against the true surfaces should do much
// better. This program runs the paper's leave-one-exploration-out cross
// validation (CrossValidation with the folds, draws, seed, descriptor and
// codebook of `iclap evaluate`'s defaults, so the `occupancy` column is
// `iclap evaluate --methods occupancy --touches 1,5,10,20`) with three
// classifiers:
//
//   occupancy        OccupancyClassifier fitted on the training touches (the
//                    normal method, for comparison in the same run);
//   shape_occupancy  the same classifier, conflict weight 0.3, fitted with
//                    fit_evidence on points sampled every 0.5 mm on the
//                    surface of each object's mesh (sample_surface), with no
//                    free points; it ignores the training touches (so it is
//                    fitted once and serves every fold). A test
//                    touch's contact points are charged their distance to
//                    the surface, and its unpressed taxels a conflict where
//                    they lie within free_radius (2 mm) of the surface;
//   shape_contact    the same with conflict weight 0: only where the pressed
//                    taxels lie.
//
// Frames: the simulator puts each object down before each exploration with a
// random shift within 10 mm and a turn within +-10 degrees about the
// object's origin, and the test touches are in that world frame; the mesh
// samples are in the object's frame (its nominal placement: centred on
// x = y = 0, resting on z = 0). The classifier's default placement grid
// (shifts within 10 mm in 4 mm steps, turns within +-10 degrees in 5 degree
// steps) covers that motion up to the grid's steps; the shapes' evidence
// turns about the object's origin (OccupancyEvidence::turn_centre = 0), as
// the simulator turns them. (The classifier's default axis, the centroid of
// the evidence, lies up to 55 mm from the origin on the built-in objects; a
// turn about it needs shifts beyond the grid and cost this bound 0.8 to
// 2.3 points on the built-in objects in a trial.)
//
// This is a study of the simulated data, where the true shapes are known
// (they are the meshes the simulator touched); it is not a method a user
// without models of the objects can run. A user WITH CAD models can do the
// same: sample_surface each model (in the table frame the test touches are
// expressed in, up to the placement grid) into OccupancyEvidence::occupied
// and call OccupancyClassifier::fit_evidence.
//
//   build/release/benchmarks/shape_bound [DATASET.csv] [--objects DIR] [--out DIR]
//                                        [--touches LIST] [--repeats N] [--threads N]
//
// Without a dataset: the built-in 20-object simulation (seed 1, as
// trade_study and `iclap evaluate` use), shapes from builtin_objects(). With
// a dataset simulated from the built-in objects (e.g. with other settings),
// the shapes are again builtin_objects(); with one simulated from meshes,
// --objects DIR loads them as `iclap simulate --objects DIR` did
// (load_mesh_objects, units from DIR/meshes.json), e.g.
//
//   iclap simulate --objects ../shared/data/meshes --out meshes.csv
//   shape_bound meshes.csv --objects ../shared/data/meshes --threads 1
//
// Every object of the dataset must have a shape of the same name. Writes
// DIR/shape_bound.csv (method,touches,rate; rate a fraction, as in
// `iclap evaluate`'s results.csv); --out defaults to shape_bound.
// --touches (as `iclap evaluate` reads it: 1,5,10,20 or 1..20) defaults to
// 1,5,10,20 and --repeats to 10 (the draws per fold,
// object and number of touches); --threads 0 (the default) uses every core,
// and the results do not depend on it.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "iclap/data/csv_reader.hpp"
#include "iclap/io/atomic_file.hpp"
#include "iclap/mesh/sampling.hpp"
#include "iclap/recognition/occupancy_classifier.hpp"
#include "iclap/recognition/recognition.hpp"
#include "iclap/sim/builtin_objects.hpp"
#include "iclap/sim/objects.hpp"
#include "iclap/sim/simulator.hpp"
#include "iclap/tactile/tactile_sift.hpp"
#include "cli.hpp"
#include "csv_field.hpp"
#include "study_output.hpp"
#include "touch_counts.hpp"

namespace {

using namespace iclap;

/// Surface sample spacing, metres: half the occupancy field's 1 mm voxel.
constexpr double kSpacing = 0.5e-3;

/// An OccupancyClassifier whose references are fixed evidence (the objects'
/// sampled surfaces, in table-object order) instead of the training touches.
/// The evidence is the same in every fold, so the classifier is fitted once
/// (fit_evidence) and shared by the wrappers the factory makes: fit() only
/// checks that the touches are of as many objects, and ignores them; the
/// rest is the fitted classifier's (const and thread-safe).
class ShapeOccupancy final : public Classifier {
 public:
  explicit ShapeOccupancy(std::shared_ptr<const OccupancyClassifier> fitted) : fitted_(std::move(fitted)) {}
  std::string name() const override { return fitted_->name(); }
  void fit(const std::vector<TouchSet>& objects, Index /*vocabulary*/) override {
    if (static_cast<Index>(objects.size()) != fitted_->objects())
      throw InvalidArgument("objects", std::to_string(objects.size()) + " objects to fit, but " +
                                           std::to_string(fitted_->objects()) + " shapes");
  }
  void distances(const TouchSet& test, Eigen::Ref<Eigen::VectorXd> out) const override { fitted_->distances(test, out); }
  Index objects() const override { return fitted_->objects(); }
  std::shared_ptr<const PreparedPool> prepare_pool(const TouchSet& pool) const override {
    return fitted_->prepare_pool(pool);
  }
  void pool_distances(const TouchSet& pool, const PreparedPool* prepared, const std::vector<Index>& subset,
                      Eigen::Ref<Eigen::VectorXd> out) const override {
    fitted_->pool_distances(pool, prepared, subset, out);
  }

 private:
  std::shared_ptr<const OccupancyClassifier> fitted_;
};

/// OccupancyClassifier `label` with conflict weight `conflict_weight` (the
/// other settings the defaults, as `iclap evaluate` uses them), fitted on
/// `evidence`.
std::shared_ptr<const OccupancyClassifier> fit_shapes(const std::string& label, double conflict_weight,
                                                      const std::vector<OccupancyEvidence>& evidence) {
  auto c = std::make_shared<OccupancyClassifier>();
  c->label = label;
  c->conflict_weight = conflict_weight;
  c->fit_evidence(evidence);
  return c;
}

/// Progress of one stage on stderr: a live line on a terminal, otherwise a
/// line every 10% (so logs of long runs show it too).
class StageProgress {
 public:
  explicit StageProgress(std::string label) : label_(label), tty_(isatty(2) != 0), line_(std::move(label)) {}
  void operator()(std::size_t done, std::size_t total) {
    if (tty_) {
      line_(done, total);
      return;
    }
    const auto decile = static_cast<int>(total ? 10 * done / total : 10);
    if (decile == last_) return;
    last_ = decile;
    std::fprintf(stderr, "shape_bound: %s: %d%%\n", label_.c_str(), 10 * decile);
  }

 private:
  std::string label_;
  bool tty_;
  cli::Progress line_;
  int last_ = -1;
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

const char* const kUsage =
    "usage: shape_bound [DATASET.csv] [--objects DIR] [--out DIR] [--touches LIST] [--repeats N] [--threads N]\n";

int run(int argc, char** argv) {
  const auto t_start = std::chrono::steady_clock::now();
  // Options: usage errors exit 2 naming the option.
  std::string dataset_path, objects_dir, out;
  CrossValidationSettings cv;
  try {
    const cli::Options opt(cli::Args(argv + 1, argv + argc), {"objects", "out", "touches", "repeats", "threads"});
    opt.expect_positional(0, 1, "at most one DATASET.csv");
    if (!opt.positional().empty()) dataset_path = opt.positional()[0];
    objects_dir = opt.string("objects");
    if (!objects_dir.empty() && dataset_path.empty())
      throw cli::UsageError("--objects: needs the DATASET.csv simulated from those meshes (without a dataset the "
                            "built-in objects are simulated and used)");
    out = opt.string("out", "shape_bound");
    cv.touches = cli::parse_touches(opt.string("touches", "1,5,10,20"));
    cv.repeats = static_cast<int>(opt.integer("repeats", 10, 1, 100000));
    cv.threads = static_cast<int>(opt.integer("threads", 0, 0, 4096));
    bench::check_out_dir(out);
  } catch (const cli::HelpRequested&) {  // --help or -h
    std::printf("%s", kUsage);
    return 0;
  } catch (const cli::UsageError& e) {
    std::fprintf(stderr, "shape_bound: %s\n%s", e.what(), kUsage);
    return 2;
  }
  cv.seed = 1;  // `iclap evaluate`'s default draws
  cv.weight_sweeps = false;

  // Inputs: unreadable or mismatched ones exit 2 naming the file or object.
  Dataset ds;
  std::vector<SimObject> shapes;
  std::string origin, shape_origin;
  try {
    if (dataset_path.empty()) {
      std::fprintf(stderr, "shape_bound: simulating the built-in objects (seed 1)\n");
      SimulationSettings sim;
      sim.threads = static_cast<unsigned>(cv.threads);
      StageProgress progress("simulating");
      ds = simulate_dataset(builtin_objects(), sim, 1, std::ref(progress));
      origin = "built-in simulation, seed 1";
    } else {
      ds = read_dataset_csv(dataset_path, [](const DatasetWarning& w) {
        std::fprintf(stderr, "%s:%zu: warning: %s\n", w.file.c_str(), w.line, w.message.c_str());
      });
      origin = dataset_path;
    }
    if (objects_dir.empty()) {
      shapes = builtin_objects();
      shape_origin = "the built-in objects";
    } else {
      std::fprintf(stderr, "shape_bound: loading the meshes of %s\n", objects_dir.c_str());
      StageProgress progress("loading meshes");
      shapes = load_mesh_objects(objects_dir, std::nullopt, std::ref(progress));
      shape_origin = objects_dir;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "shape_bound: %s\n", e.what());
    return 2;
  }

  const TouchTable table = make_touch_table(ds, TactileSift<float>{});
  // One shape per object of the table, in its order.
  std::map<std::string, const SimObject*> by_name;
  for (const auto& s : shapes) by_name[s.name] = &s;
  std::vector<const SimObject*> shape_of;
  for (const auto& name : table.objects) {
    const auto it = by_name.find(name);
    if (it == by_name.end()) {
      std::string have;
      for (const auto& s : shapes) have += (have.empty() ? "" : ", ") + s.name;
      std::fprintf(stderr, "shape_bound: %s: object '%s' has no shape in %s (%s)%s\n", origin.c_str(), name.c_str(),
                   shape_origin.c_str(), have.c_str(),
                   objects_dir.empty() ? "; give the meshes it was simulated from with --objects DIR" : "");
      return 2;
    }
    shape_of.push_back(it->second);
  }

  // The true surfaces, sampled once; every fold fits the same evidence.
  std::fprintf(stderr, "shape_bound: sampling %zu surfaces every %g mm\n", shape_of.size(), kSpacing * 1e3);
  const auto t_sample = std::chrono::steady_clock::now();
  std::vector<OccupancyEvidence> evidence(shape_of.size());
  std::vector<Index> sample_counts;
  for (std::size_t j = 0; j < shape_of.size(); ++j) {
    try {
      evidence[j].occupied = sample_surface(shape_of[j]->shape.mesh(), kSpacing);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "shape_bound: shape of '%s': %s\n", shape_of[j]->name.c_str(), e.what());
      return 2;
    }
    evidence[j].turn_centre = Eigen::Vector2d::Zero();  // the simulator turns the object about its origin
    sample_counts.push_back(evidence[j].occupied.cols());
  }
  const double sample_seconds = seconds_since(t_sample);
  std::fprintf(stderr, "shape_bound: fitting the distance fields of the shapes\n");
  const auto t_fit = std::chrono::steady_clock::now();
  std::shared_ptr<const OccupancyClassifier> shape_occupancy, shape_contact;
  double fit_seconds = 0;
  try {
    shape_occupancy = fit_shapes("shape_occupancy", 0.3, evidence);
    fit_seconds = seconds_since(t_fit);
    shape_contact = fit_shapes("shape_contact", 0.0, evidence);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "shape_bound: the shapes of %s: %s\n", shape_origin.c_str(), e.what());
    return 2;
  }
  std::vector<Index> sorted = sample_counts;
  std::sort(sorted.begin(), sorted.end());

  const std::vector<std::string> names = {"occupancy", "shape_occupancy", "shape_contact"};
  std::vector<Method> methods;
  for (const auto& n : names) methods.push_back(parse_method(n));
  const ClassifierFactory factory = [shape_occupancy, shape_contact] {
    std::vector<std::unique_ptr<Classifier>> v;
    v.push_back(std::make_unique<OccupancyClassifier>());
    v.push_back(std::make_unique<ShapeOccupancy>(shape_occupancy));
    v.push_back(std::make_unique<ShapeOccupancy>(shape_contact));
    return v;
  };
  KMeansQuantizer<float> quantizer;  // `iclap evaluate`'s codebook (k 50, seed 1); no classifier here uses it
  quantizer.settings.k = 50;
  quantizer.settings.seed = 1;

  CrossValidationResult r;
  try {
    CrossValidation<> run(table, factory, quantizer, methods, cv);
    std::printf("shape bound on %s: %zu objects, %ld touches, %d folds (leave one exploration out), %d draws per "
                "fold, object and number of touches, seed 1\n",
                origin.c_str(), table.objects.size(), static_cast<long>(table.size()), run.folds(), cv.repeats);
    std::printf("shapes: %s, sampled every %g mm: %ld to %ld points per object (median %ld), %.1f s; the fields %.1f s "
                "to fit\n",
                shape_origin.c_str(), kSpacing * 1e3, static_cast<long>(sorted.front()), static_cast<long>(sorted.back()),
                static_cast<long>(sorted[sorted.size() / 2]), sample_seconds, fit_seconds);
    std::printf("\n");
    std::fflush(stdout);
    std::fprintf(stderr, "shape_bound: cross validation\n");
    StageProgress progress("cross validation");
    r = run.run(std::ref(progress));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "shape_bound: %s: %s\n", origin.c_str(), e.what());
    return 2;
  }

  std::printf("recognition rate (%%) against the number of touches\n%7s", "touches");
  for (const auto& m : r.methods) std::printf(" %16s", m.name.c_str());
  std::printf("\n");
  for (std::size_t t = 0; t < r.touches.size(); ++t) {
    std::printf("%7d", r.touches[t]);
    for (const auto& m : r.methods) std::printf(" %16.1f", 100 * m.rate(t));
    std::printf("\n");
  }
  std::printf("\ntime per recognition (one test set against all %zu objects, CPU, ms):", r.objects.size());
  for (std::size_t c = 0; c < r.classifiers.size(); ++c)
    std::printf(" %s %.3f", r.classifiers[c].c_str(),
                r.classifier_tests[c] ? 1e3 * r.classifier_seconds[c] / static_cast<double>(r.classifier_tests[c]) : 0.0);
  std::printf("\n");

  try {
    std::filesystem::create_directories(out);
    AtomicFileWriter w(out + "/shape_bound.csv");
    w.stream() << "method,touches,rate\n";
    for (const auto& m : r.methods)
      for (std::size_t t = 0; t < r.touches.size(); ++t)
        w.stream() << bench::csv_field(m.name) << "," << r.touches[t] << "," << format_value(m.rate(t)) << "\n";
    w.commit();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "shape_bound: %s\n", e.what());
    return 1;
  }
  std::printf("wrote %s/shape_bound.csv; %.0f s in all\n", out.c_str(), seconds_since(t_start));
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return run(argc, argv); }

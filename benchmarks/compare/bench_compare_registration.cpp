// SPDX-License-Identifier: MIT
// iclap against PCL's pcl::IterativeClosestPoint and Open3D's
// open3d::pipelines::registration::RegistrationICP (point-to-point) on issue
// 2's target case: 3-D, a 400-point model, a 100-point test, 50 forced
// iterations, no correspondence rejection, one thread. Also the target (b)
// baseline, nanoflann's bare queries at the ICP's query positions, so that
// every ratio of benchmarks/compare/RESULTS.md comes from one run of this
// binary, which prints them at the end (medians with --benchmark_repetitions).
//
// Run (see RESULTS.md):
//   OMP_NUM_THREADS=1 bench_compare_registration --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true   (one line)
//
// What each timed loop contains:
//   iclap/<scalar>             Icp::align; the reference (centring + kd-tree)
//                              is built once outside, as recognition does.
//   iclap_with_build/<scalar>  the same plus building the reference.
//   pcl/prebuilt_tree          IterativeClosestPoint::align with the target's
//                              kd-tree built outside and passed with
//                              setSearchMethodTarget(tree, true) (no rebuild).
//   pcl/default                align as commonly written: PCL rebuilds the
//                              target kd-tree inside every align().
//   open3d                     RegistrationICP: it copies the source and builds
//                              the target's kd-tree inside every call (the API
//                              offers no way to pass a prebuilt one).
//   build/<library>            the reference / kd-tree build alone, to see how
//                              much of the above it is.
//   nanoflann_51x100q/<scalar> the 51 rounds of 100 nanoflann queries that the
//                              50 iterations make, at their exact positions.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>
#include <pcl/search/kdtree.h>

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#include <open3d/utility/Logging.h>

#include "compare/nanoflann_baseline.hpp"
#include "compare/registration_problem.hpp"
#include "iclap/registration/registration.hpp"

using namespace iclap;

namespace {

constexpr int kIterations = 50;
constexpr Index kModelPoints = 400;
constexpr Index kTestPoints = 100;
/// No rejection anywhere: every pair is far closer than this (metres).
constexpr double kNoRejection = 1e10;

const bench::RegistrationProblem& problem() {
  static const bench::RegistrationProblem p = bench::make_problem<FullRigid>(3, kModelPoints, kTestPoints, 2018);
  return p;
}

// --- iclap -------------------------------------------------------------------

template <typename Scalar>
struct IclapCase {
  Cloud<Scalar, 3> model = problem().model.cast<Scalar>();
  Cloud<Scalar, 3> test = problem().test.cast<Scalar>();
  ReferenceCloud<Scalar, 3> reference{model};
  Icp<Scalar, 3> icp = bench::forced_icp<Scalar, 3>(kIterations);
  IcpWorkspace<Scalar, 3> workspace;
};

template <typename Scalar>
IclapCase<Scalar>& iclap_case() {
  static IclapCase<Scalar> c;
  return c;
}

template <typename Scalar>
void BM_Iclap(benchmark::State& state) {
  auto& c = iclap_case<Scalar>();
  RegistrationResult<Scalar, 3> r;
  for (auto _ : state) {
    r = c.icp.align(c.reference, c.test, nullptr, c.workspace);
    benchmark::DoNotOptimize(r);
  }
  state.counters["iters"] = r.iterations;
}

template <typename Scalar>
void BM_IclapWithBuild(benchmark::State& state) {
  auto& c = iclap_case<Scalar>();
  RegistrationResult<Scalar, 3> r;
  for (auto _ : state) {
    const ReferenceCloud<Scalar, 3> reference(c.model);
    r = c.icp.align(reference, c.test, nullptr, c.workspace);
    benchmark::DoNotOptimize(r);
  }
  state.counters["iters"] = r.iterations;
}

template <typename Scalar>
void BM_IclapBuild(benchmark::State& state) {
  auto& c = iclap_case<Scalar>();
  for (auto _ : state) {
    const ReferenceCloud<Scalar, 3> reference(c.model);
    benchmark::DoNotOptimize(reference.working_points().data());
  }
}

template <typename Scalar>
void BM_Nanoflann(benchmark::State& state) {
  auto& c = iclap_case<Scalar>();
  static const bench::RawNanoflann<Scalar, 3> raw(c.reference.working_points());
  static const auto rounds = bench::icp_query_rounds(c.reference, c.test, kIterations);
  for (auto _ : state)
    benchmark::DoNotOptimize(bench::run_rounds(rounds, [](const Scalar* q) { return raw.nearest(q); }));
}

// --- PCL ---------------------------------------------------------------------

using PclPoint = pcl::PointXYZ;
using PclCloud = pcl::PointCloud<PclPoint>;

PclCloud::Ptr to_pcl(const Eigen::MatrixXd& m) {
  PclCloud::Ptr c(new PclCloud);
  c->reserve(static_cast<std::size_t>(m.cols()));
  for (Index j = 0; j < m.cols(); ++j)
    c->push_back(PclPoint(static_cast<float>(m(0, j)), static_cast<float>(m(1, j)), static_cast<float>(m(2, j))));
  return c;
}

/// PCL's ICP with its iteration counter exposed (a protected member).
class PclIcp : public pcl::IterativeClosestPoint<PclPoint, PclPoint> {
 public:
  /// 50 forced iterations, no rejection. PCL stops on the first of: the
  /// iteration cap; a transform increment with cos(angle) >= 1 - eps and
  /// |t|^2 <= eps (eps = -1: never); |dMSE| < absolute MSE threshold or
  /// |dMSE| / MSE < euclidean fitness epsilon (negative: never).
  PclIcp() {
    setMaximumIterations(kIterations);
    setMaxCorrespondenceDistance(kNoRejection);
    setTransformationEpsilon(-1.0);
    setEuclideanFitnessEpsilon(-std::numeric_limits<double>::infinity());
    getConvergeCriteria()->setAbsoluteMSE(-1.0);
  }
  int iterations() const { return nr_iterations_; }
  bool stopped_by_iteration_cap() {
    return getConvergeCriteria()->getConvergenceState() ==
           pcl::registration::DefaultConvergenceCriteria<float>::CONVERGENCE_CRITERIA_ITERATIONS;
  }
};

struct PclCase {
  PclCloud::Ptr model = to_pcl(problem().model);
  PclCloud::Ptr test = to_pcl(problem().test);
  pcl::search::KdTree<PclPoint>::Ptr tree{new pcl::search::KdTree<PclPoint>};
  PclIcp prebuilt, rebuilding;
  PclCloud output;
  PclCase() {
    tree->setInputCloud(model);
    prebuilt.setSearchMethodTarget(tree, true);  // true: never rebuild it
    prebuilt.setInputSource(test);
    prebuilt.setInputTarget(model);
    rebuilding.setInputSource(test);
    rebuilding.setInputTarget(model);
  }
};

PclCase& pcl_case() {
  static PclCase c;
  return c;
}

template <bool Prebuilt>
void BM_Pcl(benchmark::State& state) {
  auto& c = pcl_case();
  PclIcp& icp = Prebuilt ? c.prebuilt : c.rebuilding;
  for (auto _ : state) {
    icp.align(c.output);
    benchmark::DoNotOptimize(c.output.points.data());
  }
  state.counters["iters"] = icp.iterations();
}

void BM_PclBuild(benchmark::State& state) {
  auto& c = pcl_case();
  for (auto _ : state) {
    pcl::search::KdTree<PclPoint> tree;
    tree.setInputCloud(c.model);
    benchmark::DoNotOptimize(&tree);
  }
}

// --- Open3D ------------------------------------------------------------------

namespace o3d_reg = open3d::pipelines::registration;

std::shared_ptr<open3d::geometry::PointCloud> to_open3d(const Eigen::MatrixXd& m) {
  auto c = std::make_shared<open3d::geometry::PointCloud>();
  for (Index j = 0; j < m.cols(); ++j) c->points_.emplace_back(m(0, j), m(1, j), m(2, j));
  return c;
}

struct Open3dCase {
  std::shared_ptr<open3d::geometry::PointCloud> model = to_open3d(problem().model);
  std::shared_ptr<open3d::geometry::PointCloud> test = to_open3d(problem().test);
  /// Relative fitness and RMSE changes of 0: Open3D breaks only when both
  /// |change| < 0, which never holds, so exactly 50 iterations run.
  o3d_reg::ICPConvergenceCriteria criteria{0.0, 0.0, kIterations};
  o3d_reg::RegistrationResult run() const {
    return o3d_reg::RegistrationICP(*test, *model, kNoRejection, Eigen::Matrix4d::Identity(),
                                    o3d_reg::TransformationEstimationPointToPoint(false), criteria);
  }
};

const Open3dCase& open3d_case() {
  static const Open3dCase c;
  return c;
}

void BM_Open3d(benchmark::State& state) {
  const auto& c = open3d_case();
  for (auto _ : state) {
    auto r = c.run();
    benchmark::DoNotOptimize(r.transformation_.data());
  }
}

void BM_Open3dBuild(benchmark::State& state) {
  const auto& c = open3d_case();
  for (auto _ : state) {
    open3d::geometry::KDTreeFlann tree(*c.model);
    benchmark::DoNotOptimize(&tree);
  }
}

// --- agreement check -----------------------------------------------------------

double max_abs_difference(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) { return (a - b).cwiseAbs().maxCoeff(); }

template <typename Scalar>
Eigen::Matrix4d iclap_transform(int& iterations, double& rmse) {
  auto& c = iclap_case<Scalar>();
  const auto r = c.icp.align(c.reference, c.test);
  iterations = r.iterations;
  rmse = static_cast<double>(r.rmse);
  return r.T_model_test.matrix().template cast<double>();
}

/// Runs each library once on the inputs, prints the transforms' differences,
/// iteration counts and RMSEs; returns false if they disagree.
bool check_agreement() {
  const auto& p = problem();
  Eigen::Matrix4d truth = Eigen::Matrix4d::Identity();
  truth.topLeftCorner<3, 3>() = p.R;
  truth.topRightCorner<3, 1>() = p.t;

  int it_f = 0, it_d = 0;
  double rmse_f = 0, rmse_d = 0;
  const Eigen::Matrix4d T_f = iclap_transform<float>(it_f, rmse_f);
  const Eigen::Matrix4d T_d = iclap_transform<double>(it_d, rmse_d);

  auto& pc = pcl_case();
  pc.prebuilt.align(pc.output);
  const Eigen::Matrix4d T_pcl = pc.prebuilt.getFinalTransformation().cast<double>();
  const bool pcl_cap = pc.prebuilt.stopped_by_iteration_cap();
  const int it_pcl = pc.prebuilt.iterations();
  pc.rebuilding.align(pc.output);
  const Eigen::Matrix4d T_pcl_default = pc.rebuilding.getFinalTransformation().cast<double>();

  // Open3D reports no iteration count: count its per-iteration debug lines.
  int it_o3d = 0;
  auto& logger = open3d::utility::Logger::GetInstance();
  logger.SetPrintFunction([&it_o3d](const std::string& line) {
    if (line.find("ICP Iteration #") != std::string::npos) ++it_o3d;
  });
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Debug);
  const auto o3d = open3d_case().run();
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Warning);
  logger.ResetPrintFunction();
  const Eigen::Matrix4d T_o3d = o3d.transformation_;

  std::printf("Inputs: 3-D, model %ld points, test %ld points, 50 forced iterations, no rejection\n",
              static_cast<long>(kModelPoints), static_cast<long>(kTestPoints));
  std::printf("Iterations: iclap float %d, iclap double %d, PCL %d (stopped by the cap: %s), Open3D %d\n", it_f,
              it_d, it_pcl, pcl_cap ? "yes" : "no", it_o3d);
  std::printf("Final RMSE (mm): iclap float %.6f, iclap double %.6f, Open3D %.6f\n", 1e3 * rmse_f, 1e3 * rmse_d,
              1e3 * o3d.inlier_rmse_);
  std::printf("Max |T_a - T_b| over the 4x4 entries:\n");
  std::printf("  iclap double vs Open3D       %.3g\n", max_abs_difference(T_d, T_o3d));
  std::printf("  iclap float  vs iclap double %.3g\n", max_abs_difference(T_f, T_d));
  std::printf("  iclap float  vs PCL          %.3g\n", max_abs_difference(T_f, T_pcl));
  std::printf("  iclap double vs PCL          %.3g\n", max_abs_difference(T_d, T_pcl));
  std::printf("  PCL prebuilt vs PCL default  %.3g\n", max_abs_difference(T_pcl, T_pcl_default));
  std::printf("  iclap double vs ground truth %.3g (0.3 mm noise on both clouds)\n", max_abs_difference(T_d, truth));
  const double tolerance = 1e-4;  // float arithmetic in PCL and iclap<float>, 10 cm object
  const bool agree = it_f == kIterations && it_d == kIterations && it_pcl == kIterations && pcl_cap &&
                     it_o3d == kIterations && max_abs_difference(T_d, T_o3d) < tolerance &&
                     max_abs_difference(T_f, T_pcl) < tolerance && max_abs_difference(T_d, T_pcl) < tolerance;
  std::printf("Agreement (50 iterations everywhere, transforms within %.0e): %s\n\n", tolerance,
              agree ? "yes" : "NO");
  return agree;
}

// --- ratios --------------------------------------------------------------------

/// Console output as usual, plus the per-benchmark time kept for the ratio
/// table: the median when repetitions are run, else the single run.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  /// Colours only on a terminal (a custom reporter does not see
  /// --benchmark_color).
  RatioReporter() : ConsoleReporter(isatty(fileno(stdout)) ? OO_Defaults : OO_Tabular) {}

  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& r : runs) {
      const std::string name = r.run_name.function_name;
      const bool median = r.run_type == Run::RT_Aggregate && r.aggregate_name == "median";
      const bool single = r.run_type == Run::RT_Iteration && r.repetitions <= 1;
      if (median || single) {
        cpu_us_[name] = to_us(r.GetAdjustedCPUTime(), r.time_unit);
        real_us_[name] = to_us(r.GetAdjustedRealTime(), r.time_unit);
      }
    }
  }

  void print_ratios() const {
    std::printf("\nRatios (CPU time of the median run; wall time in brackets):\n");
    std::printf("(a) speed-up of iclap, time(other) / time(iclap), target >= 10 (PCL), >= 3.5 (Open3D)\n");
    ratio("PCL, tree prebuilt     / iclap float", "pcl/prebuilt_tree", "iclap/float");
    ratio("PCL, tree prebuilt     / iclap double", "pcl/prebuilt_tree", "iclap/double");
    ratio("PCL, default (rebuild) / iclap float with build", "pcl/default", "iclap_with_build/float");
    ratio("Open3D (builds inside) / iclap double", "open3d", "iclap/double");
    ratio("Open3D (builds inside) / iclap float", "open3d", "iclap/float");
    ratio("Open3D (builds inside) / iclap double with build", "open3d", "iclap_with_build/double");
    std::printf("(b) time(ICP) / 50 over time(100 nanoflann queries), target <= 1.2 (floor 51/50 = 1.02)\n");
    ratio("iclap float ", "iclap/float", "nanoflann_51x100q/float", 51.0 / 50.0);
    ratio("iclap double", "iclap/double", "nanoflann_51x100q/double", 51.0 / 50.0);
    std::printf("Build share: ");
    share("Open3D kd-tree", "build/open3d", "open3d");
    share("PCL kd-tree", "build/pcl", "pcl/default");
    share("iclap reference", "build/iclap_double", "iclap_with_build/double");
    std::printf("\n");
  }

 private:
  static double to_us(double t, benchmark::TimeUnit unit) {
    switch (unit) {
      case benchmark::kNanosecond: return t * 1e-3;
      case benchmark::kMicrosecond: return t;
      case benchmark::kMillisecond: return t * 1e3;
      case benchmark::kSecond: return t * 1e6;
    }
    return t;
  }
  bool has(const std::string& a) const { return cpu_us_.count(a) > 0; }
  /// time(a) / time(b) * scale ("(b)": the ICP's 51 matchings over 50 iterations).
  void ratio(const char* label, const std::string& a, const std::string& b, double scale = 1.0) const {
    if (!has(a) || !has(b)) return;
    std::printf("  %-50s %7.2f  [%.2f]   (%.1f us vs %.1f us)\n", label, cpu_us_.at(a) / cpu_us_.at(b) * scale,
                real_us_.at(a) / real_us_.at(b) * scale, cpu_us_.at(a), cpu_us_.at(b));
  }
  void share(const char* label, const std::string& part, const std::string& whole) const {
    if (!has(part) || !has(whole)) return;
    std::printf("%s %.1f%%;  ", label, 100.0 * cpu_us_.at(part) / cpu_us_.at(whole));
  }
  std::map<std::string, double> cpu_us_, real_us_;
};

int thread_count() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("Threads:", 0) == 0) return std::stoi(line.substr(8));
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  omp_set_num_threads(1);  // Open3D's correspondence search is an OpenMP loop
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Warning);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  const bool agree = check_agreement();

  // Process CPU time: work on any helper thread would be counted too.
  auto add = [](const char* name, void (*fn)(benchmark::State&)) {
    benchmark::RegisterBenchmark(name, fn)->Unit(benchmark::kMicrosecond)->MeasureProcessCPUTime();
  };
  add("iclap/float", BM_Iclap<float>);
  add("iclap/double", BM_Iclap<double>);
  add("iclap_with_build/float", BM_IclapWithBuild<float>);
  add("iclap_with_build/double", BM_IclapWithBuild<double>);
  add("nanoflann_51x100q/float", BM_Nanoflann<float>);
  add("nanoflann_51x100q/double", BM_Nanoflann<double>);
  add("pcl/prebuilt_tree", BM_Pcl<true>);
  add("pcl/default", BM_Pcl<false>);
  add("open3d", BM_Open3d);
  add("build/iclap_float", BM_IclapBuild<float>);
  add("build/iclap_double", BM_IclapBuild<double>);
  add("build/pcl", BM_PclBuild);
  add("build/open3d", BM_Open3dBuild);

  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.print_ratios();
  std::printf("Threads in this process after the run: %d (OMP max threads %d)\n", thread_count(),
              omp_get_max_threads());
  benchmark::Shutdown();
  return agree ? 0 : 1;
}

// SPDX-License-Identifier: MIT
// Registration (paper, Section III) costs and accuracy:
//
//  Icp/<search>/<scalar>/<dim>D/<model>/m:M/n:N
//      One `Icp::align` of an N-point test against an M-point reference
//      (built once, outside the timed loop, as recognition does), with the
//      paper's termination (at most 50 iterations, relative change 1e-6).
//      Counters: iters (iterations made), rmse_mm (final RMSE), t_err_mm and
//      R_err (|t - t_true| and |R - R_true|_F against the known motion),
//      degenerate (the pairs do not fix every rotation) and per_iter (time
//      per ICP iteration). Dim 3 is the plain 3-D ICP, 4 the
//      paper's (x, y, z, word), 8 and 67 descriptor-sized labels; every
//      transform model; kd-tree and brute force; float and double.
//  IcpLarge/...
//      The same where one registration takes long (brute force on the
//      20,000-point models and from 2,000 points in 67-D, kd-trees in 8-D and
//      67-D on the larger sizes; minutes each for 67-D brute force): not in
//      the default run. Examples:
//        bench_registration --benchmark_filter='IcpLarge/brute/float/3D/'
//        bench_registration --benchmark_filter='IcpLarge/kdtree/float/67D/spatial'
//        bench_registration --benchmark_filter='Icp(Large)?/kdtree/float/8D/full'
//  IcpDynamic/...
//      Run-time dimension (Eigen::Dynamic) beside the fixed-size path.
//  Reference/<search>/<scalar>/<dim>D/m:M
//      Building the reference (centring + kd-tree), 20 to 20,000 points.
//  Nearest/<search>/<scalar>/<dim>D/m:M
//      One nearest-neighbour query: iclap's kd-tree and brute force beside
//      raw nanoflann (its own L2 adaptor and KNNResultSet on the same points).
//  Target/...
//      Issue 2, target (b): 3-D point-to-point ICP, 400-point model, 100-point
//      test, kd-tree, 50 forced iterations, against the nanoflann queries
//      alone on an identical tree (same points, same leaf size), at exactly
//      the positions the ICP queries (the 51 query rounds of the 50
//      iterations, recovered by re-running with max_iterations = 0..50).
//      Target/ratio/<scalar> times both interleaved in one loop and reports
//      ratio_b = (t_icp / 50) / t_100_queries (target: <= 1.2; note that 50
//      iterations make 51 query rounds, so 1.02 is the floor).
//
//  OwnType/ratio/<scalar>
//      Icp::align of a 4-D test given as the user's own records (through
//      PointCloudTraits) against the same test as a matrix, interleaved:
//      ratio_own is what reading the records costs on top.
//
// Without --benchmark_filter the default run skips IcpLarge (a few minutes on
// one core); any explicit filter is taken as given.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "compare/nanoflann_baseline.hpp"
#include "compare/registration_problem.hpp"
#include "iclap/registration/registration.hpp"
#include "iclap/search/search.hpp"

using namespace iclap;

namespace {

// --- names and inputs --------------------------------------------------------

template <typename Scalar>
const char* scalar_name() {
  return std::is_same_v<Scalar, float> ? "float" : "double";
}

template <template <typename, int> class Search>
const char* search_name() {
  return std::is_same_v<Search<float, 3>, KdTreeSearch<float, 3>> ? "kdtree" : "brute";
}

std::string dim_name(Index dim, bool dynamic) { return std::to_string(dim) + (dynamic ? "D_dynamic" : "D"); }

/// Problems are generated once per (model, dim, m, n) and shared by every
/// scalar, search and repetition (generation is not timed, but it is not free
/// for 20,000 points in 67-D either).
template <typename Model>
const bench::RegistrationProblem& problem(Index dim, Index m, Index n) {
  static std::map<std::tuple<Index, Index, Index>, std::unique_ptr<bench::RegistrationProblem>> cache;
  auto& slot = cache[{dim, m, n}];
  if (!slot) slot = std::make_unique<bench::RegistrationProblem>(bench::make_problem<Model>(dim, m, n, 2018));
  return *slot;
}

template <typename Scalar, int Dim>
Cloud<Scalar, Dim> as_cloud(const Eigen::MatrixXd& m) {
  return m.cast<Scalar>();
}

/// Accuracy and iteration counters of the last registration of a benchmark.
template <typename Result>
void report(benchmark::State& state, const Result& r, const bench::RegistrationProblem& p, std::int64_t iterations) {
  state.counters["iters"] = r.iterations;
  state.counters["rmse_mm"] = 1e3 * static_cast<double>(r.rmse);
  state.counters["t_err_mm"] = 1e3 * (r.T_model_test.t.template cast<double>() - p.t).norm();
  state.counters["R_err"] = (r.T_model_test.R.template cast<double>() - p.R).norm();
  // 1: the final pairs leave some rotation undetermined (e.g. FullRigid in
  // 67-D: the points span only a few directions), so R_err means nothing.
  state.counters["degenerate"] = r.degenerate ? 1 : 0;
  // Seconds per ICP iteration (each also makes one query round).
  state.counters["per_iter"] =
      benchmark::Counter(static_cast<double>(iterations), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// --- registration ------------------------------------------------------------

template <typename Scalar, int Dim, typename Model, template <typename, int> class SearchT>
void BM_Icp(benchmark::State& state, Index dim) {
  using Search = SearchT<Scalar, Dim>;
  const auto& p = problem<Model>(dim, state.range(0), state.range(1));
  const ReferenceCloud<Scalar, Dim, Search> reference(as_cloud<Scalar, Dim>(p.model));
  const Cloud<Scalar, Dim> test = as_cloud<Scalar, Dim>(p.test);
  const Icp<Scalar, Dim, Model> icp;  // the paper's termination rules, defaults
  IcpWorkspace<Scalar, Dim> workspace;
  RegistrationResult<Scalar, Dim> r;
  std::int64_t iterations = 0;
  for (auto _ : state) {
    r = icp.align(reference, test, nullptr, workspace);
    benchmark::DoNotOptimize(r);
    iterations += r.iterations;
  }
  report(state, r, p, iterations);
}

/// Model-by-test sizes; a pair is "large" when one registration can take
/// seconds (brute force or a high-dimensional kd-tree on thousands of points).
struct Sizes {
  Index m, n;
};
constexpr Sizes kSizes[] = {{20, 20}, {400, 100}, {2000, 500}, {20000, 2000}, {20000, 20000}};

bool is_large(Sizes s, Index dim, bool brute) {
  // Rough per-iteration work in distance evaluations x coordinates; the
  // kd-tree prunes well below ~10 dimensions only.
  const double visited = brute || dim > 8 ? static_cast<double>(s.m) : 64.0 * static_cast<double>(dim);
  return static_cast<double>(s.n) * visited * static_cast<double>(dim) > 2.5e7;
}

template <typename Scalar, int Dim, typename Model, template <typename, int> class Search>
void register_icp(Index runtime_dim = Dim) {
  const bool brute = std::string(search_name<Search>()) == "brute";
  for (const Sizes s : kSizes) {
    const bool large = is_large(s, runtime_dim, brute);
    const std::string name = std::string(Dim == Eigen::Dynamic ? "IcpDynamic/" : large ? "IcpLarge/" : "Icp/") +
                             search_name<Search>() + "/" + scalar_name<Scalar>() + "/" +
                             dim_name(runtime_dim, Dim == Eigen::Dynamic) + "/" + Model::name;
    if (Dim == Eigen::Dynamic && large) continue;
    benchmark::RegisterBenchmark(name.c_str(), BM_Icp<Scalar, Dim, Model, Search>, runtime_dim)
        ->Args({s.m, s.n})
        ->ArgNames({"m", "n"})
        ->Unit(benchmark::kMicrosecond)
        ->MinTime(large ? 1.0 : 0.1);
  }
}

/// The search policy and the scalar change only the matching, the transform
/// model only the estimation step, so they are crossed separately (the full
/// product would compile 64 registrations for no more information): every
/// dimension x scalar x search with the paper's FullRigid model, and every
/// dimension x model with float and the kd-tree.
template <typename Scalar, int Dim>
void register_searches() {
  register_icp<Scalar, Dim, FullRigid, KdTreeSearch>();
  register_icp<Scalar, Dim, FullRigid, BruteForceSearch>();
}

template <int Dim>
void register_dim() {
  register_searches<float, Dim>();
  register_searches<double, Dim>();
  register_icp<float, Dim, SpatialRigid, KdTreeSearch>();
  register_icp<float, Dim, Planar, KdTreeSearch>();
  register_icp<float, Dim, Translation, KdTreeSearch>();
}

// --- reference build ---------------------------------------------------------

template <typename Scalar, int Dim, template <typename, int> class SearchT>
void BM_Reference(benchmark::State& state) {
  const auto& p = problem<FullRigid>(Dim, state.range(0), 20);
  const Cloud<Scalar, Dim> model = as_cloud<Scalar, Dim>(p.model);
  for (auto _ : state) {
    ReferenceCloud<Scalar, Dim, SearchT<Scalar, Dim>> reference(model);
    benchmark::DoNotOptimize(reference.working_points().data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

template <typename Scalar, int Dim, template <typename, int> class Search>
void register_reference() {
  const std::string name = std::string("Reference/") + search_name<Search>() + "/" + scalar_name<Scalar>() + "/" +
                           dim_name(Dim, false);
  benchmark::RegisterBenchmark(name.c_str(), BM_Reference<Scalar, Dim, Search>)
      ->RangeMultiplier(10)
      ->Range(20, 20000)
      ->ArgName("m")
      ->Unit(benchmark::kMicrosecond)
      ->MinTime(0.1);
}

// --- nearest-neighbour queries -------------------------------------------------

/// Queries: the test points in the reference's working frame at the true
/// alignment (where a converging ICP spends its iterations).
template <typename Scalar, int Dim>
Cloud<Scalar, Dim> aligned_queries(const bench::RegistrationProblem& p, const Eigen::VectorXd& centroid) {
  return bench::motion(p.R, p.t - centroid, p.test).cast<Scalar>();
}

template <typename Scalar, int Dim, typename Query>
void run_queries(benchmark::State& state, const Cloud<Scalar, Dim>& queries, const Query& query) {
  Index j = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(query(queries.col(j).data()));
    if (++j == queries.cols()) j = 0;
  }
  state.SetItemsProcessed(state.iterations());
}

template <typename Scalar, int Dim, int Kind>  // 0: iclap kd-tree, 1: iclap brute force, 2: raw nanoflann
void BM_Nearest(benchmark::State& state) {
  const auto& p = problem<FullRigid>(Dim, state.range(0), 500);
  const ReferenceCloud<Scalar, Dim> reference(as_cloud<Scalar, Dim>(p.model));
  const Cloud<Scalar, Dim> queries = aligned_queries<Scalar, Dim>(p, reference.centroid_accurate().template cast<double>());
  if constexpr (Kind == 0) {
    run_queries<Scalar, Dim>(state, queries, [&](const Scalar* q) { return reference.search().nearest(q).index; });
  } else if constexpr (Kind == 1) {
    const BruteForceSearch<Scalar, Dim> brute(reference.working_points());
    run_queries<Scalar, Dim>(state, queries, [&](const Scalar* q) { return brute.nearest(q).index; });
  } else {
    const bench::RawNanoflann<Scalar, Dim> raw(reference.working_points());
    run_queries<Scalar, Dim>(state, queries, [&](const Scalar* q) { return raw.nearest(q); });
  }
}

template <typename Scalar, int Dim>
void register_nearest() {
  const char* kinds[] = {"kdtree", "brute", "nanoflann"};
  auto add = [&](const char* kind, auto fn) {
    const std::string name = std::string("Nearest/") + kind + "/" + scalar_name<Scalar>() + "/" + dim_name(Dim, false);
    benchmark::RegisterBenchmark(name.c_str(), fn)->RangeMultiplier(10)->Range(20, 20000)->ArgName("m")->MinTime(0.1);
  };
  add(kinds[0], BM_Nearest<Scalar, Dim, 0>);
  add(kinds[1], BM_Nearest<Scalar, Dim, 1>);
  add(kinds[2], BM_Nearest<Scalar, Dim, 2>);
}

// --- target (b): ICP iteration vs the bare nanoflann queries -------------------

constexpr int kForcedIterations = 50;

/// The 3-D point-to-point case, everything prepared once.
template <typename Scalar>
struct TargetCase {
  bench::RegistrationProblem p = bench::make_problem<FullRigid>(3, 400, 100, 2018);
  ReferenceCloud<Scalar, 3> reference{as_cloud<Scalar, 3>(p.model)};
  Cloud<Scalar, 3> test = as_cloud<Scalar, 3>(p.test);
  Icp<Scalar, 3, FullRigid> icp = bench::forced_icp<Scalar, 3>(kForcedIterations);
  IcpWorkspace<Scalar, 3> workspace;
  bench::RawNanoflann<Scalar, 3> raw{reference.working_points()};
  std::vector<Cloud<Scalar, 3>> rounds = bench::icp_query_rounds(reference, test, kForcedIterations);

  std::uint64_t raw_rounds() const {
    return bench::run_rounds(rounds, [this](const Scalar* q) { return raw.nearest(q); });
  }
  /// The same queries through iclap's KdTreeSearch (tie-aware result set).
  std::uint64_t wrapper_rounds() const {
    return bench::run_rounds(rounds, [this](const Scalar* q) { return reference.search().nearest(q).index; });
  }
};

/// Shared by the Target benchmarks of one scalar (which run one at a time).
template <typename Scalar>
TargetCase<Scalar>& target_case() {
  static TargetCase<Scalar> c;
  return c;
}

template <typename Scalar>
void BM_TargetIcp(benchmark::State& state) {
  auto& c = target_case<Scalar>();
  RegistrationResult<Scalar, 3> r;
  std::int64_t iterations = 0;
  for (auto _ : state) {
    r = c.icp.align(c.reference, c.test, nullptr, c.workspace);
    benchmark::DoNotOptimize(r);
    iterations += r.iterations;
  }
  report(state, r, c.p, iterations);
}

/// One iteration = the 51 rounds of 100 queries; per_100q is the time of
/// one round.
template <typename Scalar, bool Raw>
void BM_TargetQueries(benchmark::State& state) {
  const auto& c = target_case<Scalar>();
  for (auto _ : state) benchmark::DoNotOptimize(Raw ? c.raw_rounds() : c.wrapper_rounds());
  state.counters["per_100q"] = benchmark::Counter(static_cast<double>(state.iterations()) * (kForcedIterations + 1),
                                                  benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

/// ICP, raw nanoflann and iclap's kd-tree queries interleaved in one loop,
/// each timed in thread CPU time (a loaded machine's waits hit none of
/// them); the reported (manual) time is the ICP's.
template <typename Scalar>
void BM_TargetRatio(benchmark::State& state) {
  auto& c = target_case<Scalar>();
  double icp_s = 0, raw_s = 0, wrap_s = 0;
  RegistrationResult<Scalar, 3> r;
  for (auto _ : state) {
    const double t0 = bench::thread_cpu_seconds();
    r = c.icp.align(c.reference, c.test, nullptr, c.workspace);
    benchmark::DoNotOptimize(r);
    const double t1 = bench::thread_cpu_seconds();
    benchmark::DoNotOptimize(c.raw_rounds());
    const double t2 = bench::thread_cpu_seconds();
    benchmark::DoNotOptimize(c.wrapper_rounds());
    const double t3 = bench::thread_cpu_seconds();
    icp_s += t1 - t0;
    raw_s += t2 - t1;
    wrap_s += t3 - t2;
    state.SetIterationTime(t1 - t0);
  }
  const double runs = static_cast<double>(state.iterations());
  const double per_iter = icp_s / runs / kForcedIterations;
  const double per_100q = raw_s / runs / (kForcedIterations + 1);
  const double per_100q_wrapped = wrap_s / runs / (kForcedIterations + 1);
  state.counters["iters"] = r.iterations;
  state.counters["icp_us_per_iter"] = 1e6 * per_iter;
  state.counters["nanoflann_us_per_100q"] = 1e6 * per_100q;
  state.counters["kdtree_us_per_100q"] = 1e6 * per_100q_wrapped;
  state.counters["ratio_b"] = per_iter / per_100q;
  state.counters["ratio_wrapper"] = per_100q_wrapped / per_100q;
}

template <typename Scalar>
void register_target() {
  const std::string s = scalar_name<Scalar>();
  benchmark::RegisterBenchmark(("Target/icp_50/" + s).c_str(), BM_TargetIcp<Scalar>)->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark(("Target/nanoflann_queries/" + s).c_str(), BM_TargetQueries<Scalar, true>)
      ->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark(("Target/kdtree_queries/" + s).c_str(), BM_TargetQueries<Scalar, false>)
      ->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark(("Target/ratio/" + s).c_str(), BM_TargetRatio<Scalar>)
      ->UseManualTime()
      ->Unit(benchmark::kMicrosecond);
}

// --- the user's own point type (PointCloudTraits) ----------------------------

/// A user's record of a touch: position and word, as a rig program keeps it.
struct TouchRecord {
  double x, y, z;
  double word;
};
using TouchRecords = std::vector<TouchRecord>;

}  // namespace

template <>
struct iclap::PointCloudTraits<TouchRecords> {
  static Index size(const TouchRecords& c) { return static_cast<Index>(c.size()); }
  static Index dimension(const TouchRecords&) { return 4; }
  static double coordinate(const TouchRecords& c, Index i, Index k) {
    const TouchRecord& t = c[static_cast<std::size_t>(i)];
    return k == 0 ? t.x : k == 1 ? t.y : k == 2 ? t.z : t.word;
  }
};

namespace {

/// `Icp::align` of a 100-point 4-D test against a 400-point reference
/// (planar iCLAP, default termination), the test given as the library's
/// matrix and as the user's records (read through PointCloudTraits at each
/// call), interleaved in one loop and each timed in thread CPU time.
/// ratio_own = t_records / t_matrix (the reading's cost; 1 is the floor);
/// same = 1 when the two results are equal to the bit.
template <typename Scalar>
void BM_OwnTypeRatio(benchmark::State& state) {
  static const bench::RegistrationProblem p = bench::make_problem<Planar>(4, 400, 100, 2018);
  static const ReferenceCloud<Scalar, 4> reference(as_cloud<Scalar, 4>(p.model));
  const Eigen::Matrix4Xd matrix = p.test;
  TouchRecords records;
  for (Index i = 0; i < matrix.cols(); ++i) records.push_back({matrix(0, i), matrix(1, i), matrix(2, i), matrix(3, i)});
  const Icp<Scalar, 4, Planar> icp;
  double matrix_s = 0, own_s = 0;
  RegistrationResult<Scalar, 4> a, b;
  for (auto _ : state) {
    const double t0 = bench::thread_cpu_seconds();
    a = icp.align(reference, matrix);
    benchmark::DoNotOptimize(a);
    const double t1 = bench::thread_cpu_seconds();
    b = icp.align(reference, records);
    benchmark::DoNotOptimize(b);
    const double t2 = bench::thread_cpu_seconds();
    matrix_s += t1 - t0;
    own_s += t2 - t1;
    state.SetIterationTime(t2 - t1);
  }
  const double runs = static_cast<double>(state.iterations());
  state.counters["iters"] = a.iterations;
  state.counters["matrix_us"] = 1e6 * matrix_s / runs;
  state.counters["records_us"] = 1e6 * own_s / runs;
  state.counters["ratio_own"] = own_s / matrix_s;
  state.counters["same"] = a.T_model_test.matrix() == b.T_model_test.matrix() && a.iterations == b.iterations ? 1 : 0;
}

bool has_filter_flag(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::strncmp(argv[i], "--benchmark_filter", 18) == 0) return true;
  return std::getenv("BENCHMARK_FILTER") != nullptr;
}

}  // namespace

int main(int argc, char** argv) {
  register_target<float>();
  register_target<double>();
  benchmark::RegisterBenchmark("OwnType/ratio/float", BM_OwnTypeRatio<float>)->UseManualTime()->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("OwnType/ratio/double", BM_OwnTypeRatio<double>)->UseManualTime()->Unit(benchmark::kMicrosecond);

  register_dim<3>();
  register_dim<4>();
  register_dim<8>();
  register_dim<67>();
  register_icp<float, Eigen::Dynamic, FullRigid, KdTreeSearch>(3);
  register_icp<float, Eigen::Dynamic, FullRigid, KdTreeSearch>(67);

  register_reference<float, 3, KdTreeSearch>();
  register_reference<double, 3, KdTreeSearch>();
  register_reference<float, 67, KdTreeSearch>();
  register_reference<float, 3, BruteForceSearch>();

  register_nearest<float, 3>();
  register_nearest<double, 3>();
  register_nearest<float, 4>();
  register_nearest<float, 8>();
  register_nearest<float, 67>();

  const bool default_run = !has_filter_flag(argc, argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  if (default_run) benchmark::SetBenchmarkFilter("^(Target|OwnType|Icp|IcpDynamic|Reference|Nearest)/");
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

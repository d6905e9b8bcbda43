// SPDX-License-Identifier: MIT
//
// One recognition per method: a set of 20 test touches against the 20
// built-in objects (references from 4 explorations of each, the test from the
// 5th), single-threaded. Issue target: `iclap` under 0.5 ms.
//
//   build/release/benchmarks/bench_recognition --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "iclap/recognition/recognition.hpp"
#include "iclap/sim/builtin_objects.hpp"
#include "iclap/sim/simulator.hpp"
#include "iclap/tactile/tactile_sift.hpp"
#include "cpu_time.hpp"
#include "held_out.hpp"

namespace {

using namespace iclap;

/// The built-in dataset, its touches, a codebook from explorations 1-4 and
/// every classifier fitted on them; test sets of 20 touches from exploration 0.
struct Scene {
  TouchTable table;
  TouchSet all;
  std::vector<TouchSet> objects;
  std::vector<TouchSet> tests;  // one per object
  /// Every object's exploration 0, the pool the cross validation draws a
  /// fold's tests from, and the tests as touches of it.
  TouchSet pool;
  std::vector<std::vector<Index>> pool_rows;
  Index k = 50;

  Scene() {
    SimulationSettings settings;
    settings.threads = 0;
    const Dataset ds = simulate_dataset(builtin_objects(), settings, 1);
    table = make_touch_table(ds, TactileSift<float>{});
    bench::HeldOut split = bench::hold_out_exploration_zero(table, k);
    all = std::move(split.all);
    objects = std::move(split.references);
    std::vector<Index> members;  // rows of `all` in the pool, ascending
    for (const auto& h : split.held_out) members.insert(members.end(), h.begin(), h.end());
    std::sort(members.begin(), members.end());
    pool = select_touches(all, members);
    for (Index o = 0; o < static_cast<Index>(objects.size()); ++o) {
      Rng rng = Rng::derive(1, static_cast<std::uint64_t>(o));
      const std::vector<Index> rows = bench::random_subset(split.held_out[static_cast<std::size_t>(o)], 20, rng);
      tests.push_back(select_touches(all, rows));
      pool_rows.emplace_back();
      for (Index r : rows)
        pool_rows.back().push_back(static_cast<Index>(std::lower_bound(members.begin(), members.end(), r) - members.begin()));
    }
  }
};

const Scene& scene() {
  static const Scene s;
  return s;
}

std::unique_ptr<Classifier> make(const std::string& name) {
  if (name == "bow") return std::make_unique<BowClassifier>();
  if (name == "icp") return std::make_unique<IcpClassifier<float, Planar>>();
  if (name == "iclap") return std::make_unique<IclapClassifier<float, Planar>>();
  if (name == "height") return std::make_unique<HeightClassifier>();
  if (name == "height_contact") {
    auto c = std::make_unique<HeightClassifier>();
    c->contact_scale = 1;
    return c;
  }
  if (name == "occupancy") return std::make_unique<OccupancyClassifier>();
  return std::make_unique<IclapNClassifier<72, float, Planar>>();
}

/// One recognition with `method`: the distances of its classifiers (each
/// once), normalisation, fusion, decision. Cycles through the 20 objects'
/// test sets; reports the fraction recognised as a counter.
void BM_Recognition(benchmark::State& state, const std::string& method_spec) {
  const Scene& s = scene();
  const Method method = parse_method(method_spec);
  std::vector<std::unique_ptr<Classifier>> cs;
  for (const auto& c : method.fusion.classifiers()) cs.push_back(make(c));
  Recognizer rec(std::move(cs));
  rec.fit(s.objects, s.k);
  std::size_t i = 0, correct = 0, count = 0;
  for (auto _ : state) {
    const std::size_t o = i++ % s.tests.size();
    const Index guess = decide(method.fusion.evaluate(rec.distances(s.tests[o])));
    benchmark::DoNotOptimize(guess);
    correct += guess == static_cast<Index>(o);
    ++count;
  }
  state.counters["recognised"] = static_cast<double>(correct) / static_cast<double>(count);
  state.counters["objects"] = static_cast<double>(s.objects.size());
}

/// iCLAP decision only, with the exact lower-bound pruning and with
/// successive halving, against every registration to the end.
void BM_IclapDecision(benchmark::State& state, PruningSettings::Schedule schedule) {
  const Scene& s = scene();
  IclapClassifier<float, Planar> c;
  c.fit(s.objects, s.k);
  PruningSettings p;
  p.schedule = schedule;
  std::size_t i = 0, correct = 0, count = 0;
  double completed = 0;
  for (auto _ : state) {
    const std::size_t o = i++ % s.tests.size();
    const PrunedDecision d = c.decide(s.tests[o], p);
    benchmark::DoNotOptimize(d);
    correct += d.object == static_cast<Index>(o);
    completed += static_cast<double>(d.completed);
    ++count;
  }
  state.counters["recognised"] = static_cast<double>(correct) / static_cast<double>(count);
  state.counters["registrations_run"] = completed / static_cast<double>(count);
}

/// Times all 20 distances of `c` (fitted on the scene's objects), cycling
/// through the 20 objects' tests.
template <typename C>
void time_distances(benchmark::State& state, C& c) {
  const Scene& s = scene();
  c.fit(s.objects, s.k);
  Eigen::VectorXd d(static_cast<Index>(s.objects.size()));
  std::size_t i = 0;
  for (auto _ : state) {
    c.distances(s.tests[i++ % s.tests.size()], d);
    benchmark::DoNotOptimize(d.data());
  }
}

/// All 20 distances of one registration classifier with `leaf` points per
/// kd-tree leaf in its references (always a kd-tree here): what the default
/// reference search settings (24) save against KdTreeSearch's own default
/// (10). The distances are identical (tests/recognition/test_pruning.cpp).
template <typename C>
void BM_LeafSize(benchmark::State& state) {
  C c;
  c.search_settings.brute_force_max_coordinates = 0;
  c.search_settings.leaf_max_size = static_cast<std::size_t>(state.range(0));
  time_distances(state, c);
}

/// All 20 distances of the same tests as BM_LeafSize (default settings),
/// each taken as a subset of the pool of every object's exploration 0, which
/// the classifier prepared once, outside the timing
/// (Classifier::prepare_pool: every touch's first matches): the path of the
/// cross validation. Same distances; the registrations skip their first
/// round of queries. Includes the check that the preparation was made for
/// the drawn touches (BM_PoolCheck).
template <typename C>
void BM_PoolDistances(benchmark::State& state) {
  const Scene& s = scene();
  C c;
  c.fit(s.objects, s.k);
  const auto prepared = c.prepare_pool(s.pool);
  Eigen::VectorXd d(static_cast<Index>(s.objects.size()));
  std::size_t i = 0;
  for (auto _ : state) {
    c.pool_distances(s.pool, prepared.get(), s.pool_rows[i++ % s.pool_rows.size()], d);
    benchmark::DoNotOptimize(d.data());
  }
}

/// All 20 distances of the same tests with each search of the references
/// (AdaptiveSearch settings): search:0 the kd-tree (24 points per leaf),
/// search:1 the default, which scans these references (about 280 points)
/// by brute force, with AVX2 where the CPU has it, search:2 the same
/// without AVX2 (the baseline x86-64 code). The distances are identical
/// (tests/search/test_search.cpp, tests/recognition/test_pruning.cpp).
template <typename C>
void BM_Search(benchmark::State& state) {
  C c;
  if (state.range(0) == 0) c.search_settings.brute_force_max_coordinates = 0;
  if (state.range(0) == 2) c.search_settings.use_avx2 = false;
  time_distances(state, c);
}

}  // namespace

BENCHMARK_TEMPLATE(BM_Search, IcpClassifier<float, Planar>)->Arg(0)->Arg(1)->Arg(2)->ArgName("search");
BENCHMARK_TEMPLATE(BM_Search, IclapClassifier<float, Planar>)->Arg(0)->Arg(1)->Arg(2)->ArgName("search");
BENCHMARK_TEMPLATE(BM_PoolDistances, IcpClassifier<float, Planar>);
BENCHMARK_TEMPLATE(BM_PoolDistances, IclapClassifier<float, Planar>);
BENCHMARK_TEMPLATE(BM_LeafSize, IcpClassifier<float, Planar>)->Arg(10)->Arg(24)->ArgName("leaf");
BENCHMARK_TEMPLATE(BM_LeafSize, IclapClassifier<float, Planar>)->Arg(10)->Arg(24)->ArgName("leaf");
BENCHMARK_CAPTURE(BM_Recognition, bow, std::string("bow"));
BENCHMARK_CAPTURE(BM_Recognition, icp, std::string("icp"));
BENCHMARK_CAPTURE(BM_Recognition, iclap, std::string("iclap"));
BENCHMARK_CAPTURE(BM_Recognition, iclapn, std::string("iclapn"));
BENCHMARK_CAPTURE(BM_Recognition, icp_plus_bow, std::string("0.7*icp+0.3*bow"));
BENCHMARK_CAPTURE(BM_Recognition, icp_times_bow, std::string("icp*bow"));
BENCHMARK_CAPTURE(BM_Recognition, iclap_plus_icp, std::string("0.9*iclap+0.1*icp"));
BENCHMARK_CAPTURE(BM_Recognition, iclap_times_icp, std::string("iclap*icp"));
BENCHMARK_CAPTURE(BM_Recognition, iclap_plus_bow, std::string("0.8*iclap+0.2*bow"));
BENCHMARK_CAPTURE(BM_Recognition, iclap_times_bow, std::string("iclap*bow"));
BENCHMARK_CAPTURE(BM_Recognition, iclap_plus_icp_plus_bow, std::string("0.6*iclap+0.2*icp+0.2*bow"));
BENCHMARK_CAPTURE(BM_Recognition, iclap_times_icp_times_bow, std::string("iclap*icp*bow"));
/// The nearest-touch sums of `height` (every test against every object)
/// through the search `height` uses, (z, s theta) in 2-D, and through the
/// 4-D search of `height_contact` with the contact coordinates 0, which
/// gives the same sums: what the 2-D path saves.
template <int Dim>
void BM_HeightSearch(benchmark::State& state) {
  const Scene& s = scene();
  HeightClassifier h;
  std::vector<AdaptiveSearch<double, Dim>> searches;
  for (const auto& o : s.objects) searches.emplace_back(h.embed(o, "object").topRows<Dim>());
  std::vector<Eigen::Matrix<double, Dim, Eigen::Dynamic>> tests;
  for (const auto& t : s.tests) tests.emplace_back(h.embed(t, "test").topRows<Dim>());
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& p = tests[i++ % tests.size()];
    double e = 0;
    for (const auto& search : searches)
      for (Index q = 0; q < p.cols(); ++q) e += search.nearest(p.col(q).data()).squared_distance;
    benchmark::DoNotOptimize(e);
  }
}

/// What the occupancy classifier's fields answer, the truncated squared
/// distance from a test contact point to an object's training contact
/// points, by the field (range 0) and by a kd-tree nearest-neighbour query
/// (range 1; the answer then truncated): every contact point of one test
/// against every object per iteration.
void BM_OccupancyLookup(benchmark::State& state) {
  const Scene& s = scene();
  const bool tree = state.range(0) == 1;
  const double tau = 3e-3;
  std::vector<TruncatedDistanceField> fields;
  std::vector<KdTreeSearch<double, 3>> trees;
  for (const auto& o : s.objects) {
    if (tree) trees.emplace_back(o.contact_points);
    else fields.emplace_back(o.contact_points, DistanceFieldSettings{1e-3, tau});
  }
  std::size_t i = 0;
  std::int64_t queries = 0;
  for (auto _ : state) {
    const TouchSet& t = s.tests[i++ % s.tests.size()];
    double e = 0;
    for (std::size_t j = 0; j < s.objects.size(); ++j)
      for (Index k = 0; k < t.contact_points.cols(); ++k) {
        const Eigen::Vector3d q = t.contact_points.col(k);
        e += tree ? std::min(tau * tau, trees[j].nearest(q.data()).squared_distance)
                  : static_cast<double>(fields[j].squared_distance(q));
      }
    benchmark::DoNotOptimize(e);
    queries += static_cast<std::int64_t>(s.objects.size()) * t.contact_points.cols();
  }
  state.SetItemsProcessed(queries);
}

BENCHMARK_CAPTURE(BM_Recognition, occupancy, std::string("occupancy"));
BENCHMARK_CAPTURE(BM_Recognition, occupancy_plus_height_contact, std::string("0.5*occupancy+0.5*height_contact"));
// The occupancy classifier's distances from a pool it prepared once (every
// touch's cost under every placement), against the same tests computed
// directly in BM_Recognition/occupancy (which adds the fusion and the
// decision).
BENCHMARK_TEMPLATE(BM_PoolDistances, OccupancyClassifier);

namespace {
/// What every prepared pool_distances call pays to check that its
/// preparation was made for the drawn touches (PreparedPool::made_for): the
/// pool's shape and the fingerprints of the 20 drawn touches of the tests
/// of BM_PoolDistances. Compare with BM_PoolDistances<OccupancyClassifier>,
/// the cheapest path that pays it.
void BM_PoolCheck(benchmark::State& state) {
  const Scene& s = scene();
  std::size_t i = 0;
  for (auto _ : state) {
    std::uint64_t h = detail::pool_shape(s.pool);
    for (Index t : s.pool_rows[i++ % s.pool_rows.size()]) h ^= detail::touch_fingerprint(s.pool, t);
    benchmark::DoNotOptimize(h);
  }
}
}  // namespace
namespace {
/// All 20 distances of the occupancy classifier with the slab behind the
/// pad (back_depth 6 mm: two layers) against the same without it (the
/// baseline), interleaved on the same tests: ratio_slab is what the slab
/// costs per recognition (the fits are not timed).
void BM_OccupancySlab(benchmark::State& state) {
  const Scene& s = scene();
  OccupancyClassifier plain, slab;
  slab.back_depth = 0.006;
  plain.fit(s.objects, s.k);
  slab.fit(s.objects, s.k);
  Eigen::VectorXd a(static_cast<Index>(s.objects.size())), b(a.size());
  double plain_s = 0, slab_s = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    const TouchSet& t = s.tests[i++ % s.tests.size()];
    const double t0 = bench::thread_cpu_seconds();
    plain.distances(t, a);
    benchmark::DoNotOptimize(a.data());
    const double t1 = bench::thread_cpu_seconds();
    slab.distances(t, b);
    benchmark::DoNotOptimize(b.data());
    const double t2 = bench::thread_cpu_seconds();
    plain_s += t1 - t0;
    slab_s += t2 - t1;
  }
  const double runs = static_cast<double>(state.iterations());
  state.counters["plain_ms"] = 1e3 * plain_s / runs;
  state.counters["slab_ms"] = 1e3 * slab_s / runs;
  state.counters["ratio_slab"] = slab_s / plain_s;
}
}  // namespace
BENCHMARK(BM_OccupancySlab);
BENCHMARK(BM_PoolCheck);
BENCHMARK(BM_OccupancyLookup)->Arg(0)->Arg(1)->ArgName("kdtree");
BENCHMARK_CAPTURE(BM_Recognition, height, std::string("height"));
BENCHMARK_CAPTURE(BM_Recognition, height_contact, std::string("height_contact"));
BENCHMARK_TEMPLATE(BM_HeightSearch, 2);
BENCHMARK_TEMPLATE(BM_HeightSearch, 4);
BENCHMARK_CAPTURE(BM_IclapDecision, all_registrations, PruningSettings::Schedule::None);
BENCHMARK_CAPTURE(BM_IclapDecision, bound_pruning, PruningSettings::Schedule::Bound);
BENCHMARK_CAPTURE(BM_IclapDecision, successive_halving, PruningSettings::Schedule::Halving);

BENCHMARK_MAIN();

// SPDX-License-Identifier: MIT
//
// Cost of recognising among many objects, with and without pruning: iCLAP
// (planar, float) decisions of 20-touch test sets against 20, 100 and 500
// simulated objects. Objects beyond the 20 built-in ones are built-in shapes
// stretched per axis (0.75-1.35, seeded), so the set gets harder as it grows.
// References from explorations 1-4, tests from exploration 0 (2 draws per
// object), single-threaded. Reports the time per recognition, its ratio to
// the 20-object cost without pruning, the accuracy lost to pruning and how
// often a schedule's decision differs from the full registration's. Each
// time is the median of at least 3 passes over the tests (and at least 0.5 s
// of them), in CPU time of the one working thread: a single short pass on a
// shared machine varied by 30% between runs, which moved the ratios.
//
//   build/release/benchmarks/scaling_study [--sizes 20,100,500] [--out DIR]

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "iclap/io/atomic_file.hpp"
#include "iclap/recognition/recognition.hpp"
#include "iclap/sim/builtin_objects.hpp"
#include "iclap/sim/simulator.hpp"
#include "iclap/tactile/tactile_sift.hpp"
#include "cli.hpp"
#include "cpu_time.hpp"
#include "csv_field.hpp"
#include "held_out.hpp"
#include "study_output.hpp"

namespace {

using namespace iclap;

std::vector<SimObject> objects(std::size_t n) {
  std::vector<SimObject> base = builtin_objects();
  std::vector<SimObject> out;
  Rng rng(2026);
  for (std::size_t i = 0; i < n; ++i) {
    const SimObject& b = base[i % base.size()];
    if (i < base.size()) {
      out.push_back(b);
      continue;
    }
    TriangleMesh m = b.shape.mesh();
    const Eigen::Vector3d s(rng.uniform(0.75, 1.35), rng.uniform(0.75, 1.35), rng.uniform(0.75, 1.35));
    m.vertices = s.asDiagonal() * m.vertices;
    out.push_back(make_sim_object(b.name + "_v" + std::to_string(i / base.size()), std::move(m), false));
  }
  return out;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

struct Measure {
  double ms = 0;
  double rate = 0;
  double registrations = 0;
  double same = 0;  // fraction of decisions equal to those of every registration run to the end
};

const char* const kUsage = "usage: scaling_study [--sizes 20,100,500] [--out DIR]\n";

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::size_t> sizes = {20, 100, 500};
  std::string out;
  try {  // usage errors exit 2 naming the option, before the study runs
    const cli::Options opt(cli::Args(argv + 1, argv + argc), {"sizes", "out"});
    opt.expect_positional(0, 0, "no operand");
    out = opt.string("out", "scaling_study");
    if (opt.has("sizes")) {
      sizes.clear();
      for (const std::string& item : cli::Options::split(opt.string("sizes"), ','))
        sizes.push_back(static_cast<std::size_t>(cli::Options::parse_integer(item, "--sizes", 2, 1000000)));
    }
    bench::check_out_dir(out);
  } catch (const cli::HelpRequested&) {  // --help or -h
    std::printf("%s", kUsage);
    return 0;
  } catch (const cli::UsageError& e) {
    std::fprintf(stderr, "scaling_study: %s\n%s", e.what(), kUsage);
    return 2;
  }
  using Schedule = PruningSettings::Schedule;
  auto halving = [](int round_iterations, double keep_fraction, Index finalists) {
    PruningSettings p;
    p.schedule = Schedule::Halving;
    p.round_iterations = round_iterations;
    p.keep_fraction = keep_fraction;
    p.finalists = finalists;
    return p;
  };
  auto bound = [](Index shortlist) {
    PruningSettings p;
    p.schedule = Schedule::Bound;
    p.shortlist = shortlist;
    return p;
  };
  const PruningSettings defaults;
  // The first schedule is the one every other decision is compared with.
  const std::vector<std::pair<std::string, PruningSettings>> schedules = {
      {"every registration", PruningSettings{Schedule::None}},
      {"lower-bound pruning (exact)", bound(0)},
      {"halving 2 it, keep 1/2, 2 final",
       halving(defaults.round_iterations, defaults.keep_fraction, defaults.finalists)},
      {"halving 1 it, keep 1/4, 3 final", halving(1, 0.25, 3)},
      {"halving 3 it, keep 1/5, 4 final", halving(3, 0.2, 4)},
      {"bound, shortlist 20", bound(20)},
      {"bound, shortlist 50", bound(50)},
  };
  std::vector<std::vector<Measure>> results;
  std::printf("iCLAP decisions of 20-touch tests, 1 thread, CPU ms (median of >= 3 passes)\n"
              "%8s  %-33s %10s %12s %14s %8s %10s %14s\n",
              "objects", "schedule", "ms/recog.", "x 20 objects", "registrations", "rate", "rate lost", "same decision");
  for (std::size_t n : sizes) {
    SimulationSettings sim;
    sim.threads = 0;
    const Dataset ds = simulate_dataset(objects(n), sim, 1);
    const TouchTable table = make_touch_table(ds, TactileSift<float>{});
    const bench::HeldOut split = bench::hold_out_exploration_zero(table, 50);
    std::vector<std::pair<Index, TouchSet>> tests;
    for (Index o = 0; o < static_cast<Index>(table.objects.size()); ++o) {
      const auto& te = split.held_out[static_cast<std::size_t>(o)];
      for (std::uint64_t r = 0; r < 2 && !te.empty(); ++r) {
        Rng rng = Rng::derive(7, static_cast<std::uint64_t>(o), r);
        tests.emplace_back(o, select_touches(split.all, bench::random_subset(te, 20, rng)));
      }
    }
    IclapClassifier<float, Planar> c;
    c.fit(split.references, split.words);
    std::vector<Measure> row;
    std::vector<Index> reference_decisions;
    for (const auto& schedule : schedules) {
      const PruningSettings& p = schedule.second;
      Measure m;
      std::size_t correct = 0, same = 0;
      std::vector<Index> decisions;
      std::vector<double> pass_ms;
      double spent = 0;
      while (pass_ms.size() < 3 || spent < 0.5) {  // the decisions are the same in every pass
        correct = 0;
        m.registrations = 0;
        decisions.clear();
        const double t0 = bench::thread_cpu_seconds();
        for (const auto& [truth, test] : tests) {
          const PrunedDecision d = c.decide(test, p);
          correct += d.object == truth;
          decisions.push_back(d.object);
          m.registrations += static_cast<double>(d.completed);
        }
        const double dt = bench::thread_cpu_seconds() - t0;
        spent += dt;
        pass_ms.push_back(1e3 * dt / static_cast<double>(tests.size()));
      }
      m.ms = median(pass_ms);
      m.rate = static_cast<double>(correct) / static_cast<double>(tests.size());
      m.registrations /= static_cast<double>(tests.size());
      if (reference_decisions.empty()) reference_decisions = decisions;
      for (std::size_t t = 0; t < decisions.size(); ++t) same += decisions[t] == reference_decisions[t];
      m.same = static_cast<double>(same) / static_cast<double>(tests.size());
      row.push_back(m);
    }
    results.push_back(row);
    for (std::size_t s = 0; s < row.size(); ++s)
      std::printf("%8zu  %-33s %10.3f %12.2f %14.1f %7.1f%% %9.1f %13.1f%%\n", n, schedules[s].first.c_str(), row[s].ms,
                  row[s].ms / results.front()[0].ms, row[s].registrations, 100 * row[s].rate,
                  100 * (row[0].rate - row[s].rate), 100 * row[s].same);
    std::fflush(stdout);
  }
  try {
    std::filesystem::create_directories(out);
    AtomicFileWriter w(out + "/scaling_study.csv");
    w.stream() << "objects,schedule,ms_per_recognition,ratio_to_first_size_full,registrations_completed,rate,"
                  "same_decision\n";
    for (std::size_t i = 0; i < sizes.size(); ++i)
      for (std::size_t s = 0; s < results[i].size(); ++s)
        w.stream() << sizes[i] << "," << bench::csv_field(schedules[s].first) << "," << results[i][s].ms << ","
                   << results[i][s].ms / results.front()[0].ms << "," << results[i][s].registrations << ","
                   << results[i][s].rate << "," << results[i][s].same << "\n";
    w.commit();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scaling_study: %s\n", e.what());
    return 1;
  }
  std::printf("wrote %s/scaling_study.csv\n", out.c_str());
  return 0;
}

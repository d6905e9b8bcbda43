// SPDX-License-Identifier: MIT
//
// Rig simulator speed. Targets: the default 20-object dataset in under 10 s
// on one core, the 25 shared meshes (load + placement + simulation) in under
// 30 s. Baselines measured in the same run: the rig itself (5 frames/s,
// counter `x_realtime`), brute-force ray casting beside the BVH and the
// dense convex hull check beside the ball tree.
//
//   <build>/benchmarks/bench_sim --benchmark_counters_tabular=true

#include <benchmark/benchmark.h>

#include <filesystem>
#include <limits>
#include <string>

#include "iclap/core/random.hpp"
#include "iclap/mesh/mesh.hpp"
#include "iclap/sim/sim.hpp"

namespace {

void report(benchmark::State& state, const iclap::Dataset& ds, double frame_rate) {
  const double frames = static_cast<double>(ds.frames.size());
  state.counters["frames"] = frames;
  state.counters["contact_frames"] = static_cast<double>(iclap::contact_frame_count(ds));
  state.counters["frames_per_s"] = benchmark::Counter(frames, benchmark::Counter::kIsIterationInvariantRate);
  // Seconds the rig would take to record it, per second of simulation.
  state.counters["x_realtime"] =
      benchmark::Counter(frames / frame_rate, benchmark::Counter::kIsIterationInvariantRate);
}

// The 20 built-in objects x 5 explorations, seed 1, one thread.
void simulate_builtin(benchmark::State& state, const iclap::SimulationSettings& settings) {
  const auto objects = iclap::builtin_objects();
  iclap::Dataset ds;
  for (auto _ : state) {
    ds = iclap::simulate_dataset(objects, settings, 1);
    benchmark::DoNotOptimize(ds.frames.data());
  }
  report(state, ds, settings.exploration.frame_rate);
}

void BM_SimulateBuiltinDataset(benchmark::State& state) { simulate_builtin(state, iclap::SimulationSettings{}); }
BENCHMARK(BM_SimulateBuiltinDataset)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

// The covering operator (ExplorationSettings::start_candidates, short
// sweeps, a lift after each: README, "How the operator moves decides the
// coverage") against the default operator above: each new start weighs 8
// candidates, each candidate probed as the default operator probes its one.
void BM_SimulateBuiltinDatasetCovering(benchmark::State& state) {
  iclap::SimulationSettings settings;
  settings.exploration.start_candidates = 8;
  settings.exploration.sweep_length_min = 0.01;
  settings.exploration.sweep_length_max = 0.02;
  settings.exploration.turn_probability = 0;
  simulate_builtin(state, settings);
}
BENCHMARK(BM_SimulateBuiltinDatasetCovering)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

std::string shared_meshes() { return std::string(ICLAP_SHARED_DIR) + "/data/meshes"; }

void BM_SharedMeshesLoadAndPlace(benchmark::State& state) {
  if (!std::filesystem::exists(shared_meshes() + "/meshes.json")) {
    state.SkipWithError("shared meshes not found");
    return;
  }
  std::size_t n = 0;
  for (auto _ : state) {
    const auto objects = iclap::load_mesh_objects(shared_meshes());
    n = objects.size();
    benchmark::DoNotOptimize(objects.data());
  }
  state.counters["objects"] = static_cast<double>(n);
}
BENCHMARK(BM_SharedMeshesLoadAndPlace)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

void BM_SharedMeshesEndToEnd(benchmark::State& state) {
  if (!std::filesystem::exists(shared_meshes() + "/meshes.json")) {
    state.SkipWithError("shared meshes not found");
    return;
  }
  iclap::SimulationSettings settings;
  iclap::Dataset ds;
  for (auto _ : state) {
    const auto objects = iclap::load_mesh_objects(shared_meshes());
    ds = iclap::simulate_dataset(objects, settings, 1);
    benchmark::DoNotOptimize(ds.frames.data());
  }
  report(state, ds, settings.exploration.frame_rate);
}
BENCHMARK(BM_SharedMeshesEndToEnd)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

// Ray casting on a scanned mesh (16k triangles): the BVH against brute force.
struct RayFixture {
  iclap::TriangleMesh mesh;
  std::vector<Eigen::Vector3d> origins, directions;
  RayFixture() {
    const std::string path = shared_meshes() + "/ycb_037_scissors.obj";
    if (std::filesystem::exists(path)) {
      mesh = iclap::place_on_table(iclap::load_mesh(path)).mesh;
    } else {
      mesh = iclap::make_sphere(0.05, 128, 64);
    }
    iclap::Rng rng(1);
    const auto box = iclap::mesh_bounds(mesh);
    for (int i = 0; i < 1024; ++i) {
      const Eigen::Vector3d target(rng.uniform(box.min().x(), box.max().x()), rng.uniform(box.min().y(), box.max().y()),
                                   rng.uniform(box.min().z(), box.max().z()));
      const Eigen::Vector3d from = target + Eigen::Vector3d(rng.normal(), rng.normal(), std::abs(rng.normal())).normalized() * 0.05;
      origins.push_back(from);
      directions.push_back((target - from).normalized());
    }
  }
};

const RayFixture& rays() {
  static const RayFixture f;
  return f;
}

void BM_RayBvh(benchmark::State& state) {
  const auto& f = rays();
  const iclap::MeshBvh bvh(f.mesh);
  std::size_t hits = 0;
  for (auto _ : state) {
    hits = 0;
    for (std::size_t i = 0; i < f.origins.size(); ++i)
      hits += bvh.intersect(f.origins[i], f.directions[i], 0.1, iclap::RaySide::front).has_value();
    benchmark::DoNotOptimize(hits);
  }
  state.counters["triangles"] = static_cast<double>(f.mesh.triangle_count());
  state.counters["hit_fraction"] = static_cast<double>(hits) / static_cast<double>(f.origins.size());
  state.counters["rays_per_s"] =
      benchmark::Counter(static_cast<double>(f.origins.size()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_RayBvh)->Unit(benchmark::kMicrosecond);

void BM_RayBruteForce(benchmark::State& state) {
  const auto& f = rays();
  std::size_t hits = 0;
  const std::size_t n = 64;  // a subset: brute force is slow
  for (auto _ : state) {
    hits = 0;
    for (std::size_t i = 0; i < n; ++i) {
      double best = std::numeric_limits<double>::infinity();
      for (iclap::Index t = 0; t < f.mesh.triangle_count(); ++t) {
        const Eigen::Vector3d a = f.mesh.corner(t, 0), e1 = f.mesh.corner(t, 1) - a, e2 = f.mesh.corner(t, 2) - a;
        const Eigen::Vector3d p = f.directions[i].cross(e2);
        const double det = e1.dot(p);
        if (!(det > 0)) continue;
        const Eigen::Vector3d tv = f.origins[i] - a;
        const double u = tv.dot(p) / det;
        if (u < 0 || u > 1) continue;
        const Eigen::Vector3d q = tv.cross(e1);
        const double v = f.directions[i].dot(q) / det;
        if (v < 0 || u + v > 1) continue;
        const double t_hit = e2.dot(q) / det;
        if (t_hit >= 0 && t_hit <= 0.1) best = std::min(best, t_hit);
      }
      hits += best < std::numeric_limits<double>::infinity();
    }
    benchmark::DoNotOptimize(hits);
  }
  state.counters["triangles"] = static_cast<double>(f.mesh.triangle_count());
  state.counters["rays_per_s"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_RayBruteForce)->Unit(benchmark::kMicrosecond);

// convex_hull's result check (no input point more than 1e-6 of the extent in
// front of a hull face) on the largest shared mesh (27k vertices, 3.8k hull
// triangles): the ball tree against the dense products it replaced.
struct HullCheckFixture {
  Eigen::Matrix3Xd points;
  Eigen::MatrixX3d normals;
  Eigen::VectorXd offsets;
  double tolerance = 0;
  HullCheckFixture() {
    const std::string path = shared_meshes() + "/wt_clamp.ply";
    points = std::filesystem::exists(path) ? iclap::load_mesh(path).vertices : iclap::make_sphere(0.05, 128, 64).vertices;
    const iclap::TriangleMesh hull = iclap::convex_hull(points);
    normals.resize(hull.triangle_count(), 3);
    offsets.resize(hull.triangle_count());
    for (iclap::Index t = 0; t < hull.triangle_count(); ++t) {
      const Eigen::Vector3d u = hull.area_normal(t).normalized();
      normals.row(t) = u.transpose();
      offsets[t] = u.dot(hull.corner(t, 0));
    }
    tolerance = 1e-6 * (points.rowwise().maxCoeff() - points.rowwise().minCoeff()).maxCoeff();
  }
};

const HullCheckFixture& hull_check() {
  static const HullCheckFixture f;
  return f;
}

void hull_check_counters(benchmark::State& state, const HullCheckFixture& f) {
  state.counters["points"] = static_cast<double>(f.points.cols());
  state.counters["faces"] = static_cast<double>(f.normals.rows());
}

void BM_HullCheckBallTree(benchmark::State& state) {
  const auto& f = hull_check();
  for (auto _ : state) benchmark::DoNotOptimize(iclap::detail::worst_point_in_front(f.normals, f.offsets, f.points, f.tolerance));
  hull_check_counters(state, f);
}
BENCHMARK(BM_HullCheckBallTree)->Unit(benchmark::kMillisecond);

void BM_HullCheckDense(benchmark::State& state) {
  const auto& f = hull_check();
  for (auto _ : state) benchmark::DoNotOptimize(iclap::detail::worst_point_in_front_dense(f.normals, f.offsets, f.points));
  hull_check_counters(state, f);
}
BENCHMARK(BM_HullCheckDense)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

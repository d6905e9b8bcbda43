// SPDX-License-Identifier: MIT
// The tactile pipeline's costs: descriptor extraction per 14 x 6 frame,
// codebook fit at the paper's scale (8,500 Tactile-SIFT features, k = 50)
// against plain Lloyd as the baseline, and single-feature assignment through
// brute force vs the kd-tree. Frames are synthetic WTS-like contacts
// (tests/tactile/synthetic_contacts.hpp).
#include <benchmark/benchmark.h>

#include <vector>

#include "../tests/tactile/synthetic_contacts.hpp"
#include "iclap/search/kdtree.hpp"
#include "iclap/tactile/tactile.hpp"

using namespace iclap;

namespace {

constexpr Index kPaperFeatures = 8500;  // the paper collected 8,492 tactile images
constexpr Index kPaperWords = 50;

const std::vector<Eigen::MatrixXd>& frames() {
  static const std::vector<Eigen::MatrixXd> f = [] {
    Rng rng(2018);
    return test::synthetic_contacts(kPaperFeatures, rng, {std::begin(test::kAllShapes), std::end(test::kAllShapes)},
                                    {1, 1, 1, 1, 1});
  }();
  return f;
}

const std::vector<TactileImage>& images() {
  static const std::vector<TactileImage> im = [] {
    std::vector<TactileImage> v;
    for (const auto& p : frames()) v.emplace_back(p);
    return v;
  }();
  return im;
}

const Cloud<float, 72>& sift_features() {
  static const Cloud<float, 72> f = extract_features(TactileSift<>(), images());
  return f;
}

// --- descriptor extraction per frame ---------------------------------------
template <typename D>
void BM_Descriptor(benchmark::State& state, const D& descriptor) {
  const auto& im = images();
  std::size_t i = 0;
  for (auto _ : state) {
    auto f = descriptor.compute(im[i]);
    benchmark::DoNotOptimize(f.data());
    if (++i == im.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
}

TactileSift<float>::Settings upsampled() {
  TactileSift<float>::Settings s;
  s.upsample = 2;
  return s;
}
TactileSift<float>::Settings box() {
  TactileSift<float>::Settings s;
  s.spatial = SiftSpatialBinning::Box;
  return s;
}
DynamicTactileSift<float>::Settings dynamic_default() { return {}; }

BENCHMARK_CAPTURE(BM_Descriptor, TactileSift_3x3x8_fixed, TactileSift<float>());
BENCHMARK_CAPTURE(BM_Descriptor, TactileSift_3x3x8_double, TactileSift<double>());
BENCHMARK_CAPTURE(BM_Descriptor, TactileSift_3x3x8_dynamic, DynamicTactileSift<float>(dynamic_default()));
BENCHMARK_CAPTURE(BM_Descriptor, TactileSift_3x3x8_box, TactileSift<float>(box()));
BENCHMARK_CAPTURE(BM_Descriptor, TactileSift_3x3x8_upsample2, TactileSift<float>(upsampled()));
BENCHMARK_CAPTURE(BM_Descriptor, RawPressures_14x6_fixed, RawPressures<float, 14, 6>());
BENCHMARK_CAPTURE(BM_Descriptor, RawPressures_dynamic, RawPressures<float>());
BENCHMARK_CAPTURE(BM_Descriptor, Moments, MomentsDescriptor<float>());

/// Building the validated image from a dataset frame (copy + checks).
void BM_TactileImageFromFrame(benchmark::State& state) {
  const auto& f = frames();
  std::size_t i = 0;
  for (auto _ : state) {
    TactileImage image(f[i]);
    benchmark::DoNotOptimize(image.pressures().data());
    if (++i == f.size()) i = 0;
  }
}
BENCHMARK(BM_TactileImageFromFrame);

// --- codebook fit at the paper's scale -------------------------------------
template <typename Search>
void BM_FitCodebook(benchmark::State& state) {
  const auto& x = sift_features();
  KMeansQuantizer<float, 72, Search> q;
  q.settings.k = kPaperWords;
  q.settings.pruning = state.range(0) != 0;
  KMeansResult r;
  for (auto _ : state) {
    r = q.fit(x);
    benchmark::DoNotOptimize(q.centres().data());
  }
  state.counters["iterations"] = r.iterations;
  state.counters["inertia"] = r.inertia;
  // Share of plain Lloyd's n k distances per step that were evaluated.
  state.counters["dist_eval_pct"] = 100.0 * static_cast<double>(r.distance_evaluations) /
                                    (static_cast<double>(r.assignment_steps) * static_cast<double>(x.cols()) * kPaperWords);
  state.counters["features"] = static_cast<double>(x.cols());
}
// Arg(0) = plain Lloyd (every feature searched every iteration): the baseline.
BENCHMARK_TEMPLATE(BM_FitCodebook, BruteForceSearch<float, 72>)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_FitCodebook, KdTreeSearch<float, 72>)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

// --- assignment of one feature ---------------------------------------------
template <typename Search>
const KMeansQuantizer<float, 72, Search>& codebook() {
  static const KMeansQuantizer<float, 72, Search> q = [] {
    KMeansQuantizer<float, 72, Search> k;
    k.settings.k = kPaperWords;
    k.fit(sift_features());
    return k;
  }();
  return q;
}

template <typename Search>
void BM_AssignOne(benchmark::State& state) {
  const auto& q = codebook<Search>();
  const auto& x = sift_features();
  Index j = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(q.assign(x.col(j).data()));
    if (++j == x.cols()) j = 0;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK_TEMPLATE(BM_AssignOne, BruteForceSearch<float, 72>);
BENCHMARK_TEMPLATE(BM_AssignOne, KdTreeSearch<float, 72>);

/// The checked Eigen overload (length and finiteness checks, a copy).
void BM_AssignOneChecked(benchmark::State& state) {
  const auto& q = codebook<BruteForceSearch<float, 72>>();
  const auto& x = sift_features();
  Index j = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(q.assign(x.col(j)));
    if (++j == x.cols()) j = 0;
  }
}
BENCHMARK(BM_AssignOneChecked);

/// One touch end to end: frame -> image -> Tactile-SIFT -> word.
void BM_TouchToWord(benchmark::State& state) {
  const auto& q = codebook<BruteForceSearch<float, 72>>();
  const auto& f = frames();
  const TactileSift<> sift;
  std::size_t i = 0;
  for (auto _ : state) {
    const TactileImage image(f[i]);
    const auto feature = sift.compute(image);
    benchmark::DoNotOptimize(q.assign(feature.data()));
    if (++i == f.size()) i = 0;
  }
}
BENCHMARK(BM_TouchToWord);

}  // namespace

BENCHMARK_MAIN();

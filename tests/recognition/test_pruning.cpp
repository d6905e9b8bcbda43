// SPDX-License-Identifier: MIT
// Lower bounds, pruned decisions, multi-start and reference subsampling of
// the registration classifiers.
#include <doctest/doctest.h>

#include <cmath>

#include "iclap/core/random.hpp"
#include "iclap/recognition/recognition.hpp"

using namespace iclap;

namespace {

/// `count` bar-like objects of different lengths and heights, touches with
/// words 0..3 by position along the bar; one training set per object and
/// test sets drawn from a re-placed copy.
struct Scene {
  std::vector<TouchSet> objects;
  std::vector<std::pair<Index, TouchSet>> tests;
};

TouchSet bar(Rng& rng, double length, double height, int n, double yaw, Eigen::Vector2d shift) {
  TouchSet s;
  s.positions.resize(3, n);
  s.words.resize(n);
  const double c = std::cos(yaw), sn = std::sin(yaw);
  for (int i = 0; i < n; ++i) {
    const double u = rng.uniform(-0.5, 0.5) * length;
    const double v = rng.uniform(-0.008, 0.008);
    s.positions.col(i) << c * u - sn * v + shift.x(), sn * u + c * v + shift.y(), height + rng.normal(0, 2e-4);
    s.words(i) = static_cast<Index>(std::floor((u / length + 0.5) * 3.999));
  }
  return s;
}

Scene make_scene(int count, std::uint64_t seed, double test_yaw = 0.05) {
  Rng rng(seed);
  Scene sc;
  for (int o = 0; o < count; ++o) {
    const double length = 0.08 + 0.01 * (o % 7);
    const double height = 0.005 + 0.004 * (o % 5);
    sc.objects.push_back(bar(rng, length, height, 120, 0.0, Eigen::Vector2d::Zero()));
    for (int t = 0; t < 3; ++t)
      sc.tests.emplace_back(o, bar(rng, length, height, 12, test_yaw, Eigen::Vector2d(0.003, -0.002)));
  }
  return sc;
}

}  // namespace

TEST_CASE("lower bounds never exceed the final errors") {
  const Scene sc = make_scene(12, 1);
  IclapClassifier<double, Planar> iclap;
  iclap.embedding.label_scale = 0.002;
  iclap.fit(sc.objects, 4);
  IcpClassifier<float, Planar> icp;
  icp.fit(sc.objects, 4);
  for (const auto& [truth, test] : sc.tests) {
    (void)truth;
    Eigen::VectorXd d(12);
    iclap.distances(test, d);
    const Eigen::VectorXd lb = iclap.lower_bounds(test);
    for (Index j = 0; j < 12; ++j) CHECK(lb(j) <= d(j) * (1 + 1e-9) + 1e-15);
    CHECK(lb.maxCoeff() > 0);  // z and labels do bound
    icp.distances(test, d);
    const Eigen::VectorXd lb3 = icp.lower_bounds(test);
    for (Index j = 0; j < 12; ++j) CHECK(lb3(j) <= d(j) * (1 + 1e-5) + 1e-12);
    // Trimmed: the smallest per-point bounds, as many as pairs are kept.
    for (double fraction : {0.25, 0.5, 0.9}) {
      IclapClassifier<double, Planar> trimmed = iclap;
      trimmed.icp.rejection.trim_fraction = fraction;
      trimmed.distances(test, d);
      const Eigen::VectorXd lbt = trimmed.lower_bounds(test);
      for (Index j = 0; j < 12; ++j) {
        CHECK(lbt(j) <= d(j) * (1 + 1e-9) + 1e-15);
        CHECK(lbt(j) <= lb(j));
      }
      CHECK(lbt.maxCoeff() > 0);
    }
  }
  // A model that moves every coordinate leaves nothing to bound.
  IclapClassifier<double, FullRigid> full;
  full.fit(sc.objects, 4);
  CHECK(full.lower_bounds(sc.tests[0].second).isZero(0));
}

namespace {

struct BoundTally {
  Index pruned = 0, completed = 0;
  int correct = 0;
};

/// Over every test of `sc`: the Bound decision of `c` is the full
/// registration's (and the argmin of its distances), with every object
/// either registered or pruned.
BoundTally check_bound_is_exact(const IclapClassifier<float, Planar>& c, const Scene& sc) {
  BoundTally tally;
  const Index n = static_cast<Index>(sc.objects.size());
  for (const auto& [truth, test] : sc.tests) {
    Eigen::VectorXd d(n);
    c.distances(test, d);
    const PrunedDecision full = c.decide(test, {PruningSettings::Schedule::None});
    const PrunedDecision bound = c.decide(test, {PruningSettings::Schedule::Bound});
    CHECK(full.object == decide(d));
    CHECK(bound.object == full.object);
    CHECK(bound.error == full.error);
    CHECK(full.completed == n);
    CHECK(bound.completed + bound.pruned == n);
    tally.pruned += bound.pruned;
    tally.completed += bound.completed;
    tally.correct += bound.object == truth;
  }
  return tally;
}

}  // namespace

TEST_CASE("bound pruning gives exactly the decisions of the full registration, with less work") {
  const Scene sc = make_scene(30, 2);
  IclapClassifier<float, Planar> c;
  c.embedding.label_scale = 0.002;
  c.fit(sc.objects, 4);
  const BoundTally plain = check_bound_is_exact(c, sc);
  CHECK(plain.pruned > plain.completed);  // most registrations are skipped on this scene
  CHECK(plain.correct > static_cast<int>(sc.tests.size()) / 10);  // well above chance (1/30)
  // Trimmed ICP keeps an exact bound (the smallest per-point bounds).
  IclapClassifier<float, Planar> trimmed = c;
  trimmed.icp.rejection.trim_fraction = 0.5f;
  trimmed.fit(sc.objects, 4);
  CHECK(check_bound_is_exact(trimmed, sc).pruned > 0);
  // With a distance cut-off the bound is not valid and is not used.
  IclapClassifier<float, Planar> cut = c;
  cut.icp.rejection.max_distance = 0.05f;
  cut.fit(sc.objects, 4);
  const PrunedDecision t = cut.decide(sc.tests[0].second, {PruningSettings::Schedule::Bound});
  CHECK(t.pruned == 0);
  CHECK(t.completed == 30);
  CHECK(c.lower_bounds(sc.tests[0].second).maxCoeff() > 0);
  CHECK(cut.lower_bounds(sc.tests[0].second).isZero(0));  // the only bound that holds
}

TEST_CASE("successive halving: valid decisions, fewer iterations, settings checked") {
  const Scene sc = make_scene(30, 3);
  IclapClassifier<float, Planar> c;
  c.embedding.label_scale = 0.002;
  c.fit(sc.objects, 4);
  PruningSettings halving;
  halving.schedule = PruningSettings::Schedule::Halving;
  long long it_full = 0, it_halving = 0;
  int agree = 0;
  for (const auto& [truth, test] : sc.tests) {
    (void)truth;
    const PrunedDecision full = c.decide(test, {PruningSettings::Schedule::None});
    const PrunedDecision h = c.decide(test, halving);
    REQUIRE(h.object >= 0);
    CHECK(h.object < 30);
    CHECK(h.completed + h.pruned + h.eliminated == 30);
    CHECK(h.completed >= 1);
    it_full += full.iterations;
    it_halving += h.iterations;
    agree += h.object == full.object;
  }
  CHECK(it_halving < it_full);
  CHECK(agree >= static_cast<int>(sc.tests.size()) * 9 / 10);
  PruningSettings bad;
  bad.keep_fraction = 1.0;
  CHECK_THROWS_AS(c.decide(sc.tests[0].second, bad), InvalidArgument);
}

TEST_CASE("a shortlist registers only the objects with the smallest bounds") {
  const Scene sc = make_scene(30, 4);
  IclapClassifier<float, Planar> c;
  c.embedding.label_scale = 0.002;
  c.fit(sc.objects, 4);
  int agree = 0;
  for (const auto& [truth, test] : sc.tests) {
    (void)truth;
    const PrunedDecision exact = c.decide(test, {PruningSettings::Schedule::Bound});
    const Eigen::VectorXd lb = c.lower_bounds(test);
    PruningSettings all;
    all.shortlist = 30;  // every object: the exact decision
    const PrunedDecision whole = c.decide(test, all);
    CHECK(whole.object == exact.object);
    CHECK(whole.completed == exact.completed);
    CHECK(whole.eliminated == 0);
    PruningSettings one;
    one.shortlist = 1;  // the smallest bound alone, ties to the smaller index
    const PrunedDecision first = c.decide(test, one);
    Index argmin = 0;
    for (Index j = 1; j < lb.size(); ++j)
      if (lb(j) < lb(argmin)) argmin = j;
    CHECK(first.object == argmin);
    CHECK(first.completed == 1);
    CHECK(first.eliminated == 29);
    for (auto schedule : {PruningSettings::Schedule::Bound, PruningSettings::Schedule::Halving}) {
      PruningSettings five;
      five.schedule = schedule;
      five.shortlist = 5;
      const PrunedDecision d = c.decide(test, five);
      CHECK(d.completed + d.pruned + d.eliminated == 30);
      CHECK(d.eliminated >= 25);
      // Among the five smallest bounds.
      Index below = 0;
      for (Index j = 0; j < lb.size(); ++j) below += lb(j) < lb(d.object);
      CHECK(below < 5);
      if (schedule == PruningSettings::Schedule::Bound) agree += d.object == exact.object;
    }
  }
  // The bound ranks well: five objects chosen at random would hold the exact
  // winner 1 time in 6; the five smallest bounds hold it most of the time
  // (79 of 90 tests here).
  CHECK(agree >= static_cast<int>(sc.tests.size()) * 3 / 4);
  PruningSettings bad;
  bad.shortlist = -1;
  CHECK_THROWS_AS(c.decide(sc.tests[0].second, bad), InvalidArgument);
  // No bound (a motion of every coordinate): a shortlist cannot be formed.
  IclapClassifier<float, FullRigid> full;
  full.embedding.label_scale = 0.002;
  full.fit(sc.objects, 4);
  PruningSettings five;
  five.shortlist = 5;
  CHECK_THROWS_AS(full.decide(sc.tests[0].second, five), InvalidArgument);
  five.schedule = PruningSettings::Schedule::None;  // ignored there
  CHECK(full.decide(sc.tests[0].second, five).completed == 30);
}

TEST_CASE("multi-start widens the basin; subsampling bounds the reference size") {
  // Tests turned by 50 degrees: far outside the basin of a start at 0.
  const Scene sc = make_scene(6, 4, 50.0 * 3.141592653589793 / 180.0);
  IcpClassifier<double, Planar> one, many;
  many.yaw_starts_deg = {-60, -30, 0, 30, 60};
  one.fit(sc.objects, 4);
  many.fit(sc.objects, 4);
  int better = 0;
  for (const auto& [truth, test] : sc.tests) {
    Eigen::VectorXd a(6), b(6);
    one.distances(test, a);
    many.distances(test, b);
    CHECK((b.array() <= a.array() * (1 + 1e-9)).all());  // the minimum over starts includes 0
    better += b(truth) < 0.5 * a(truth);
  }
  CHECK(better > 0);  // some tests only converge from another start
  many.yaw_starts_deg = {};
  Eigen::VectorXd out(6);
  CHECK_THROWS_AS(many.distances(sc.tests[0].second, out), InvalidArgument);

  IcpClassifier<float, Planar> small;
  small.max_reference_points = 25;
  small.fit(sc.objects, 4);
  for (const auto& r : small.references()) CHECK(r.size() == 25);
}

TEST_CASE("the reference search settings change the speed, never the distances") {
  const Scene sc = make_scene(8, 5);
  // by_default scans these small references by brute force (AdaptiveSearch);
  // the others are kd-trees of several leaf sizes, or brute force without AVX2.
  IclapClassifier<float, Planar> by_default, tiny_leaves, one_leaf, baseline_isa;
  by_default.embedding.label_scale = tiny_leaves.embedding.label_scale = one_leaf.embedding.label_scale =
      baseline_isa.embedding.label_scale = 0.002;
  CHECK(by_default.search_settings.leaf_max_size == 24);
  tiny_leaves.search_settings.brute_force_max_coordinates = one_leaf.search_settings.brute_force_max_coordinates = 0;
  tiny_leaves.search_settings.leaf_max_size = 1;
  one_leaf.search_settings.leaf_max_size = 1000;  // one leaf: brute force inside the tree
  baseline_isa.search_settings.use_avx2 = false;
  for (auto* c : {&by_default, &tiny_leaves, &one_leaf, &baseline_isa}) c->fit(sc.objects, 4);
  CHECK(!by_default.references().front().search().uses_tree());
  CHECK(tiny_leaves.references().front().search().uses_tree());
  IcpClassifier<double, Planar> icp_default, icp_tiny;
  icp_tiny.search_settings.brute_force_max_coordinates = 0;
  icp_tiny.search_settings.leaf_max_size = 2;
  icp_default.fit(sc.objects, 4);
  icp_tiny.fit(sc.objects, 4);
  for (const auto& [truth, test] : sc.tests) {
    (void)truth;
    Eigen::VectorXd a(8), b(8), c(8), d(8);
    by_default.distances(test, a);
    tiny_leaves.distances(test, b);
    one_leaf.distances(test, c);
    baseline_isa.distances(test, d);
    CHECK(a == b);  // bit for bit: same neighbours, same arithmetic
    CHECK(a == c);
    CHECK(a == d);
    icp_default.distances(test, a);
    icp_tiny.distances(test, b);
    CHECK(a == b);
  }
  // A leaf size of 0 is refused even where the references would not need a tree.
  IclapClassifier<float, Planar> bad;
  bad.search_settings.leaf_max_size = 0;
  CHECK_THROWS_AS(bad.fit(sc.objects, 4), InvalidArgument);
}

namespace {
/// The touches of every test of `sc`, one after another.
TouchSet pool_of(const Scene& sc) {
  Index n = 0;
  for (const auto& t : sc.tests) n += t.second.size();
  TouchSet pool;
  pool.positions.resize(3, n);
  pool.words.resize(n);
  Index k = 0;
  for (const auto& t : sc.tests) {
    pool.positions.middleCols(k, t.second.size()) = t.second.positions;
    pool.words.segment(k, t.second.size()) = t.second.words;
    k += t.second.size();
  }
  return pool;
}

/// Positions, with the per-touch promise withdrawn.
struct UnpromisedEmbedding : PositionEmbedding {
  static constexpr bool per_touch = false;
};
/// A user's embedding that does not mention the promise makes none.
struct Silent {};
static_assert(!detail::embeds_per_touch<Silent>::value);
static_assert(!detail::embeds_per_touch<UnpromisedEmbedding>::value);
static_assert(detail::embeds_per_touch<PositionEmbedding>::value);

template <typename C>
void check_pool(const C& c, const TouchSet& pool, Index objects) {
  const auto prepared = c.prepare_pool(pool);
  REQUIRE(prepared != nullptr);
  Rng rng(17);
  for (Index n : {1, 3, 12, 30}) {
    std::vector<Index> subset;
    for (Index k = 0; k < n; ++k)
      subset.push_back(static_cast<Index>(rng.below(static_cast<std::uint64_t>(pool.size()))));
    Eigen::VectorXd a(objects), b(objects), none(objects);
    c.pool_distances(pool, prepared.get(), subset, a);
    c.distances(select_touches(pool, subset), b);
    c.pool_distances(pool, nullptr, subset, none);
    CAPTURE(n);
    CHECK(a == b);  // bit for bit
    CHECK(none == b);
  }
}
}  // namespace

TEST_CASE("first matches prepared for a pool: every subset's distances unchanged, bit for bit") {
  const Scene sc = make_scene(8, 6, 0.3);
  const TouchSet pool = pool_of(sc);
  IcpClassifier<float, Planar> icp;
  IclapClassifier<float, Planar> iclap;
  iclap.embedding.label_scale = 0.002;
  IclapClassifier<double, SpatialRigid> trimmed;
  trimmed.icp.rejection.trim_fraction = 0.7;
  IcpClassifier<float, Planar> starts;  // only the zero start uses them
  starts.yaw_starts_deg = {-30, 0, 30};
  for (Classifier* c : std::initializer_list<Classifier*>{&icp, &iclap, &trimmed, &starts}) c->fit(sc.objects, 4);
  check_pool(icp, pool, 8);
  check_pool(iclap, pool, 8);
  check_pool(trimmed, pool, 8);
  check_pool(starts, pool, 8);

  // Nothing to reuse: no zero start, centroid alignment, an embedding
  // without the per-touch promise. pool_distances still gives the distances.
  IcpClassifier<float, Planar> turned;
  turned.yaw_starts_deg = {-30, 30};
  IcpClassifier<float, Planar> centred;
  centred.icp.centroid_alignment = true;
  RegistrationClassifier<UnpromisedEmbedding, float> unpromised;
  for (Classifier* c : std::initializer_list<Classifier*>{&turned, &centred, &unpromised}) {
    c->fit(sc.objects, 4);
    CHECK(c->prepare_pool(pool) == nullptr);
    Eigen::VectorXd a(8), b(8);
    c->pool_distances(pool, nullptr, {2, 5, 7}, a);
    c->distances(select_touches(pool, std::vector<Index>{2, 5, 7}), b);
    CHECK(a == b);
  }
}

TEST_CASE("a prepared pool is refused by another classifier, pool or fit") {
  const Scene sc = make_scene(4, 7);
  const TouchSet pool = pool_of(sc);
  IcpClassifier<float, Planar> icp, other;
  CHECK_THROWS_WITH_AS(icp.prepare_pool(pool), doctest::Contains("before fit"), InvalidArgument);
  icp.fit(sc.objects, 4);
  other.fit(sc.objects, 4);
  const auto prepared = icp.prepare_pool(pool);
  Eigen::VectorXd out(4);
  auto argument = [&](auto&& f) {
    try {
      f();
    } catch (const InvalidArgument& e) {
      return e.argument();
    }
    return std::string("(no exception)");
  };
  CHECK(argument([&] { other.pool_distances(pool, prepared.get(), {0, 1}, out); }) == "prepared");
  const TouchSet smaller = select_touches(pool, std::vector<Index>{0, 1, 2});
  CHECK(argument([&] { icp.pool_distances(smaller, prepared.get(), {0, 1}, out); }) == "prepared");
  CHECK(argument([&] { icp.pool_distances(pool, prepared.get(), {0, -1}, out); }) == "subset");
  CHECK(argument([&] { icp.pool_distances(pool, prepared.get(), {0, 1}, out.head(3)); }) == "out");
  icp.pool_distances(pool, prepared.get(), {0, 1}, out);  // still valid
  icp.fit(sc.objects, 4);                                 // a refit makes it stale
  CHECK(argument([&] { icp.pool_distances(pool, prepared.get(), {0, 1}, out); }) == "prepared");
  // A pool of the same size but other touches: the drawn touches'
  // fingerprints differ (detail::touch_fingerprint), one position by a bit
  // is enough.
  TouchSet moved = pool;
  moved.positions.row(0).array() += 0.01;
  const auto fresh = icp.prepare_pool(pool);
  CHECK(argument([&] { icp.pool_distances(moved, fresh.get(), {0, 1}, out); }) == "prepared");
  TouchSet nudged = pool;
  nudged.positions(2, 1) = std::nextafter(nudged.positions(2, 1), 1.0);
  CHECK(argument([&] { icp.pool_distances(nudged, fresh.get(), {0, 1}, out); }) == "prepared");
  icp.pool_distances(TouchSet(pool), fresh.get(), {0, 1}, out);  // a copy is the same pool
  // Another classifier type's preparation of this very pool, and a
  // preparation a user type made without a fit and pool.
  IclapClassifier<float, Planar> iclap;
  iclap.fit(sc.objects, 4);
  const auto foreign = iclap.prepare_pool(pool);
  REQUIRE(foreign);
  Eigen::VectorXd with(4), without(4);
  iclap.pool_distances(pool, foreign.get(), {0, 1}, with);
  iclap.pool_distances(pool, nullptr, {0, 1}, without);
  CHECK(with == without);
  CHECK(argument([&] { icp.pool_distances(pool, foreign.get(), {0, 1}, out); }) == "prepared");
  // Only the drawn touches are compared: a change elsewhere in the pool
  // leaves the draw's distances what they were, a change in a drawn touch's
  // word or descriptor (which iCLAP and iCLAP-N read) is refused.
  TouchSet elsewhere = pool;
  elsewhere.positions(0, 5) += 0.01;
  Eigen::VectorXd same(4);
  icp.pool_distances(elsewhere, fresh.get(), {0, 1}, same);
  icp.pool_distances(pool, nullptr, {0, 1}, out);
  CHECK(same == out);
  TouchSet reworded = pool;
  reworded.words(1) = (reworded.words(1) + 1) % 4;
  CHECK(argument([&] { icp.pool_distances(reworded, fresh.get(), {0, 1}, out); }) == "prepared");
  TouchSet described = pool;
  described.features = Eigen::MatrixXf::Constant(2, pool.size(), 0.5f);
  const auto with_features = icp.prepare_pool(described);
  TouchSet redescribed = described;
  redescribed.features(1, 0) = std::nextafter(0.5f, 1.0f);
  CHECK(argument([&] { icp.pool_distances(redescribed, with_features.get(), {0, 1}, out); }) == "prepared");
  CHECK(argument([&] { icp.pool_distances(redescribed, with_features.get(), {1, 2}, out); }) == "(no exception)");
  CHECK(argument([&] { icp.pool_distances(pool, with_features.get(), {1, 2}, out); }) == "prepared");  // shape
  struct Bare final : PreparedPool {};
  const Bare bare;
  CHECK_FALSE(bare.made_for(0, pool, {0, 1}));
  // The base class alone: its fit, its touches, and an index outside the
  // pool is false (nothing read past the fingerprints).
  struct Probe final : PreparedPool {
    Probe(std::uint64_t fit_id, const TouchSet& p) : PreparedPool(fit_id, p) {}
  };
  const Probe probe(7, pool);
  CHECK(probe.made_for(7, pool, {0, 1}));
  CHECK_FALSE(probe.made_for(8, pool, {0, 1}));
  CHECK_FALSE(probe.made_for(7, pool, {0, pool.size()}));
  CHECK_FALSE(probe.made_for(7, pool, {-1}));
  CHECK_FALSE(probe.made_for(7, nudged, {1}));
  CHECK(probe.made_for(7, nudged, {0, 2}));
  CHECK(argument([&] { icp.pool_distances(pool, &bare, {0, 1}, out); }) == "prepared");
}

TEST_CASE("every schedule counts registrations per object and start; finalists run to the end") {
  const Scene sc = make_scene(8, 8);
  IclapClassifier<float, Planar> c;
  c.embedding.label_scale = 0.002;
  c.yaw_starts_deg = {-20, 0, 20};
  c.fit(sc.objects, 4);
  const Index all = 8 * 3;  // objects x starts
  for (std::size_t t = 0; t < sc.tests.size(); t += 4) {
    CAPTURE(t);
    const TouchSet& test = sc.tests[t].second;
    const PrunedDecision full = c.decide(test, {PruningSettings::Schedule::None});
    CHECK(full.completed == all);
    CHECK(full.pruned + full.eliminated == 0);
    const PrunedDecision bound = c.decide(test, {PruningSettings::Schedule::Bound});
    CHECK(bound.object == full.object);
    CHECK(bound.completed + bound.pruned == all);
    CHECK(bound.completed % 3 == 0);
    PruningSettings three;
    three.shortlist = 3;
    const PrunedDecision shortlisted = c.decide(test, three);
    CHECK(shortlisted.eliminated == 5 * 3);
    CHECK(shortlisted.completed + shortlisted.pruned == 3 * 3);
    PruningSettings halving;
    halving.schedule = PruningSettings::Schedule::Halving;
    const PrunedDecision h = c.decide(test, halving);
    CHECK(h.completed + h.pruned + h.eliminated == all);
    // As many finalists as objects: nothing is eliminated, and every
    // registration the bound leaves runs to its end.
    halving.finalists = 8;
    const PrunedDecision everyone = c.decide(test, halving);
    CHECK(everyone.eliminated == 0);
    CHECK(everyone.object == full.object);
    CHECK(everyone.error == full.error);
  }
}

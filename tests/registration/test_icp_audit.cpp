// SPDX-License-Identifier: MIT
// Reproducers of defects found by a user-side audit of the N-D ICP and
// search API (helper-46, session 51), fixed since. What used to crash
// (Eigen assertions, bad reads) runs in a child process, so that the suite
// itself would survive a regression.

#include <string>
#include <type_traits>
#include <utility>

#include "../support/child_outcome.hpp"
#include "../support/errors.hpp"
#include "icp_test_util.hpp"
#include "iclap/search/distance_field.hpp"

using namespace iclap;
using namespace iclap::test;

// Expected: a fixed-dimension search given a cloud of another row count (a
// MatrixXd, as for every other entry point) throws DimensionMismatch naming
// "points", as ReferenceCloud does and as the README promises for
// mismatched dimensions (KMeansQuantizer was fixed for the same reason).
// Happened: the constructors take `CloudType` by value, so Eigen converts
// the matrix before any check: an Eigen assertion (SIGABRT) in a debug
// build; in a release build 4 rows are silently cut to 3 and 2 rows are
// copied into a 2-row buffer read as 3 rows (a heap overflow).
TEST_CASE("a fixed-dimension search refuses a cloud of another row count, naming points") {
  const Eigen::MatrixXd four = random_points(4, 10, 1), two = random_points(2, 10, 2);
  CHECK(outcome_in_child([&] {
          const KdTreeSearch<double, 3> s(four);
          return "built, dim " + std::to_string(s.dim());
        }) == "DimensionMismatch points");
  CHECK(outcome_in_child([&] {
          const BruteForceSearch<double, 3> s(two);
          return "built, dim " + std::to_string(s.dim());
        }) == "DimensionMismatch points");
  CHECK(outcome_in_child([&] {
          const AdaptiveSearch<float, 3> s(Eigen::MatrixXf(four.cast<float>()));
          return "built, dim " + std::to_string(s.dim());
        }) == "DimensionMismatch points");
}

// Expected (SharedCloudSearch::nearest, shared_cloud.hpp): "the search over
// an empty cloud answers index -1 to any query"; AdaptiveSearch, whose
// dim() is 0 then, may instead refuse the length naming "query".
// Happened: with a fixed Dim, a default-constructed search skips the length
// check and converts the query to Point<Scalar, Dim>: an Eigen assertion
// (SIGABRT) in a debug build, a read past a shorter query in release.
TEST_CASE("a default-constructed fixed-dimension search answers a query of any length") {
  const Eigen::VectorXd five = Eigen::VectorXd::Zero(5), two = Eigen::VectorXd::Zero(2);
  CHECK(outcome_in_child([&] { return std::to_string(KdTreeSearch<double, 3>().nearest(five).index); }) == "-1");
  CHECK(outcome_in_child([&] { return std::to_string(BruteForceSearch<double, 3>().nearest(two).index); }) == "-1");
  const std::string adaptive =
      outcome_in_child([&] { return std::to_string(AdaptiveSearch<double, 3>().nearest(two).index); });
  CAPTURE(adaptive);
  CHECK(adaptive == "-1");
}

// A ReferenceCloud whose search policy keeps its points in another cloud
// type (`KdTreeSearch<double>` or `AdaptiveSearch<double>`, their default
// Dim being Eigen::Dynamic, under a ReferenceCloud<double, 3>) used to
// compile with only a -Wreturn-local-addr warning, and working_points()
// returned a reference to a converted temporary that Icp::estimate read (a
// crash). It is refused at compile time now, through this trait.
static_assert(search_keeps_cloud_v<KdTreeSearch<double, 3>, double, 3>);
static_assert(search_keeps_cloud_v<AdaptiveSearch<float, 4>, float, 4>);
static_assert(search_keeps_cloud_v<KdTreeSearch<double>, double, Eigen::Dynamic>);
static_assert(!search_keeps_cloud_v<KdTreeSearch<double>, double, 3>);
static_assert(!search_keeps_cloud_v<AdaptiveSearch<double>, double, 3>);
static_assert(!search_keeps_cloud_v<BruteForceSearch<float, 3>, double, 3>);

// Expected: a TruncatedDistanceField given a matrix that is not 3 x n (a
// MatrixXd of 4 rows) throws DimensionMismatch naming "points", as the
// README promises for mismatched dimensions.
// Happened: the constructor takes Eigen::Ref<const Matrix3Xd>, whose
// conversion asserts (SIGABRT) in a debug build before the field sees it.
TEST_CASE("a distance field refuses points that are not 3-D, naming them") {
  const Eigen::MatrixXd four = random_points(4, 10, 4);
  CHECK(outcome_in_child([&] {
          const TruncatedDistanceField field(four);
          return "built, " + std::to_string(field.memory_bytes()) + " bytes";
        }) == "DimensionMismatch points");
}

// Expected: RigidTransform<Scalar, Dynamic>::identity(dim) with a negative
// dim is refused naming "dim" (a fixed Dim refuses any other dim so).
// Happened: Matrix::Identity(-1, -1) trips an Eigen assertion (SIGABRT).
TEST_CASE("a run-time-dimension identity of negative dimension is refused naming dim") {
  const std::string outcome = outcome_in_child(
      [] { return "dim " + std::to_string(RigidTransform<double, Eigen::Dynamic>::identity(-1).dim()); });
  CAPTURE(outcome);
  CHECK(outcome == "InvalidArgument dim");
}

namespace {

/// A model, and two tests of it (of 120 and of 100 points) under different
/// motions, for the resumable registrations below.
struct TwoTests {
  Eigen::Matrix3Xd model = random_points(3, 200, 5);
  Eigen::Matrix3Xd a, b;
  TwoTests() {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.1, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    a = ((R * model).colwise() + Eigen::Vector3d(0.05, 0.02, -0.03)).leftCols(120);
    b = (model.colwise() + Eigen::Vector3d(-0.04, 0.01, 0.02)).rightCols(100);
  }
};

}  // namespace

// Expected: registrations interleaved through `start` / `step` (what the
// README offers it for: "schedules that interleave many registrations")
// that were given one workspace either each end as `align` does, or the
// sharing is refused naming "workspace" (start's doc asks only that the
// workspace outlive the registration; IcpWorkspace's doc invites passing
// "the same workspace to many registrations").
// Happened: the second start overwrites the first's working test points,
// pairs and hints (icp.hpp, Registration keeps `Workspace* ws_`): the first
// registration's next step reads test point 100+ of a 100-column cloud, an
// Eigen assertion (SIGABRT) in a debug build, reads out of bounds and a
// wrong transform in release.
TEST_CASE("two live registrations given one workspace end as align does, or are refused") {
  const TwoTests data;
  const ReferenceCloud<double, 3> ref(data.model);
  const Icp<double, 3> icp;
  const auto expected_a = icp.align(ref, data.a), expected_b = icp.align(ref, data.b);
  const std::string outcome = outcome_in_child([&] {
    IcpWorkspace<double, 3> ws;
    auto ra = icp.start(ref, data.a, nullptr, ws);
    auto rb = icp.start(ref, data.b, nullptr, ws);
    while (!ra.done() || !rb.done()) {
      ra.step();
      rb.step();
    }
    const bool same_a = difference(ra.result().T_model_test.matrix(), expected_a.T_model_test.matrix()) < 1e-12;
    const bool same_b = difference(rb.result().T_model_test.matrix(), expected_b.T_model_test.matrix()) < 1e-12;
    return std::string(same_a && same_b ? "same" : "differs");
  });
  CAPTURE(outcome);
  CHECK(outcome == "InvalidArgument workspace");
}

// A copy of a registration in progress used to share the original's
// workspace and run on its pairs (2 updates where align makes 3). A
// registration is not copyable now, only movable.
using Registration3 = decltype(Icp<double, 3>().start(std::declval<const ReferenceCloud<double, 3>&>(),
                                                      std::declval<const Eigen::Matrix3Xd&>(), nullptr,
                                                      std::declval<IcpWorkspace<double, 3>&>()));
static_assert(!std::is_copy_constructible_v<Registration3>);
static_assert(!std::is_copy_assignable_v<Registration3>);
static_assert(std::is_move_constructible_v<Registration3>);

TEST_CASE("a registration moved along keeps its workspace and ends as align does") {
  const TwoTests data;
  const ReferenceCloud<double, 3> ref(data.model);
  const Icp<double, 3> icp;
  const auto expected = icp.align(ref, data.a);
  IcpWorkspace<double, 3> ws;
  auto original = icp.start(ref, data.a, nullptr, ws);
  REQUIRE(original.step());
  auto moved = std::move(original);
  moved.run();
  CHECK(moved.result().iterations == expected.iterations);
  CHECK(difference(moved.result().T_model_test.matrix(), expected.T_model_test.matrix()) < 1e-12);
}

namespace {

/// A custom rejector (see DistanceRejector's doc) with an off-by-one bug of
/// the kind a user's policy may have: it reports `n + offset` kept pairs.
struct MiscountingRejector {
  Index offset = 0;
  void validate() const {}
  Index select(Correspondence<double>* /*pairs*/, Index n) const { return n + offset; }
};

}  // namespace

// Expected: a custom rejector's count outside [0, n] (its contract: it
// "moves the kept pairs to the front and returns how many it kept") is
// refused naming "rejection", as every other policy setting is checked.
// Happened (icp.hpp, Icp::correspond / Registration::match_and_check use
// the count unchecked): a count of -1 gives E = 0 over "-1 pairs", reported
// as converged (absolute tolerance) at the initial transform; a count of
// n + 1 sums and estimates from the pair past the end of the workspace's
// vector (an out-of-bounds read; here its garbage indices trip an Eigen
// assertion, SIGABRT).
TEST_CASE("a custom rejector's count outside [0, n] is refused, not taken as kept pairs") {
  const Eigen::Matrix3Xd model = random_points(3, 30, 6);
  const Eigen::Matrix3Xd test = model.array() + 0.05;
  const ReferenceCloud<double, 3> ref(model);
  Icp<double, 3, FullRigid, MiscountingRejector> icp;
  icp.rejection.offset = -31;  // n = 30 test points: -1 kept
  std::string outcome;
  try {
    const auto r = icp.align(ref, test);
    outcome = "pairs " + std::to_string(r.pairs) + (r.converged ? ", converged" : ", not converged");
  } catch (const InvalidArgument& e) {
    outcome = "InvalidArgument " + e.argument();
  }
  CHECK(outcome == "InvalidArgument rejection");
  icp.rejection.offset = 1;  // n + 1 kept: read in a child, since it reads past the pairs
  CHECK(outcome_in_child([&] {
          const auto r = icp.align(ref, test);
          return "pairs " + std::to_string(r.pairs);
        }) == "InvalidArgument rejection");
}

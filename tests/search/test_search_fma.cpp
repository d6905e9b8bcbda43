// SPDX-License-Identifier: MIT
// Built with -mfma -ffp-contract=fast (tests/search/CMakeLists.txt), on a
// machine that runs FMA: the searches must still agree bit for bit, which
// iclap's interface option -ffp-contract=off ensures.
#include <doctest/doctest.h>

#include "iclap/core/random.hpp"
#include "iclap/search/brute_force.hpp"
#include "iclap/search/kdtree.hpp"

using namespace iclap;

TEST_CASE("with FMA: kd-tree and brute force give the same neighbour and distance bits on exact ties") {
  // Two points at exactly the same distance from the query, summed in
  // another order: fused and unfused sums round differently, so a kernel
  // that fuses picks the other point or reports other bits.
  Rng rng(7);
  int different_index = 0, different_bits = 0;
  for (int t = 0; t < 20000; ++t) {
    const double a = rng.normal(), b = rng.normal(), c = rng.normal();
    Cloud<double, 3> p(3, 2);
    p.col(0) << a, b, c;
    p.col(1) << b, c, a;
    const KdTreeSearch<double, 3> kd(p);
    const BruteForceSearch<double, 3> brute(p);
    const double q[3] = {0, 0, 0};
    const auto x = kd.nearest(q), y = brute.nearest(q);
    different_index += x.index != y.index;
    different_bits += x.squared_distance != y.squared_distance;
  }
  CHECK(different_index == 0);
  CHECK(different_bits == 0);
}

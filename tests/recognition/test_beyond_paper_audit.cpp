// SPDX-License-Identifier: MIT
// Reproducers of defects found by a user-side audit of the beyond-the-paper
// classifiers (height, occupancy) and the touch data they read (session 52).
// Each case states what the documented contract promises and failed on the
// code before its fix.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "iclap/recognition/height_classifier.hpp"
#include "iclap/recognition/touch_set.hpp"

using namespace iclap;

// contact_extents promises the extents of any finite points: spreads whose
// covariance would overflow are rescaled (test_height covers points whose
// sum overflows). Here the mean is finite but a point's distance from it
// (2.27e308) overflowed to inf before the rescaling, and the result was NaN,
// though the true standard deviation (1.6e308) is a finite double.
TEST_CASE("audit: contact_extents of finite points whose deviations from the mean overflow") {
  Eigen::Matrix3Xd p(3, 3);
  p << 1.7e308, -1.7e308, -1.7e308,  //
      0, 0, 0,                        //
      0, 0, 0;
  const Eigen::Vector2d e = contact_extents(p);
  // x: mean -1.7e308 / 3, deviations (4, -2, -2) 1.7e308 / 3, sd 2 sqrt(2) 1.7e308 / 3.
  const double sd = 2 * std::sqrt(2.0) / 3 * 1.7e308;  // (in this order: no overflow)
  CHECK(std::isfinite(e(0)));
  CHECK(e(0) == doctest::Approx(sd).epsilon(1e-9).scale(0));
  CHECK(e(1) == 0.0);
}

// Classifier::pool_distances (the default, used by HeightClassifier and by
// OccupancyClassifier without a preparation) selects the subset's touches
// before anything validated the pool, so contact offsets that did not match
// the contact points were read as they were: an Eigen assertion in a debug
// build, an out-of-range read in release. distances() and prepare_pool()
// refuse the same pool (TouchSet::validate: InvalidArgument naming
// ".contact_offsets"), and PreparedPool::made_for takes care to read
// nothing outside a pool with corrupt offsets; pool_distances now refuses
// it too (TouchSet::validate_layout).
TEST_CASE("audit: pool_distances refuses a pool whose contact offsets overrun its contact points") {
  HeightClassifier c;
  c.contact_scale = 1;
  TouchSet object;
  object.positions = Eigen::Matrix3Xd::Zero(3, 1);
  object.normals = Eigen::Matrix3Xd::Zero(3, 1);
  object.normals(2, 0) = -1;
  object.contact_points = Eigen::Matrix3Xd::Zero(3, 2);
  object.contact_points(0, 1) = 1e-3;
  object.contact_offsets = {0, 2};
  c.fit({object}, 0);

  TouchSet pool = object;
  pool.contact_offsets = {0, 5};  // 5 points claimed, 2 held
  Eigen::VectorXd d(1);
  // What distances() says of the same touches.
  CHECK_THROWS_AS(c.distances(pool, d), InvalidArgument);
  std::string message;
  try {
    c.pool_distances(pool, nullptr, {0}, d);
  } catch (const InvalidArgument& e) {
    message = e.what();
  }
  CHECK(message.find("contact_offsets") != std::string::npos);
}

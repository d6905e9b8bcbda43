// SPDX-License-Identifier: MIT
// The small synthetic touch table and the classifiers the recognition
// tests share.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/recognition/bow_classifier.hpp"
#include "iclap/recognition/registration_classifier.hpp"
#include "iclap/recognition/touch_table.hpp"

namespace iclap::test {

struct SyntheticTableSettings {
  int touches_per_exploration = 25;
  /// Standard deviation of the noise added to every feature value.
  double feature_noise = 0.05;
  /// Store each exploration's touches out of time order (frame index
  /// (7 i) mod n for the i-th stored touch), so that a consumer has to
  /// restore time order from the frame index.
  bool shuffled_frames = false;
};

/// Three objects on a table, 4 explorations each (ids 10..13: ids need not
/// start at 0): a straight bar (object 0), a ring (object 1) and the same bar
/// with a differently shaped end (object 2: same extent as 0, another local
/// feel at one end). Features are 4-D: a "pattern" per local shape plus
/// noise. Each exploration re-places the object by a small shift.
inline TouchTable synthetic_table(std::uint64_t seed, const SyntheticTableSettings& settings = {}) {
  TouchTable t;
  t.objects = {"bar", "ring", "bar_hooked"};
  Rng rng(seed);
  const int per = settings.touches_per_exploration;
  const int n = 3 * 4 * per;
  t.touches.positions.resize(3, n);
  t.touches.features.resize(4, n);
  Index j = 0;
  for (Index o = 0; o < 3; ++o) {
    for (std::int64_t e = 0; e < 4; ++e) {
      const Eigen::Vector3d shift(rng.uniform(-0.002, 0.002), rng.uniform(-0.002, 0.002), 0.0);
      for (int i = 0; i < per; ++i) {
        const double u = rng.uniform();
        Eigen::Vector3d p;
        Eigen::Vector4f f = Eigen::Vector4f::Zero();
        if (o == 1) {
          const double a = 2 * 3.141592653589793 * u;
          p << 0.03 * std::cos(a), 0.03 * std::sin(a), 0.01;
          f(1) = 1;
        } else {
          p << -0.06 + 0.12 * u, 0.0, 0.01;
          f(u > 0.8 ? (o == 0 ? 2 : 3) : 0) = 1;
        }
        p += shift + Eigen::Vector3d(rng.normal(0, 3e-4), rng.normal(0, 3e-4), rng.normal(0, 3e-4));
        for (Index k = 0; k < 4; ++k) f(k) += static_cast<float>(rng.normal(0, settings.feature_noise));
        t.touches.positions.col(j) = p;
        t.touches.features.col(j) = f;
        t.object.push_back(o);
        t.exploration.push_back(e + 10);
        t.frame.push_back(settings.shuffled_frames ? (i * 7) % per : i);
        ++j;
      }
    }
  }
  return t;
}

/// The paper's three classifiers: bow, icp and iclap with a label axis of
/// 0.01 (one word apart weighs as much as 1 cm, on objects 6-12 cm across).
inline std::vector<std::unique_ptr<Classifier>> paper_classifiers() {
  std::vector<std::unique_ptr<Classifier>> cs;
  cs.push_back(std::make_unique<BowClassifier>());
  cs.push_back(std::make_unique<IcpClassifier<float, Planar>>());
  auto iclap = std::make_unique<IclapClassifier<float, Planar>>();
  iclap->embedding.label_scale = 0.01;
  cs.push_back(std::move(iclap));
  return cs;
}

}  // namespace iclap::test

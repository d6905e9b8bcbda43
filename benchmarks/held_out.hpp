// SPDX-License-Identifier: MIT
#pragma once

// Shared by the recognition benchmarks: exploration 0 of every object held
// out for tests, the codebook and the references from the other explorations.

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/recognition/recognition.hpp"

namespace iclap::bench {

struct HeldOut {
  TouchSet all;                              ///< every touch, with its word
  std::vector<TouchSet> references;          ///< per object: its other explorations' touches
  std::vector<std::vector<Index>> held_out;  ///< per object: indices of its exploration-0 touches
  Index words = 0;                           ///< codebook size
};

/// Fits a k-word codebook (seed 1) on the touches of explorations other than
/// 0, labels every touch, and splits each object's touches into its
/// reference (explorations != 0) and its held-out pool (exploration 0).
inline HeldOut hold_out_exploration_zero(const TouchTable& table, Index k) {
  std::vector<Index> train;
  for (Index i = 0; i < table.size(); ++i)
    if (table.exploration[static_cast<std::size_t>(i)] != 0) train.push_back(i);
  const Eigen::MatrixXf f = table.touches.features(Eigen::all, train);
  KMeansQuantizer<float> q;
  q.settings.k = k;
  q.settings.seed = 1;
  q.fit(f);
  HeldOut h;
  h.words = q.size();
  h.all = table.touches;
  h.all.words = assign_words(q, table.touches.features);
  for (Index o = 0; o < static_cast<Index>(table.objects.size()); ++o) {
    std::vector<Index> tr, te;
    for (Index i = 0; i < table.size(); ++i) {
      if (table.object[static_cast<std::size_t>(i)] != o) continue;
      (table.exploration[static_cast<std::size_t>(i)] == 0 ? te : tr).push_back(i);
    }
    h.references.push_back(select_touches(h.all, tr));
    h.held_out.push_back(std::move(te));
  }
  return h;
}

/// At most `n` distinct elements of `pool`, drawn by a partial Fisher-Yates
/// shuffle driven by `rng`.
inline std::vector<Index> random_subset(std::vector<Index> pool, std::size_t n, Rng& rng) {
  for (std::size_t i = 0; i < n && i < pool.size(); ++i)
    std::swap(pool[i], pool[i + static_cast<std::size_t>(rng.below(pool.size() - i))]);
  pool.resize(std::min(n, pool.size()));
  return pool;
}

}  // namespace iclap::bench

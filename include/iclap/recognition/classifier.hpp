// SPDX-License-Identifier: MIT
#pragma once

#include <atomic>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"
#include "iclap/recognition/touch_set.hpp"

namespace iclap {

namespace detail {
/// A new identity for every fit of every classifier, so that a prepared pool
/// is recognised as stale after a refit.
inline std::uint64_t next_fit_id() {
  static std::atomic<std::uint64_t> next{0};
  return ++next;
}

/// What a prepared pool remembers of the pool it was made for, so that
/// another pool of the same size is refused rather than scored with the
/// first one's work: a 64-bit FNV-1a hash of the bits of every touch
/// position, the words and the numbers of features, contact and free
/// points. O(touches); two explorations share it only if their pads stood
/// at the same places to the last bit.
inline std::uint64_t pool_fingerprint(const TouchSet& pool) {
  std::uint64_t h = 14695981039346656037ull;
  auto mix = [&h](std::uint64_t v) {
    for (int b = 0; b < 8; ++b) {
      h ^= (v >> (8 * b)) & 0xffu;
      h *= 1099511628211ull;
    }
  };
  mix(static_cast<std::uint64_t>(pool.size()));
  for (Index k = 0; k < pool.positions.size(); ++k) {
    std::uint64_t bits;
    std::memcpy(&bits, pool.positions.data() + k, sizeof bits);
    mix(bits);
  }
  for (Index k = 0; k < pool.words.size(); ++k) mix(static_cast<std::uint64_t>(pool.words(k)));
  mix(static_cast<std::uint64_t>(pool.features.size()));
  mix(static_cast<std::uint64_t>(pool.contact_points.cols()));
  mix(static_cast<std::uint64_t>(pool.free_points.cols()));
  return h;
}
}  // namespace detail

/// What a classifier computed once for a pool of touches that many tests are
/// drawn from (`Classifier::prepare_pool`). Opaque; only the classifier that
/// made it reads it.
class PreparedPool {
 public:
  virtual ~PreparedPool() = default;
};

/// A recognition pipeline that measures how far a set of test touches is
/// from every known object (smaller: more alike). Runtime-polymorphic so that
/// a recogniser can hold any mix of them, chosen on the command line.
///
/// Contract: `fit` builds the references once per training set (one touch
/// set per object, in object order; kd-trees included) and may be called
/// again to replace them; `distances` is const, thread-safe, and writes one
/// finite, non-negative, unnormalised distance per object.
class Classifier {
 public:
  virtual ~Classifier() = default;
  /// Stable name used by fusion expressions and results files.
  virtual std::string name() const = 0;
  /// `vocabulary` is the number of words of the codebook that produced the
  /// touches' word ids.
  virtual void fit(const std::vector<TouchSet>& objects, Index vocabulary) = 0;
  virtual void distances(const TouchSet& test, Eigen::Ref<Eigen::VectorXd> out) const = 0;
  /// Number of objects of the last fit (0 before).
  virtual Index objects() const = 0;

  /// Work that depends on single touches of `pool` only, done once for all
  /// the tests `pool_distances` draws from it (cross validation draws many
  /// subsets of each held-out exploration). Null when the classifier has
  /// nothing to reuse (the default). Valid until the next `fit`.
  virtual std::shared_ptr<const PreparedPool> prepare_pool(const TouchSet& pool) const {
    (void)pool;
    return nullptr;
  }

  /// The distances of the test made of `pool`'s touches `subset`, in that
  /// order: exactly those of `distances(select_touches(pool, subset), out)`,
  /// sooner when `prepared` is `prepare_pool(pool)` of this classifier since
  /// its last fit (null: nothing prepared). Throws InvalidArgument naming
  /// "subset" for an index outside the pool, and whatever `distances` throws.
  virtual void pool_distances(const TouchSet& pool, const PreparedPool* prepared, const std::vector<Index>& subset,
                              Eigen::Ref<Eigen::VectorXd> out) const {
    (void)prepared;
    distances(select_touches(pool, checked_subset(pool, subset)), out);
  }

 protected:
  /// `subset`, after checking that every index names a touch of `pool`.
  static const std::vector<Index>& checked_subset(const TouchSet& pool, const std::vector<Index>& subset) {
    for (std::size_t k = 0; k < subset.size(); ++k)
      if (subset[k] < 0 || subset[k] >= pool.size())
        throw InvalidArgument("subset", "entry " + std::to_string(k) + " is touch " + std::to_string(subset[k]) +
                                            " of a pool of " + std::to_string(pool.size()));
    return subset;
  }
};

}  // namespace iclap

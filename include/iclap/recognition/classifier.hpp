// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <type_traits>
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

/// A 64-bit hash that changes whenever one mixed value does: each value v
/// is mixed in by h = xorshift(odd * (h ^ v)), a bijection of h for a given
/// v, so two sequences of the same length that differ in one value always
/// hash differently. One multiply per value.
class Fingerprint {
 public:
  void mix(std::uint64_t v) noexcept { h_ = step(h_, v); }
  /// The bits of `n` contiguous scalars of 8 or 4 bytes (two a value), in
  /// four independent lanes (the multiplies overlap) that are then mixed in
  /// one after the other: still a bijection of each lane, so one differing
  /// value still changes the hash.
  template <typename S>
  void mix_bits(const S* data, Index n) noexcept {
    static_assert(std::is_trivially_copyable_v<S> && (sizeof(S) == 8 || sizeof(S) == 4), "8- or 4-byte scalars");
    const auto* bytes = reinterpret_cast<const unsigned char*>(data);
    const std::size_t size = static_cast<std::size_t>(n) * sizeof(S);
    std::uint64_t lane[4] = {h_, ~h_, h_ ^ 0x5555555555555555ull, h_ ^ 0xaaaaaaaaaaaaaaaaull};
    std::size_t at = 0;
    for (; at + 32 <= size; at += 32)
      for (int l = 0; l < 4; ++l) lane[l] = step(lane[l], load(bytes + at + 8 * l, 8));
    for (int l = 0; at < size; at += 8, ++l) lane[l] = step(lane[l], load(bytes + at, std::min<std::size_t>(8, size - at)));
    for (std::uint64_t v : lane) mix(v);
  }
  std::uint64_t value() const noexcept { return h_; }

 private:
  static std::uint64_t step(std::uint64_t h, std::uint64_t v) noexcept {
    h = (h ^ v) * 0x9e3779b97f4a7c15ull;
    return h ^ (h >> 29);
  }
  /// `n` <= 8 bytes at `p` as the low bytes of a value, zeros above.
  static std::uint64_t load(const unsigned char* p, std::size_t n) noexcept {
    std::uint64_t v = 0;
    std::memcpy(&v, p, n);
    return v;
  }
  std::uint64_t h_ = 0x243f6a8885a308d3ull;  // any start: the digits of pi
};

/// The Fingerprint of the parts a prepared pool depends on for touch `i` of
/// `pool` (in range): the bits of its position, descriptor, contact points,
/// normal and free points, and its word, each part preceded by its length.
/// Reads nothing outside `pool` even if its offsets are corrupt (such a
/// range is mixed in as a marker instead of its points).
inline std::uint64_t touch_fingerprint(const TouchSet& pool, Index i) {
  Fingerprint f;
  auto part = [&f](const auto* data, Index n) {
    f.mix(static_cast<std::uint64_t>(n));
    f.mix_bits(data, n);
  };
  auto points = [&](const Eigen::Matrix3Xd& p, const std::vector<Index>& offsets) {
    if (offsets.empty()) return;
    const auto k = static_cast<std::size_t>(i);
    if (k + 1 >= offsets.size() || offsets[k] < 0 || offsets[k] > offsets[k + 1] || offsets[k + 1] > p.cols())
      return f.mix(~std::uint64_t{0});
    part(p.data() + 3 * offsets[k], 3 * (offsets[k + 1] - offsets[k]));
  };
  part(pool.positions.col(i).data(), 3);
  if (pool.features.cols() > i) part(pool.features.col(i).data(), pool.features.rows());
  if (pool.words.size() > i) part(pool.words.data() + i, 1);
  points(pool.contact_points, pool.contact_offsets);
  if (pool.normals.cols() > i) part(pool.normals.col(i).data(), 3);
  points(pool.free_points, pool.free_offsets);
  return f.value();
}

/// The Fingerprint of the sizes of `pool`'s parts besides its number of
/// touches (which PreparedPool::made_for compares on its own): its
/// descriptors' shape, and the numbers of words, contact points and
/// offsets, normals, free points and offsets.
inline std::uint64_t pool_shape(const TouchSet& pool) {
  Fingerprint f;
  for (std::size_t v : {std::size_t(pool.features.rows()), std::size_t(pool.features.cols()),
                        std::size_t(pool.words.size()), std::size_t(pool.contact_points.cols()),
                        pool.contact_offsets.size(), std::size_t(pool.normals.cols()),
                        std::size_t(pool.free_points.cols()), pool.free_offsets.size()})
    f.mix(static_cast<std::uint64_t>(v));
  return f.value();
}
}  // namespace detail

/// What a classifier computed once for a pool of touches that many tests are
/// drawn from (`Classifier::prepare_pool`). Opaque; only the classifier that
/// made it reads it. It remembers the fit it was made by and a fingerprint
/// of every touch of its pool (`made_for`), so that a classifier refuses a
/// stale or foreign preparation instead of scoring a test with another
/// pool's work.
class PreparedPool {
 public:
  virtual ~PreparedPool() = default;

  /// Whether this was made by the fit `fit_id` (a detail::next_fit_id() of
  /// the classifier's last fit) for a pool with `pool`'s shape (its number
  /// of touches and the sizes of its parts) whose touches
  /// `subset` were those of `pool` to the last bit (false for an index
  /// outside the pool): all a test
  /// drawn from them reads. O(size of those touches), about what copying
  /// them costs (`bench_recognition --benchmark_filter=PoolCheck`), so a
  /// check per draw, not one over the whole pool. Always false for a
  /// preparation constructed without a fit and pool.
  bool made_for(std::uint64_t fit_id, const TouchSet& pool, const std::vector<Index>& subset) const {
    if (fit_ == 0 || fit_ != fit_id || static_cast<std::size_t>(pool.size()) != touches_.size() ||
        shape_ != detail::pool_shape(pool))
      return false;
    for (Index i : subset)
      if (i < 0 || i >= pool.size() || detail::touch_fingerprint(pool, i) != touches_[static_cast<std::size_t>(i)])
        return false;
    return true;
  }

 protected:
  PreparedPool() = default;
  /// Made by the fit `fit_id` for `pool` (validated): fingerprints every
  /// touch, O(pool).
  PreparedPool(std::uint64_t fit_id, const TouchSet& pool) : fit_(fit_id), shape_(detail::pool_shape(pool)) {
    touches_.reserve(static_cast<std::size_t>(pool.size()));
    for (Index i = 0; i < pool.size(); ++i) touches_.push_back(detail::touch_fingerprint(pool, i));
  }
  PreparedPool(const PreparedPool&) = default;
  PreparedPool& operator=(const PreparedPool&) = default;

 private:
  std::uint64_t fit_ = 0;                // the fit it was made by; 0: none
  std::uint64_t shape_ = 0;              // detail::pool_shape of the pool
  std::vector<std::uint64_t> touches_;  // detail::touch_fingerprint of every touch
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

  /// The descriptor length (rows of TouchSet::features) that `distances`
  /// needs of a test: that of the last fit's references for a classifier
  /// that reads descriptors (iclapn), 0 for one that reads none (the
  /// default) and before a fit. A live session checks every touch's
  /// descriptor against it (LiveSession::add_touch), so that a touch
  /// without one, or with one of another length, is refused naming
  /// "feature" before the classifier sees it: override it in a classifier
  /// of your own that reads descriptors.
  virtual Index descriptor_length() const { return 0; }

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
  /// "subset" for an index outside the pool, DimensionMismatch /
  /// InvalidArgument naming "pool.<part>" for parts of `pool` that do not
  /// fit together (TouchSet::validate_layout), and whatever `distances`
  /// throws.
  /// A classifier that reads `prepared` refuses one it did not make for
  /// this pool since its last fit (InvalidArgument naming "prepared"; see
  /// PreparedPool::made_for and `checked_preparation`).
  virtual void pool_distances(const TouchSet& pool, const PreparedPool* prepared, const std::vector<Index>& subset,
                              Eigen::Ref<Eigen::VectorXd> out) const {
    (void)prepared;
    distances(select_touches(pool, checked_subset(pool, subset)), out);
  }

 protected:
  /// `prepared` as the preparation type `P` of this classifier, null when it
  /// is null; throws InvalidArgument naming "subset" for an index outside
  /// `pool` (whether or not there is a preparation) and "prepared" when it
  /// is not a `P` made for `pool`'s touches `subset` by the fit `fit_id`
  /// (another classifier's, another pool's, or one from before the last
  /// fit).
  template <typename P>
  static const P* checked_preparation(const PreparedPool* prepared, std::uint64_t fit_id, const TouchSet& pool,
                                      const std::vector<Index>& subset) {
    checked_subset(pool, subset);
    if (!prepared) return nullptr;
    const auto* p = dynamic_cast<const P*>(prepared);
    if (!p || !p->made_for(fit_id, pool, subset))
      throw InvalidArgument("prepared", "was not made by prepare_pool of this classifier for this pool since its last fit");
    return p;
  }

  /// `subset`, after checking that every index names a touch of `pool` and
  /// that selecting touches from `pool` reads nothing outside it
  /// (TouchSet::validate_layout, naming "pool").
  static const std::vector<Index>& checked_subset(const TouchSet& pool, const std::vector<Index>& subset) {
    pool.validate_layout("pool");
    for (std::size_t k = 0; k < subset.size(); ++k)
      if (subset[k] < 0 || subset[k] >= pool.size())
        throw InvalidArgument("subset", "entry " + std::to_string(k) + " is touch " + std::to_string(subset[k]) +
                                            " of a pool of " + std::to_string(pool.size()));
    return subset;
  }
};

}  // namespace iclap

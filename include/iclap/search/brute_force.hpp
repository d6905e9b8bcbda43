// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "iclap/core/check.hpp"
#include "iclap/core/point_cloud.hpp"
#include "iclap/core/types.hpp"
#include "iclap/search/neighbor.hpp"
#include "iclap/search/shared_cloud.hpp"

#if defined(__GNUC__)
// GCC and Clang: the points are scanned with their vector extensions, 8
// floats or 4 doubles at a time.
#define ICLAP_VECTOR_BRUTE_FORCE 1
#if defined(__x86_64__) || defined(__i386__)
// On x86 the scan is compiled twice, for the baseline ISA and for AVX2, and
// the AVX2 code runs where the CPU has it (checked once, at run time).
#define ICLAP_AVX2_DISPATCH 1
#endif
#endif

namespace iclap {

namespace detail {

#if defined(ICLAP_VECTOR_BRUTE_FORCE)
// GCC at -O2 keeps short constant-count loops rolled, so they are asked to
// unroll. Clang unrolls those by itself, and its pragma warns (an error
// under -Werror) on loops whose count is only known at run time.
#if defined(__clang__)
#define ICLAP_UNROLL
#else
#define ICLAP_UNROLL _Pragma("GCC unroll 8")
#endif

/// A vector of `Bytes` bytes of coordinates, one point per lane, and the
/// integer vector that comparisons return and lane indices live in.
template <typename Scalar, int Bytes>
struct Lanes;
template <>
struct Lanes<float, 16> {
  typedef std::int32_t Element;
  typedef float Vector __attribute__((vector_size(16)));
  typedef Element Mask __attribute__((vector_size(16)));
};
template <>
struct Lanes<float, 32> {
  typedef std::int32_t Element;
  typedef float Vector __attribute__((vector_size(32)));
  typedef Element Mask __attribute__((vector_size(32)));
};
template <>
struct Lanes<double, 16> {
  typedef std::int64_t Element;
  typedef double Vector __attribute__((vector_size(16)));
  typedef Element Mask __attribute__((vector_size(16)));
};
template <>
struct Lanes<double, 32> {
  typedef std::int64_t Element;
  typedef double Vector __attribute__((vector_size(32)));
  typedef Element Mask __attribute__((vector_size(32)));
};

/// Points per block of the brute force's copy of a cloud: 32 bytes of each
/// coordinate (8 floats or 4 doubles).
template <typename Scalar>
inline constexpr int block_width = 32 / static_cast<int>(sizeof(Scalar));

// With a run-time dimension, the unrolled loops over the query's
// coordinates hold copies for up to 8 of them; inlined into a caller whose
// query is a fixed-size vector of fewer (a Vector4f for a 4-D cloud of
// Eigen::Dynamic), GCC warns that the copies that never run read past it
// (-Warray-bounds, a false positive: the loops stop at the cloud's
// dimension, the length nearest() requires of its query). Kept quiet here,
// for this function only; the sanitizers still see every read.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Warray-bounds"
#endif

/// The nearest of the points stored in `blocks` (`count` blocks of
/// block_width points; block b holds coordinate i of its points at
/// blocks[(b * dim + i) * block_width + lane], unused lanes +infinity),
/// scanned `Bytes` bytes at a time: 16 (SSE2 and other 128-bit units) or
/// 32 (AVX2).
///
/// Each lane sums its squared coordinate differences in exactly the order
/// of `squared_distance` (one running sum below 8 coordinates, eight
/// interleaved partial sums combined pairwise from 8 on), so every distance
/// is bit for bit the kd-tree's. A lane keeps a point only when it is
/// strictly closer than the lane's best, so within a lane the smaller index
/// wins ties; the lanes are then combined with `closer`, which gives the
/// shared tie rule overall. A NaN distance never wins. Inlined into the
/// baseline and the AVX2 entry points below, which compile it for their ISA.
template <int Bytes, int Dim, typename Scalar>
__attribute__((always_inline)) inline void nearest_in_blocks(const Scalar* blocks, Index count, Index dim,
                                                             const Scalar* query, Scalar& best_distance,
                                                             Index& best_index) noexcept {
  using V = typename Lanes<Scalar, Bytes>::Vector;
  using M = typename Lanes<Scalar, Bytes>::Mask;
  using Element = typename Lanes<Scalar, Bytes>::Element;
  constexpr int width = Bytes / static_cast<int>(sizeof(Scalar));
  constexpr int stride = block_width<Scalar>;
  constexpr std::size_t parts = static_cast<std::size_t>(stride / width);
  const Index n = Dim > 0 ? Index(Dim) : dim;
  V best[parts];
  M best_lane_index[parts], lane_index[parts];
  for (std::size_t p = 0; p < parts; ++p) {
    V infinite = {};
    M none = {}, lanes = {};
    for (int l = 0; l < width; ++l) {
      infinite[l] = std::numeric_limits<Scalar>::infinity();
      none[l] = -1;
      lanes[l] = static_cast<Element>(static_cast<int>(p) * width + l);
    }
    best[p] = infinite;
    best_lane_index[p] = none;
    lane_index[p] = lanes;
  }
  const Scalar* block = blocks;
  for (Index b = 0; b < count; ++b, block += n * stride) {
    ICLAP_UNROLL
    for (std::size_t p = 0; p < parts; ++p) {
      const Scalar* part = block + static_cast<int>(p) * width;
      V sum = {};
      if (n < 8) {
        ICLAP_UNROLL
        for (Index i = 0; i < n; ++i) {
          V c;
          std::memcpy(&c, part + i * stride, sizeof c);  // an unaligned load
          const V d = query[i] - c;
          sum += d * d;
        }
      } else {
        V s[8] = {};
        ICLAP_UNROLL
        for (Index i = 0; i < n; ++i) {
          V c;
          std::memcpy(&c, part + i * stride, sizeof c);
          const V d = query[i] - c;
          s[i & 7] += d * d;
        }
        sum = ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
      }
      const M closer_here = sum < best[p];
      best[p] = closer_here ? sum : best[p];
      best_lane_index[p] = closer_here ? lane_index[p] : best_lane_index[p];
      lane_index[p] += static_cast<Element>(stride);
    }
  }
  for (std::size_t p = 0; p < parts; ++p)
    for (int l = 0; l < width; ++l) {
      const Index i = static_cast<Index>(best_lane_index[p][l]);
      if (i >= 0 && closer(best[p][l], i, best_distance, best_index)) {
        best_distance = best[p][l];
        best_index = i;
      }
    }
}

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#undef ICLAP_UNROLL

template <int Dim, typename Scalar>
inline void nearest_in_blocks_baseline(const Scalar* blocks, Index count, Index dim, const Scalar* query,
                                       Scalar& best_distance, Index& best_index) noexcept {
  nearest_in_blocks<16, Dim>(blocks, count, dim, query, best_distance, best_index);
}

#if defined(ICLAP_AVX2_DISPATCH)
template <int Dim, typename Scalar>
__attribute__((target("avx2"))) inline void nearest_in_blocks_avx2(const Scalar* blocks, Index count, Index dim,
                                                                   const Scalar* query, Scalar& best_distance,
                                                                   Index& best_index) noexcept {
  nearest_in_blocks<32, Dim>(blocks, count, dim, query, best_distance, best_index);
}

/// True when this CPU (and its OS) runs AVX2 code.
inline bool cpu_has_avx2() noexcept {
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
}
#endif
#endif  // ICLAP_VECTOR_BRUTE_FORCE

/// BruteForceSearch's shared block: the points and, with the vector scan,
/// their copy a vector width at a time (see nearest_in_blocks).
template <typename Scalar, int Dim>
struct ScanBlock {
  Cloud<Scalar, Dim> points;
  bool use_avx2 = true;
#if defined(ICLAP_VECTOR_BRUTE_FORCE)
  std::vector<Scalar> lanes;
  Index blocks = 0;
#endif
  ScanBlock(Cloud<Scalar, Dim> p, bool avx2) : points(std::move(p)), use_avx2(avx2) {
#if defined(ICLAP_VECTOR_BRUTE_FORCE)
    constexpr int width = block_width<Scalar>;
    const Index d = points.rows();
    blocks = (points.cols() + width - 1) / width;
    lanes.assign(static_cast<std::size_t>(blocks * d * width), std::numeric_limits<Scalar>::infinity());
    for (Index j = 0; j < points.cols(); ++j)
      for (Index i = 0; i < d; ++i)
        lanes[static_cast<std::size_t>(((j / width) * d + i) * width + j % width)] = points(i, j);
#endif
  }
};

}  // namespace detail

/// Exhaustive nearest-neighbour search: O(n) per query, no build cost.
///
/// The test oracle for `KdTreeSearch` (same distances, same tie rule, so the
/// same answers), and the faster choice for small clouds or high
/// dimensions: with GCC or Clang it scans a copy of the points stored a
/// vector width at a time (8 floats or 4 doubles per 32-byte vector), with
/// AVX2 where an x86 CPU has it. On the few-hundred-point references of a
/// recognition that is about twice as fast as the kd-tree
/// (`bench_recognition`, `AdaptiveSearch`).
///
/// The points and their vector copy live in one immutable, shared block, as
/// `KdTreeSearch`'s tree does: copying a `BruteForceSearch` is cheap and the
/// copies share the points. Queries are const and thread-safe.
template <typename Scalar, int Dim = Eigen::Dynamic>
class BruteForceSearch
    : public detail::SharedCloudSearch<BruteForceSearch<Scalar, Dim>, Scalar, Dim, detail::ScanBlock<Scalar, Dim>> {
  ICLAP_CHECK_SCALAR_AND_DIM(Scalar, Dim);
  using Base = detail::SharedCloudSearch<BruteForceSearch, Scalar, Dim, detail::ScanBlock<Scalar, Dim>>;
  using Base::block_;

 public:
  using typename Base::CloudType;
  using Base::nearest;  // the Eigen-vector overload

  struct Settings {
    /// x86: run the AVX2 code where the CPU has it (checked at run time).
    /// false: the baseline code only. The answers are the same either way.
    bool use_avx2 = true;
  };

  BruteForceSearch() = default;

  /// Takes the points (one per column). Throws EmptyInput for an empty cloud
  /// and NonFiniteValue for NaN or infinite coordinates, naming `points`,
  /// and InvalidArgument for more than 2^31 - 9 float points (the scan
  /// numbers them in 32-bit lanes).
  explicit BruteForceSearch(CloudType points, const Settings& settings = {}) {
    check_not_empty(points, "points");
    check_finite(points, "points");
#if defined(ICLAP_VECTOR_BRUTE_FORCE)
    constexpr int width = detail::block_width<Scalar>;
    if (points.cols() > Index(std::numeric_limits<typename detail::Lanes<Scalar, 32>::Element>::max() - width))
      throw InvalidArgument("points", "too many points for the brute force's lane indices");
#endif
    block_ = std::make_shared<const detail::ScanBlock<Scalar, Dim>>(std::move(points), settings.use_avx2);
  }

  /// The same for another Eigen type (a MatrixXd, a block, a map); with a
  /// fixed Dim, DimensionMismatch naming `points` for another row count.
  template <typename Derived, typename = std::enable_if_t<!std::is_same_v<Derived, CloudType>>>
  explicit BruteForceSearch(const Eigen::MatrixBase<Derived>& points, const Settings& settings = {})
      : BruteForceSearch(detail::checked_rows<CloudType>(points, "points"), settings) {}

  /// A cloud of your own type (a PointCloudTraits specialisation, see
  /// iclap/core/point_cloud.hpp), read once as `to_cloud<Scalar, Dim>` reads
  /// it: the search of a matrix of the same values. Throws what to_cloud
  /// throws, naming `points`, then as the matrix constructor.
  template <typename C, typename = std::enable_if_t<is_point_cloud_v<C>>>
  explicit BruteForceSearch(const C& points, const Settings& settings = {})
      : BruteForceSearch(to_cloud<Scalar, Dim>(points, "points"), settings) {}

  /// The closest point to `query` (length `dim()`), ties to the smaller index.
  /// A default-constructed search has no points: index -1, infinite distance.
  Neighbor<Scalar> nearest(const Scalar* query) const noexcept {
    Neighbor<Scalar> best;
    if (!block_) return best;
    const detail::ScanBlock<Scalar, Dim>& m = *block_;
#if defined(ICLAP_VECTOR_BRUTE_FORCE)
#if defined(ICLAP_AVX2_DISPATCH)
    if (m.use_avx2 && detail::cpu_has_avx2()) {
      detail::nearest_in_blocks_avx2<Dim>(m.lanes.data(), m.blocks, m.points.rows(), query, best.squared_distance,
                                          best.index);
      return best;
    }
#endif
    detail::nearest_in_blocks_baseline<Dim>(m.lanes.data(), m.blocks, m.points.rows(), query, best.squared_distance,
                                            best.index);
#else
    const Index d = m.points.rows();
    for (Index j = 0; j < m.points.cols(); ++j) {
      const Scalar dist = detail::squared_distance<Dim>(query, m.points.col(j).data(), d);
      if (detail::closer(dist, j, best.squared_distance, best.index)) {
        best.index = j;
        best.squared_distance = dist;
      }
    }
#endif
    return best;
  }
};

}  // namespace iclap

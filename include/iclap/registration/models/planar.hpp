// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <limits>

#include "iclap/core/error.hpp"
#include "iclap/registration/models/procrustes.hpp"

namespace iclap {

/// Transform model: rotation about z and translation in the (x, y) plane,
/// SE(2) acting on the first two coordinates. An object lying on a table
/// and re-placed moves like this; z and any further coordinates are never
/// moved. Needs Dim >= 2.
struct Planar {
  static constexpr const char* name = "planar";
  template <int Dim>
  static constexpr int block = 2;
  static Index block_size(Index /*dim*/) noexcept { return 2; }
  static constexpr bool uses_covariance = true;
  static void check_dimension(Index dim) {
    if (dim < 2)
      throw InvalidArgument("test", "the planar transform model needs at least 2 coordinates (x, y), got " +
                                        std::to_string(dim));
  }
  /// Closed form: with a = H00 + H11 and b = H01 - H10, tr(R H) =
  /// cos(t) a + sin(t) b is maximal at (cos t, sin t) = (a, b) / |(a, b)|
  /// (the angle atan2(b, a), without evaluating it); always a proper
  /// rotation, the identity when a = b = 0.
  template <typename Acc, int B>
  static BlockEstimate<Acc, B> estimate(const Point<Acc, B>& cp, const Point<Acc, B>& cq,
                                        const SquareMatrix<Acc, B>& H, double rank_tol) {
    static_assert(B == 2, "Planar acts on a 2-coordinate block");
    BlockEstimate<Acc, B> e;
    const Acc a = H(0, 0) + H(1, 1), b = H(0, 1) - H(1, 0);
    // Singular values of the 2x2 H in closed form (H = rotation part +
    // reflection part): s = q + r and |q - r|, q the norm of the rotation
    // part, r of the reflection part. No cancellation: both are norms.
    const Acc norm = length(a, b);
    const Acc q = norm / 2;
    const Acc r = length(H(0, 0) - H(1, 1), H(1, 0) + H(0, 1)) / 2;
    Acc c = 1, s = 0;
    if (norm > 0 && norm <= std::numeric_limits<Acc>::max()) {
      c = a / norm;
      s = b / norm;
    } else if (!(norm == 0)) {  // overflowed or NaN: what the angle gives
      const Acc angle = std::atan2(b, a);
      c = std::cos(angle);
      s = std::sin(angle);
    }
    e.R << c, -s, s, c;
    e.t = cq - e.R * cp;
    // Degenerate when H is rank deficient, and also when its rotation part
    // vanishes against its reflection part (q <= tol (q + r): pairs that
    // mirror each other), where tr(R H) hardly changes with the angle and
    // the identity above is no answer.
    e.degenerate = detail::rank_deficient<Acc, 2>(Point<Acc, 2>(q + r, std::abs(q - r)), rank_tol) ||
                   !(q > (q + r) * static_cast<Acc>(rank_tol));
    return e;
  }

 private:
  /// |(x, y)|: sqrt(x^2 + y^2) where that cannot overflow or lose precision
  /// to underflow (within an ulp of std::hypot, several times faster),
  /// std::hypot elsewhere (and for NaN).
  template <typename Acc>
  static Acc length(Acc x, Acc y) {
    const Acc s = x * x + y * y;
    if (s >= std::numeric_limits<Acc>::min() && s <= std::numeric_limits<Acc>::max()) return std::sqrt(s);
    return std::hypot(x, y);
  }
};

}  // namespace iclap

// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

namespace iclap {

/// Deterministic random numbers, xoshiro256** (Blackman and Vigna) seeded
/// through splitmix64, with its own uniform, integer and normal draws: the
/// same on every platform (normal() to the rounding of std::log, std::cos).
///
/// `std::uniform_real_distribution` and `std::normal_distribution` are
/// implementation-defined, so a seed would not give the same codebook or the
/// same simulated dataset everywhere; everything in iclap that draws random
/// numbers takes an `Rng` (or a seed) and uses only these members.
///
/// Not thread-safe; give each thread its own stream with `Rng::derive`.
class Rng {
 public:
  using result_type = std::uint64_t;

  /// A generator whose whole sequence is fixed by `seed`.
  explicit Rng(std::uint64_t seed = 0) noexcept {
    std::uint64_t s = seed;
    for (auto& word : state_) word = splitmix64(s);
  }

  /// An independent stream identified by (seed, stream, substream), e.g.
  /// (experiment seed, fold, test index). Streams for different ids do not
  /// overlap in practice, and do not depend on the order they are made in.
  static Rng derive(std::uint64_t seed, std::uint64_t stream, std::uint64_t substream = 0) noexcept {
    std::uint64_t s = seed;
    std::uint64_t mixed = splitmix64(s);
    mixed ^= stream * 0xD1B54A32D192ED03ull;
    s = mixed;
    mixed = splitmix64(s);
    mixed ^= substream * 0x8CB92BA72F3D8DD7ull;
    return Rng(mixed);
  }

  static constexpr result_type min() noexcept { return 0; }
  static constexpr result_type max() noexcept { return std::numeric_limits<result_type>::max(); }

  /// The next 64 random bits.
  result_type operator()() noexcept {
    const std::uint64_t result = rotl(state_[1] * 5, 7) * 9;
    const std::uint64_t t = state_[1] << 17;
    state_[2] ^= state_[0];
    state_[3] ^= state_[1];
    state_[1] ^= state_[2];
    state_[0] ^= state_[3];
    state_[2] ^= t;
    state_[3] = rotl(state_[3], 45);
    return result;
  }

  /// Uniform in [0, 1) with 53 random bits.
  double uniform() noexcept { return static_cast<double>((*this)() >> 11) * 0x1.0p-53; }

  /// Uniform in [a, b) for a < b (a itself when a == b). Where the rounding
  /// of a + (b - a) u reaches b (an interval a few ulps wide) the largest
  /// double below b is returned instead; where b - a overflows (a and b near
  /// the ends of the double range) the draw is a (1 - u) + b u, which stays
  /// finite.
  double uniform(double a, double b) noexcept {
    const double u = uniform();
    const double width = b - a;
    const double r = std::isfinite(width) ? a + width * u : a * (1 - u) + b * u;
    return r < b || !(a < b) ? r : std::nextafter(b, a);
  }

  /// Uniform integer in [0, n), without modulo bias; n must be > 0.
  std::uint64_t below(std::uint64_t n) noexcept {
    // Rejection on the top of the range (Lemire's threshold).
    const std::uint64_t threshold = (0 - n) % n;
    for (;;) {
      const std::uint64_t r = (*this)();
      if (r >= threshold) return r % n;
    }
  }

  /// Standard normal N(0, 1) by the Box-Muller transform (one draw per call,
  /// no cached spare, so the sequence does not depend on call parity). The C
  /// library need not round std::log and std::cos correctly: draws may differ
  /// in their last bits between C libraries, never between runs on one.
  double normal() noexcept {
    const double u1 = 1.0 - uniform();  // (0, 1]: log is finite
    const double u2 = uniform();
    constexpr double two_pi = 6.283185307179586476925286766559;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(two_pi * u2);
  }

  /// Normal with mean `mean` and standard deviation `sigma`.
  double normal(double mean, double sigma) noexcept { return mean + sigma * normal(); }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) noexcept { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t splitmix64(std::uint64_t& s) noexcept {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }

  std::uint64_t state_[4];
};

}  // namespace iclap

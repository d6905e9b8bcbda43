// SPDX-License-Identifier: MIT
#pragma once

// Synthetic tactile frames for the tactile tests and benchmarks: plausible
// WTS-like contact patterns (point, ridge, edge, corner, flat) at random
// positions, orientations, widths and forces, with integer 12-bit values and
// a little noise. Deterministic through iclap::Rng.

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/random.hpp"
#include "iclap/core/types.hpp"

namespace iclap::test {

enum class ContactShape { Blob, Ridge, Edge, Corner, Flat };
constexpr ContactShape kAllShapes[] = {ContactShape::Blob, ContactShape::Ridge, ContactShape::Edge,
                                       ContactShape::Corner, ContactShape::Flat};

inline double logistic(double z) { return 1.0 / (1.0 + std::exp(-z)); }

/// One random frame of the given shape, rows x cols raw pressures.
inline Eigen::MatrixXd synthetic_contact(ContactShape shape, Rng& rng, Index rows = 14, Index cols = 6) {
  const double cx = rng.uniform(0.0, static_cast<double>(cols - 1));
  const double cy = rng.uniform(0.0, static_cast<double>(rows - 1));
  const double angle = rng.uniform(0.0, 3.141592653589793);
  const double sigma = rng.uniform(0.6, 1.6);
  const double amplitude = rng.uniform(800.0, 4000.0);
  const double ux = std::cos(angle), uy = std::sin(angle);
  Eigen::MatrixXd p(rows, cols);
  for (Index r = 0; r < rows; ++r) {
    for (Index c = 0; c < cols; ++c) {
      const double dx = static_cast<double>(c) - cx;
      const double dy = static_cast<double>(r) - cy;
      const double along = dx * ux + dy * uy;    // along the line
      const double across = -dx * uy + dy * ux;  // signed distance to it
      double v = 0.0;
      switch (shape) {
        case ContactShape::Blob: v = std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma)); break;
        case ContactShape::Ridge: v = std::exp(-across * across / (2 * sigma * sigma)); break;
        case ContactShape::Edge: v = logistic(across / (0.5 * sigma)); break;
        case ContactShape::Corner: v = logistic(across / (0.5 * sigma)) * logistic(along / (0.5 * sigma)); break;
        case ContactShape::Flat: v = 0.85 + 0.1 * rng.uniform(); break;
      }
      const double noisy = amplitude * v + rng.uniform(0.0, 20.0);
      p(r, c) = std::clamp(std::round(noisy), 0.0, 4095.0);
    }
  }
  return p;
}

/// `n` frames with shapes drawn from `shapes` with the given weights.
inline std::vector<Eigen::MatrixXd> synthetic_contacts(Index n, Rng& rng, const std::vector<ContactShape>& shapes,
                                                       const std::vector<double>& weights, Index rows = 14,
                                                       Index cols = 6) {
  double total = 0.0;
  for (const double w : weights) total += w;
  std::vector<Eigen::MatrixXd> frames;
  frames.reserve(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) {
    double pick = rng.uniform(0.0, total);
    std::size_t s = 0;
    while (s + 1 < shapes.size() && pick >= weights[s]) pick -= weights[s++];
    frames.push_back(synthetic_contact(shapes[s], rng, rows, cols));
  }
  return frames;
}

}  // namespace iclap::test

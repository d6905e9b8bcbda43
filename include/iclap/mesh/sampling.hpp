// SPDX-License-Identifier: MIT
#pragma once

// Points covering the surface of a triangle mesh: a known shape (a CAD
// model, a scan) turned into the point evidence that point-based
// recognition uses (OccupancyClassifier::fit_evidence).

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"
#include "iclap/mesh/triangle_mesh.hpp"

namespace iclap {

/// Largest number of points sample_surface returns (5e7 points take
/// 1.2 GB).
inline constexpr double kMaxSurfaceSamples = 5e7;

namespace detail {

/// How sample_surface lays its rows on one triangle: `a`-`b` its longest
/// edge, `c` the opposite corner, `rows` + 1 rows parallel to a-b from a-b
/// (row 0) to c (row `rows`).
struct SampledTriangle {
  Eigen::Vector3d a, b, c;
  double length = 0;  // |b - a|
  double rows = 0;    // integral; a double so that a huge count cannot overflow
};

/// The rows of triangle `t` at `spacing`.
inline SampledTriangle sampled_triangle(const TriangleMesh& mesh, Index t, double spacing) {
  SampledTriangle s;
  int longest = 0;
  double best = -1;
  for (int k = 0; k < 3; ++k) {
    const double l = (mesh.corner(t, (k + 1) % 3) - mesh.corner(t, k)).squaredNorm();
    if (l > best) {
      best = l;
      longest = k;
    }
  }
  s.a = mesh.corner(t, longest);
  s.b = mesh.corner(t, (longest + 1) % 3);
  s.c = mesh.corner(t, (longest + 2) % 3);
  s.length = std::sqrt(best);
  if (s.length > 0) {
    // norm() squares the cross product's entries, which underflow for a
    // triangle below about 1e-77 across (it then got no rows beyond its
    // longest edge); stableNorm() only then, so others keep their bits.
    const Eigen::Vector3d cross = (s.b - s.a).cross(s.c - s.a);
    const double squared = cross.squaredNorm();
    const double twice_area =
        squared >= std::numeric_limits<double>::min() ? std::sqrt(squared) : cross.stableNorm();
    const double height = twice_area / s.length;
    // Rows at most sqrt(3)/2 spacing apart, points at most `spacing` apart
    // along each row: the angles at the longest edge are at most 90
    // degrees, so a point between two rows projects onto the longer one,
    // within sqrt(3/4 + 1/4) spacing of one of its points.
    s.rows = std::ceil(height / (spacing * 0.86602540378443864676));
  }
  return s;
}

/// Intervals of row `k` of `s`: its points are intervals + 1.
inline double row_intervals(const SampledTriangle& s, double k, double spacing) {
  const double along = s.rows > 0 ? s.length * (1 - k / s.rows) : s.length;
  return std::ceil(along / spacing);
}

}  // namespace detail

/// Points on the surface of `mesh`, laid so that every point of every
/// triangle lies within `spacing` (in the mesh's length unit) of one of
/// them: on each triangle, rows parallel to its longest edge at most
/// sqrt(3)/2 `spacing` apart, from that edge to the opposite corner, each
/// row's points equally spaced at most `spacing` apart, its two ends
/// included (so are the triangle's three corners). About 1.15 area /
/// spacing^2 points, plus about one per `spacing` of each triangle's longest
/// edge and one per row: a sliver narrower than `spacing` costs one row
/// along its length, not a lattice over its length in both directions.
///
/// Deterministic (no randomness): triangle order, then rows, then along
/// each row. Every point is a convex combination of its triangle's corners,
/// so it lies on the surface up to rounding. Points where triangles meet
/// (corners, edges) appear once per triangle; degenerate triangles are
/// sampled along their longest edge (a point for a triangle whose corners
/// coincide).
///
/// Throws what validate_mesh and check_mesh_range throw (naming "mesh"),
/// InvalidArgument naming "spacing" unless it is finite and > 0, and
/// InvalidArgument naming "spacing" with the number of points it would take
/// when that is more than kMaxSurfaceSamples (a spacing given in the wrong
/// unit, or too fine for the mesh's size). O(triangles + points).
inline Eigen::Matrix3Xd sample_surface(const TriangleMesh& mesh, double spacing) {
  validate_mesh(mesh, "mesh");
  check_mesh_range(mesh, "mesh");
  check_positive(spacing, "spacing");
  const auto too_many = [&](double count, const char* how) {
    throw InvalidArgument("spacing", format_value(spacing) + " would take " + how + format_value(count) +
                                         " points on this mesh (surface area " + format_value(surface_area(mesh)) +
                                         "), more than the " + format_value(kMaxSurfaceSamples) +
                                         " allowed; use a larger spacing (same unit as the mesh)");
  };
  // A lower bound first (row k has at least length (1 - k / rows) / spacing
  // + 1 points, so the rows are fewer than it), so that a far too fine
  // spacing is refused without walking its rows.
  double at_least = 0;
  for (Index t = 0; t < mesh.triangle_count(); ++t) {
    const detail::SampledTriangle s = detail::sampled_triangle(mesh, t, spacing);
    at_least += (s.rows + 1) * (s.length / (2 * spacing) + 1);
  }
  if (!(at_least <= 2 * kMaxSurfaceSamples)) too_many(at_least, "at least ");
  double count = 0;
  for (Index t = 0; t < mesh.triangle_count(); ++t) {
    const detail::SampledTriangle s = detail::sampled_triangle(mesh, t, spacing);
    for (double k = 0; k <= s.rows; ++k) count += detail::row_intervals(s, k, spacing) + 1;
  }
  if (!(count <= kMaxSurfaceSamples)) too_many(count, "");

  Eigen::Matrix3Xd out(3, static_cast<Index>(count));
  Index n = 0;
  for (Index t = 0; t < mesh.triangle_count(); ++t) {
    const detail::SampledTriangle s = detail::sampled_triangle(mesh, t, spacing);
    for (double k = 0; k <= s.rows; ++k) {
      const double intervals = detail::row_intervals(s, k, spacing);
      if (s.rows > 0 && k == s.rows) {  // the apex, exactly
        out.col(n++) = s.c;
        continue;
      }
      const double f = s.rows > 0 ? k / s.rows : 0;
      const Eigen::Vector3d p0 = k == 0 ? s.a : Eigen::Vector3d(s.a + f * (s.c - s.a));
      const Eigen::Vector3d p1 = k == 0 ? s.b : Eigen::Vector3d(s.b + f * (s.c - s.b));
      out.col(n++) = p0;
      for (double i = 1; i < intervals; ++i) out.col(n++) = p0 + (i / intervals) * (p1 - p0);
      if (intervals > 0) out.col(n++) = p1;
    }
  }
  // Every row wrote intervals + 1 points (the apex row: 0 + 1).
  if (n != out.cols()) throw Error("sample_surface: internal count mismatch");
  return out;
}

}  // namespace iclap

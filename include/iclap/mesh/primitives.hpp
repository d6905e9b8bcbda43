// SPDX-License-Identifier: MIT
#pragma once

// Closed triangle meshes of simple solids, to build objects from: boxes,
// solids of revolution (cylinders, cones, spheres, capsules) and extruded
// outlines. All have outward normals; combine them with append_mesh (the
// object is the union of the overlapping shells). Arguments that would give
// no solid, an inside-out one or a non-finite vertex are refused with an
// InvalidArgument naming the argument (lengths and radii finite and > 0).

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/mesh/triangle_mesh.hpp"

namespace iclap {

namespace detail {
inline constexpr double kPi = 3.14159265358979323846;

inline TriangleMesh mesh_from(const std::vector<Eigen::Vector3d>& v, const std::vector<Eigen::Vector3i>& t) {
  TriangleMesh m;
  m.vertices.resize(3, static_cast<Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) m.vertices.col(static_cast<Index>(i)) = v[i];
  m.triangles.resize(3, static_cast<Index>(t.size()));
  for (std::size_t i = 0; i < t.size(); ++i) m.triangles.col(static_cast<Index>(i)) = t[i];
  return m;
}
}  // namespace detail

/// Appends the shells of `b` to `a` (indices shifted).
inline void append_mesh(TriangleMesh& a, const TriangleMesh& b) {
  const Index nv = a.vertex_count(), nt = a.triangle_count();
  a.vertices.conservativeResize(3, nv + b.vertex_count());
  a.vertices.rightCols(b.vertex_count()) = b.vertices;
  a.triangles.conservativeResize(3, nt + b.triangle_count());
  a.triangles.rightCols(b.triangle_count()) = b.triangles.array() + static_cast<int>(nv);
}

/// `mesh` moved by the transform `T` (a copy).
inline TriangleMesh transformed(TriangleMesh mesh, const Eigen::Affine3d& T) {
  transform_mesh(mesh, T);
  return mesh;
}

/// Axis-aligned box of edge lengths `size`, centred on the origin. 12 triangles.
inline TriangleMesh make_box(const Eigen::Vector3d& size) {
  if (!(size.array() > 0).all() || !size.allFinite())
    throw InvalidArgument("size", "box edges must be finite and positive, got " + format_value(size.x()) + " x " +
                                      format_value(size.y()) + " x " + format_value(size.z()));
  const Eigen::Vector3d h = size / 2;
  std::vector<Eigen::Vector3d> v;
  for (int i = 0; i < 8; ++i)
    v.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z());
  const std::vector<Eigen::Vector3i> t = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                                          {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return detail::mesh_from(v, t);
}

/// Solid of revolution about the z axis: `profile` lists (radius, z) points
/// from the bottom to the top; a radius of 0 is a pole (use it at the two
/// ends to close the solid). `segments` points per ring (>= 3). A profile
/// that, closed along the axis, encloses no area or runs clockwise in the
/// (radius, z) plane (listed from the top down: an inside-out solid) is
/// refused naming "profile".
inline TriangleMesh make_lathe(const std::vector<Eigen::Vector2d>& profile, int segments) {
  if (profile.size() < 2) throw InvalidArgument("profile", "needs at least 2 points");
  if (segments < 3) throw InvalidArgument("segments", "needs at least 3, got " + std::to_string(segments));
  for (std::size_t i = 0; i < profile.size(); ++i) {
    const std::string which = "point " + std::to_string(i);
    if (!profile[i].allFinite()) throw InvalidArgument("profile", which + " is not finite");
    if (profile[i].x() < 0)
      throw InvalidArgument("profile", "radius must be >= 0, got " + format_value(profile[i].x()) + " at " + which);
  }
  // Twice the signed area of the profile closed along the axis (shoelace).
  double twice_area = 0;
  for (std::size_t i = 0; i < profile.size(); ++i) {
    const Eigen::Vector2d& p = profile[i];
    const Eigen::Vector2d& q = profile[(i + 1) % profile.size()];
    twice_area += p.x() * q.y() - q.x() * p.y();
  }
  if (!(twice_area > 0))
    throw InvalidArgument("profile", "encloses no area or lists its points from the top down (signed area " +
                                         format_value(twice_area / 2) +
                                         " in the (radius, z) plane, closed along the axis): list them from the "
                                         "bottom up");
  std::vector<Eigen::Vector3d> v;
  std::vector<int> start;  // first vertex of each profile point
  for (const auto& p : profile) {
    start.push_back(static_cast<int>(v.size()));
    if (p.x() == 0) {
      v.emplace_back(0, 0, p.y());
    } else {
      for (int j = 0; j < segments; ++j) {
        const double a = 2 * detail::kPi * j / segments;
        v.emplace_back(p.x() * std::cos(a), p.x() * std::sin(a), p.y());
      }
    }
  }
  std::vector<Eigen::Vector3i> t;
  for (std::size_t i = 0; i + 1 < profile.size(); ++i) {
    const bool lo_pole = profile[i].x() == 0, hi_pole = profile[i + 1].x() == 0;
    const int a0 = start[i], b0 = start[i + 1];
    for (int j = 0; j < segments; ++j) {
      const int j1 = (j + 1) % segments;
      if (lo_pole && hi_pole) break;
      if (lo_pole) {
        t.emplace_back(a0, b0 + j1, b0 + j);
      } else if (hi_pole) {
        t.emplace_back(a0 + j, a0 + j1, b0);
      } else {
        t.emplace_back(a0 + j, a0 + j1, b0 + j1);
        t.emplace_back(a0 + j, b0 + j1, b0 + j);
      }
    }
  }
  return detail::mesh_from(v, t);
}

/// Cylinder of `radius` and `length` along z, centred on the origin.
inline TriangleMesh make_cylinder(double radius, double length, int segments = 32) {
  check_positive(radius, "radius");
  check_positive(length, "length");
  const double h = length / 2;
  return make_lathe({{0, -h}, {radius, -h}, {radius, h}, {0, h}}, segments);
}

/// Frustum along z from z = 0 (radius r0) to z = length (radius r1); one
/// radius may be 0 (a cone).
inline TriangleMesh make_frustum(double r0, double r1, double length, int segments = 32) {
  check_non_negative(r0, "r0");
  check_non_negative(r1, "r1");
  if (r0 == 0 && r1 == 0) throw InvalidArgument("r1", "r0 and r1 are both 0: no solid");
  check_positive(length, "length");
  std::vector<Eigen::Vector2d> p = {{0, 0}};
  if (r0 > 0) p.emplace_back(r0, 0);
  if (r1 > 0) p.emplace_back(r1, length);
  p.emplace_back(0, length);
  return make_lathe(p, segments);
}

/// Capsule along z: a cylinder of `radius` whose axis segment has `length`,
/// with hemispherical ends; centred on the origin. Total length
/// length + 2 radius.
inline TriangleMesh make_capsule(double radius, double length, int segments = 24, int cap_rings = 6) {
  check_positive(radius, "radius");
  check_positive(length, "length");  // 0 would stack two rings: use make_sphere
  if (cap_rings < 1) throw InvalidArgument("cap_rings", "needs at least 1, got " + std::to_string(cap_rings));
  const double h = length / 2;
  if (!std::isfinite(h + radius))
    throw InvalidArgument("length", "length / 2 + radius is beyond a double (length " + format_value(length) +
                                        ", radius " + format_value(radius) + ")");
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i <= cap_rings; ++i) {
    const double a = -detail::kPi / 2 + (detail::kPi / 2) * i / cap_rings;
    p.emplace_back(radius * std::cos(a), -h + radius * std::sin(a));
  }
  for (int i = 0; i <= cap_rings; ++i) {
    const double a = (detail::kPi / 2) * i / cap_rings;
    p.emplace_back(radius * std::cos(a), h + radius * std::sin(a));
  }
  p.front().x() = 0;
  p.back().x() = 0;
  return make_lathe(p, segments);
}

/// Sphere of `radius` centred on the origin.
inline TriangleMesh make_sphere(double radius, int segments = 24, int rings = 12) {
  check_positive(radius, "radius");
  if (rings < 2) throw InvalidArgument("rings", "needs at least 2, got " + std::to_string(rings));
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i <= rings; ++i) {
    const double a = -detail::kPi / 2 + detail::kPi * i / rings;
    p.emplace_back(i == 0 || i == rings ? 0.0 : radius * std::cos(a), radius * std::sin(a));
  }
  return make_lathe(p, segments);
}

/// Prism: the simple polygon `outline` (x, y; either orientation) extruded
/// from z = z0 to z = z1. Caps are triangulated by ear clipping. An outline
/// that is not simple is refused, naming the points or edges at fault: two
/// points that coincide, two edges in a row that fold back on each other
/// (a spike of zero width), a point on an edge not its own, two edges that
/// cross. Consecutive collinear points going on in the same direction are
/// fine. The tests are exact in double (a point off an edge by rounding is
/// not on it). O(n^2) in the outline size.
inline TriangleMesh make_extrusion(std::vector<Eigen::Vector2d> outline, double z0, double z1) {
  const std::size_t n = outline.size();
  if (n < 3) throw InvalidArgument("outline", "needs at least 3 points");
  for (std::size_t i = 0; i < n; ++i)
    if (!outline[i].allFinite()) throw InvalidArgument("outline", "point " + std::to_string(i) + " is not finite");
  check_finite(z0, "z0");
  check_finite(z1, "z1");
  if (!(z1 > z0)) throw InvalidArgument("z1", "must be above z0");
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  // Edge i runs from point i to point i + 1 (mod n). Each refusal below is
  // an outline whose caps or walls would be degenerate or overlap.
  auto refuse = [](const std::string& why) { throw InvalidArgument("outline", why + ": not a simple polygon"); };
  auto text = [](std::size_t i) { return std::to_string(i); };
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t i1 = (i + 1) % n, i2 = (i + 2) % n;
    const auto &a = outline[i], &b = outline[i1], &c = outline[i2];
    if (a == b) refuse("points " + text(std::min(i, i1)) + " and " + text(std::max(i, i1)) + " coincide");
    if (b != c && cross(a, b, c) == 0 && (b - a).dot(c - b) < 0)
      refuse("edges " + text(std::min(i, i1)) + " and " + text(std::max(i, i1)) + " fold back on each other");
  }
  // Two edges not next to each other must not meet: a crossing (each one's
  // ends strictly on both sides of the other) makes a bow-tie, whose caps
  // ear clipping would cover wrongly; a point on the other edge pinches the
  // polygon into two that share a point or overlap along a segment.
  auto opposite = [](double u, double v) { return (u > 0 && v < 0) || (u < 0 && v > 0); };
  // q, collinear with edge [e0, e1], lies within it.
  auto within = [](const Eigen::Vector2d& e0, const Eigen::Vector2d& e1, const Eigen::Vector2d& q) {
    return std::min(e0.x(), e1.x()) <= q.x() && q.x() <= std::max(e0.x(), e1.x()) &&
           std::min(e0.y(), e1.y()) <= q.y() && q.y() <= std::max(e0.y(), e1.y());
  };
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      const std::size_t i1 = (i + 1) % n, j1 = (j + 1) % n;
      const auto &a = outline[i], &b = outline[i1], &c = outline[j], &d = outline[j1];
      const double c_ab = cross(a, b, c), d_ab = cross(a, b, d), a_cd = cross(c, d, a), b_cd = cross(c, d, b);
      if (opposite(c_ab, d_ab) && opposite(a_cd, b_cd)) refuse("edges " + text(i) + " and " + text(j) + " cross");
      // Which point of one edge lies on the other; a point equal to an end of
      // that edge is a repeated point.
      auto on = [&](std::size_t k, double side, const Eigen::Vector2d& e0, const Eigen::Vector2d& e1,
                    std::size_t k0, std::size_t k1, std::size_t edge) {
        const auto& q = outline[k];
        if (side != 0 || !within(e0, e1, q)) return;
        if (q == e0 || q == e1)
          refuse("points " + text(std::min(k, q == e0 ? k0 : k1)) + " and " + text(std::max(k, q == e0 ? k0 : k1)) +
                 " coincide");
        refuse("point " + text(k) + " lies on edge " + text(edge));
      };
      on(j, c_ab, a, b, i, i1, i);
      on(j1, d_ab, a, b, i, i1, i);
      on(i, a_cd, c, d, j, j1, j);
      on(i1, b_cd, c, d, j, j1, j);
    }
  double area2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& a = outline[i];
    const auto& b = outline[(i + 1) % n];
    area2 += a.x() * b.y() - b.x() * a.y();
  }
  if (area2 == 0) throw InvalidArgument("outline", "has zero area");
  if (area2 < 0) std::reverse(outline.begin(), outline.end());
  // Ear clipping of the counter-clockwise outline.
  std::vector<int> idx(n);
  for (std::size_t i = 0; i < n; ++i) idx[i] = static_cast<int>(i);
  std::vector<Eigen::Vector3i> caps;  // counter-clockwise seen from +z
  std::size_t guard = 0;
  while (idx.size() > 3) {
    bool clipped = false;
    for (std::size_t i = 0; i < idx.size(); ++i) {
      const int ia = idx[(i + idx.size() - 1) % idx.size()], ib = idx[i], ic = idx[(i + 1) % idx.size()];
      const auto &a = outline[static_cast<std::size_t>(ia)], &b = outline[static_cast<std::size_t>(ib)],
                 &c = outline[static_cast<std::size_t>(ic)];
      if (cross(a, b, c) <= 0) continue;  // reflex or degenerate
      bool empty = true;
      for (int k : idx) {
        if (k == ia || k == ib || k == ic) continue;
        const auto& q = outline[static_cast<std::size_t>(k)];
        if (cross(a, b, q) >= 0 && cross(b, c, q) >= 0 && cross(c, a, q) >= 0) {
          empty = false;
          break;
        }
      }
      if (!empty) continue;
      caps.emplace_back(ia, ib, ic);
      idx.erase(idx.begin() + static_cast<std::ptrdiff_t>(i));
      clipped = true;
      break;
    }
    if (!clipped || ++guard > 4 * n)
      throw InvalidArgument("outline", "is not a simple polygon (ear clipping failed)");
  }
  caps.emplace_back(idx[0], idx[1], idx[2]);
  std::vector<Eigen::Vector3d> v;
  for (const auto& p : outline) v.emplace_back(p.x(), p.y(), z0);
  for (const auto& p : outline) v.emplace_back(p.x(), p.y(), z1);
  const int N = static_cast<int>(n);
  std::vector<Eigen::Vector3i> t;
  for (const auto& c : caps) {
    t.emplace_back(c[0] + N, c[1] + N, c[2] + N);  // top, +z
    t.emplace_back(c[0], c[2], c[1]);              // bottom, -z
  }
  for (int i = 0; i < N; ++i) {
    const int j = (i + 1) % N;
    t.emplace_back(i, j, j + N);
    t.emplace_back(i, j + N, i + N);
  }
  return detail::mesh_from(v, t);
}

/// Points of a circular arc (centre, radius, angles in radians, both ends
/// included: steps + 1 points, steps >= 1), for building outlines.
inline std::vector<Eigen::Vector2d> arc_points(const Eigen::Vector2d& centre, double radius, double from, double to,
                                               int steps) {
  if (!centre.allFinite()) throw InvalidArgument("centre", "is not finite");
  check_positive(radius, "radius");
  check_finite(from, "from");
  check_finite(to, "to");
  if (steps < 1) throw InvalidArgument("steps", "needs at least 1, got " + std::to_string(steps));
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i <= steps; ++i) {
    const double a = from + (to - from) * i / steps;
    p.push_back(centre + radius * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  return p;
}

}  // namespace iclap

// SPDX-License-Identifier: MIT
#pragma once

// Putting a mesh on the table: a stable resting pose, principal axes along x
// and y, centred on the table origin with its lowest point on z = 0.

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "iclap/core/error.hpp"
#include "iclap/mesh/convex_hull.hpp"
#include "iclap/mesh/triangle_mesh.hpp"

namespace iclap {

/// Settings of place_on_table.
struct TablePlacementSettings {
  /// Hull triangles whose normals differ by less than this (radians) from
  /// the largest one of a group are merged into one resting face. Scanned
  /// meshes have slightly wavy flat faces; 2 degrees keeps them one face.
  /// Must be in [0, pi/2].
  double face_merge_angle = 2.0 * 3.14159265358979323846 / 180.0;
};

/// The outcome of place_on_table.
struct TablePlacement {
  TriangleMesh mesh;              ///< the placed mesh (same units as the input)
  Eigen::Isometry3d T_table_mesh; ///< maps input coordinates to table coordinates
  double resting_face_area = 0;   ///< area of the hull face it rests on (squared units)
  bool stable = false;            ///< the centre of mass projects inside that face
};

/// Moves `mesh` so that its bounds are centred on x = y = 0 and its lowest
/// point is on z = 0, without rotating it. For meshes already built in their
/// resting orientation (the simulator's built-in objects).
inline TablePlacement center_on_table(TriangleMesh mesh) {
  validate_mesh(mesh);
  const Eigen::AlignedBox3d box = mesh_bounds(mesh);
  const Eigen::Vector3d shift(-box.center().x(), -box.center().y(), -box.min().z());
  mesh.vertices.colwise() += shift;
  TablePlacement out;
  out.T_table_mesh = Eigen::Isometry3d::Identity();
  out.T_table_mesh.translation() = shift;
  out.mesh = std::move(mesh);
  out.stable = true;
  return out;
}

namespace detail {

/// Twice the signed area of triangle (o, a, b) in 2-D.
inline double cross2(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

/// Andrew's monotone chain: the convex hull of 2-D points, counter-clockwise.
inline std::vector<Eigen::Vector2d> convex_hull_2d(std::vector<Eigen::Vector2d> pts) {
  std::sort(pts.begin(), pts.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (pts.size() < 3) return pts;
  std::vector<Eigen::Vector2d> h(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross2(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross2(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  h.resize(k - 1);
  return h;
}

/// Distance from `q` to the outside of the convex counter-clockwise polygon
/// (negative inside: minus the distance to the nearest edge).
inline double signed_distance_to_polygon(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& q) {
  if (poly.size() < 3) return std::numeric_limits<double>::infinity();
  double inside = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector2d a = poly[i], b = poly[(i + 1) % poly.size()];
    const Eigen::Vector2d e = b - a;
    const double len = e.norm();
    if (len <= 0) continue;
    const double d = cross2(a, b, q) / len;  // > 0 left of the edge (inside)
    inside = std::min(inside, d);
  }
  return -inside;
}

}  // namespace detail

/// Puts a mesh on the table the way a person would lay the object down:
///
/// 1. Resting pose: the convex hull's faces (nearly coplanar triangles
///    merged, see the settings) on which the object is statically stable,
///    i.e. its centre of mass (uniform density) projects inside the face; of
///    those the one with the lowest centre of mass (the most stable pose:
///    for a box its largest face, for a flat tool lying flat, which a
///    "largest face" rule misses on scanned meshes whose flat sides are
///    wavy), ties to the larger face. That face is turned to point down.
/// 2. Principal axes: turned about z so that the principal axis of largest
///    spread (area-weighted surface) is x and the next one y; the sign puts
///    the centre of mass at x >= 0 of the bounds' centre (the heavier end
///    towards +x), then y >= 0.
/// 3. Centred: bounds centred on x = y = 0, lowest point on z = 0.
///
/// Works in any unit (scale first for metres). Deterministic. O(T log T) for
/// T triangles. Throws like validate_mesh (also for a mesh whose triangles
/// all have zero area), InvalidArgument if the mesh is flat (spans no
/// volume), has a coordinate beyond +-1e75 (areas and volumes would
/// overflow), or settings.face_merge_angle is outside [0, pi/2].
inline TablePlacement place_on_table(const TriangleMesh& mesh, const TablePlacementSettings& settings = {}) {
  validate_mesh(mesh);
  if (!(settings.face_merge_angle >= 0 && settings.face_merge_angle <= 3.14159265358979323846 / 2))
    throw InvalidArgument("settings.face_merge_angle",
                          "must be in [0, pi/2] radians, got " + format_value(settings.face_merge_angle));
  check_mesh_range(mesh);
  // Only vertices that triangles use (some CAD files carry unused ones).
  std::vector<char> used(static_cast<std::size_t>(mesh.vertex_count()), 0);
  for (Index t = 0; t < mesh.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) used[static_cast<std::size_t>(mesh.triangles(k, t))] = 1;
  Eigen::Matrix3Xd pts(3, std::count(used.begin(), used.end(), 1));
  for (Index v = 0, j = 0; v < mesh.vertex_count(); ++v)
    if (used[static_cast<std::size_t>(v)]) pts.col(j++) = mesh.vertices.col(v);
  // convex_hull's refusal of a flat point set ("points") is the mesh's.
  const TriangleMesh hull = rename_argument("points", "mesh", [&] { return convex_hull(pts); });
  const Eigen::Vector3d com = mass_centroid(mesh);

  // Group hull triangles into faces, largest triangles first.
  const Index nh = hull.triangle_count();
  std::vector<double> area(static_cast<std::size_t>(nh));
  std::vector<Eigen::Vector3d> normal(static_cast<std::size_t>(nh));
  std::vector<Index> by_area(static_cast<std::size_t>(nh));
  for (Index t = 0; t < nh; ++t) {
    const Eigen::Vector3d an = hull.area_normal(t);
    area[static_cast<std::size_t>(t)] = 0.5 * an.norm();
    normal[static_cast<std::size_t>(t)] = an.norm() > 0 ? Eigen::Vector3d(an.normalized()) : Eigen::Vector3d::Zero();
    by_area[static_cast<std::size_t>(t)] = t;
  }
  std::stable_sort(by_area.begin(), by_area.end(),
                   [&](Index x, Index y) { return area[static_cast<std::size_t>(x)] > area[static_cast<std::size_t>(y)]; });
  std::vector<char> taken(static_cast<std::size_t>(nh), 0);
  const double cos_merge = std::cos(settings.face_merge_angle);
  double best_area = -1, best_any_area = -1, best_height = std::numeric_limits<double>::infinity();
  const double scale = (pts.rowwise().maxCoeff() - pts.rowwise().minCoeff()).norm();
  Eigen::Vector3d best_down = Eigen::Vector3d::Zero(), best_any_down = Eigen::Vector3d::Zero();
  for (Index seed : by_area) {
    if (taken[static_cast<std::size_t>(seed)] || area[static_cast<std::size_t>(seed)] <= 0) continue;
    const Eigen::Vector3d n0 = normal[static_cast<std::size_t>(seed)];
    double face_area = 0;
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
    std::vector<Index> members;
    for (Index t = 0; t < nh; ++t) {
      if (taken[static_cast<std::size_t>(t)] || normal[static_cast<std::size_t>(t)].dot(n0) < cos_merge) continue;
      taken[static_cast<std::size_t>(t)] = 1;
      members.push_back(t);
      face_area += area[static_cast<std::size_t>(t)];
      weighted += area[static_cast<std::size_t>(t)] * normal[static_cast<std::size_t>(t)];
    }
    const Eigen::Vector3d down = weighted.normalized();
    // Stability: the centre of mass projected along `down` inside the face.
    const Eigen::Vector3d u = down.unitOrthogonal(), w = down.cross(u);
    std::vector<Eigen::Vector2d> footprint;
    for (Index t : members)
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d q = hull.corner(t, k);
        footprint.emplace_back(u.dot(q), w.dot(q));
      }
    const auto poly = detail::convex_hull_2d(footprint);
    const bool stable = detail::signed_distance_to_polygon(poly, Eigen::Vector2d(u.dot(com), w.dot(com))) < 0;
    // Height of the centre of mass above the table in this pose.
    const double height = (down.transpose() * hull.vertices).maxCoeff() - down.dot(com);
    if (stable && (height < best_height - 1e-9 * scale ||
                   (height <= best_height + 1e-9 * scale && face_area > best_area))) {
      best_height = height;
      best_area = face_area;
      best_down = down;
    }
    if (face_area > best_any_area) {
      best_any_area = face_area;
      best_any_down = down;
    }
  }
  TablePlacement out;
  out.stable = best_area > 0;
  if (!out.stable) {  // numerically impossible for a real hull; keep a pose anyway
    best_area = best_any_area;
    best_down = best_any_down;
  }
  out.resting_face_area = best_area;

  // Rotate `down` onto -z.
  Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(best_down, -Eigen::Vector3d::UnitZ()).toRotationMatrix();
  // Principal axes in the table plane, from the area-weighted surface.
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  double total = 0;
  for (Index t = 0; t < mesh.triangle_count(); ++t) {
    const double a = 0.5 * mesh.area_normal(t).norm();
    const Eigen::Vector3d c = R * (mesh.corner(t, 0) + mesh.corner(t, 1) + mesh.corner(t, 2)) / 3.0;
    mean += a * c.head<2>();
    total += a;
  }
  if (!(total > 0))  // validate_mesh saw an area; its square underflowed (coordinates near 1e-160)
    throw InvalidArgument("mesh", "triangle areas underflow to zero (scale the mesh up)");
  mean /= total;
  for (Index t = 0; t < mesh.triangle_count(); ++t) {
    // Exact second moment of the triangle's area:
    // integral of d d^T dA = A / 12 (sum_i d_i d_i^T + s s^T), s = sum_i d_i.
    const double a = 0.5 * mesh.area_normal(t).norm();
    Eigen::Vector2d s = Eigen::Vector2d::Zero();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d d = (R * mesh.corner(t, k)).head<2>() - mean;
      cov += (a / 12.0) * d * d.transpose();
      s += d;
    }
    cov += (a / 12.0) * s * s.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
  Eigen::Vector2d major = eig.eigenvectors().col(1);  // largest eigenvalue last
  const double yaw = -std::atan2(major.y(), major.x());
  R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R;
  // Signs: heavier end towards +x, then +y (rotations by pi about z keep z).
  TriangleMesh placed = mesh;
  for (Index v = 0; v < placed.vertex_count(); ++v) placed.vertices.col(v) = R * mesh.vertices.col(v);
  Eigen::AlignedBox3d box = mesh_bounds(placed);
  const Eigen::Vector3d c = R * com - box.center();
  if (c.x() < 0 || (c.x() == 0 && c.y() < 0)) {
    const Eigen::Matrix3d flip = Eigen::AngleAxisd(3.14159265358979323846, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    R = flip * R;
    for (Index v = 0; v < placed.vertex_count(); ++v) placed.vertices.col(v) = R * mesh.vertices.col(v);
    box = mesh_bounds(placed);
  }
  const Eigen::Vector3d shift(-box.center().x(), -box.center().y(), -box.min().z());
  placed.vertices.colwise() += shift;
  out.T_table_mesh.linear() = R;
  out.T_table_mesh.translation() = shift;
  out.T_table_mesh.makeAffine();
  out.mesh = std::move(placed);
  return out;
}

}  // namespace iclap

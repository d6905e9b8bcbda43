// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"

namespace iclap {

namespace detail {

/// The exponent e with 2^-e * extent in [0.5, 1) (std::frexp's), for an
/// extent > 0. Geometry scaled by 2^-e (scale_by_power_of_two) rounds
/// exactly as unscaled geometry does, but its products of up to four
/// lengths neither overflow nor underflow.
inline int unit_exponent(double extent) {
  int exponent = 0;
  std::frexp(extent, &exponent);
  return exponent;
}

/// Every coefficient of `m` times 2^e, exactly (std::ldexp, so no factor
/// 2^e is formed: it would overflow for the e of a subnormal extent).
template <typename Derived>
auto scale_by_power_of_two(const Eigen::MatrixBase<Derived>& m, int e) {
  return m.unaryExpr([e](typename Derived::Scalar v) { return std::ldexp(v, e); });
}

}  // namespace detail

/// An indexed triangle mesh: the surface of a rigid object.
///
/// Invariants (checked by `validate_mesh`): every vertex finite, every index
/// in [0, vertices.cols()). Triangles are counter-clockwise seen from outside
/// (outward normals) for closed meshes; loaders keep the file's order and
/// `orient_outward` fixes inverted ones. Several closed shells may overlap or
/// touch (CAD assemblies, unions of primitives): queries in iclap treat the
/// object as their union. Length unit: whatever the producer says; loaders
/// return file units, the simulator works in metres.
struct TriangleMesh {
  Eigen::Matrix3Xd vertices;   ///< one vertex per column
  Eigen::Matrix3Xi triangles;  ///< one triangle per column: three vertex indices

  Index vertex_count() const noexcept { return vertices.cols(); }
  Index triangle_count() const noexcept { return triangles.cols(); }

  /// Corner `k` (0..2) of triangle `t`.
  Eigen::Vector3d corner(Index t, int k) const { return vertices.col(triangles(k, t)); }

  /// Unnormalised normal of triangle `t` (length = twice its area).
  Eigen::Vector3d area_normal(Index t) const {
    const Eigen::Vector3d a = corner(t, 0);
    return (corner(t, 1) - a).cross(corner(t, 2) - a);
  }
};

/// Throws InvalidArgument naming `argument` if `mesh` breaks an invariant
/// (non-finite vertex, index out of range), has no triangles, or has no
/// triangle of positive area (every one degenerate: no surface). O(size).
inline void validate_mesh(const TriangleMesh& mesh, const std::string& argument = "mesh") {
  if (mesh.triangles.cols() == 0) throw EmptyInput(argument, "has no triangles");
  for (Index v = 0; v < mesh.vertices.cols(); ++v)
    if (!mesh.vertices.col(v).allFinite())
      throw InvalidArgument(argument, "vertex " + std::to_string(v) + " is not finite");
  for (Index t = 0; t < mesh.triangles.cols(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int i = mesh.triangles(k, t);
      if (i < 0 || i >= mesh.vertices.cols())
        throw InvalidArgument(argument, "triangle " + std::to_string(t) + " has vertex index " +
                                            std::to_string(i) + " outside [0, " +
                                            std::to_string(mesh.vertices.cols()) + ")");
    }
  bool any_area = false;
  for (Index t = 0; t < mesh.triangles.cols() && !any_area; ++t)
    any_area = (mesh.area_normal(t).array() != 0.0).any();
  if (!any_area)
    throw InvalidArgument(argument, "every one of its " + std::to_string(mesh.triangles.cols()) +
                                        " triangles has zero area (no surface)");
}

/// The largest vertex coordinate magnitude the geometry functions take
/// (place_on_table, MeshBvh, sample_surface): areas square and volumes cube
/// the coordinates, and beyond this they overflow a double.
inline constexpr double kMaxMeshCoordinate = 1e75;

/// Throws InvalidArgument naming `argument` when a vertex that a triangle
/// uses has a coordinate beyond +-kMaxMeshCoordinate (the value and the
/// vertex named). Call after validate_mesh. O(size).
inline void check_mesh_range(const TriangleMesh& mesh, const std::string& argument = "mesh") {
  for (Index t = 0; t < mesh.triangles.cols(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles(k, t);
      const double big = mesh.vertices.col(v).cwiseAbs().maxCoeff();
      if (!(big <= kMaxMeshCoordinate))
        throw InvalidArgument(argument, "has a coordinate of magnitude " + format_value(big) + ", more than " +
                                            format_value(kMaxMeshCoordinate) + " (vertex " + std::to_string(v) +
                                            "; scale it down)");
    }
}

/// Axis-aligned bounds of the vertices that triangles use.
inline Eigen::AlignedBox3d mesh_bounds(const TriangleMesh& mesh) {
  Eigen::AlignedBox3d box;
  for (Index t = 0; t < mesh.triangles.cols(); ++t)
    for (int k = 0; k < 3; ++k) box.extend(mesh.corner(t, k));
  return box;
}

/// Total triangle area (squared units). O(triangles).
inline double surface_area(const TriangleMesh& mesh) {
  double a = 0;
  for (Index t = 0; t < mesh.triangles.cols(); ++t) a += 0.5 * mesh.area_normal(t).norm();
  return a;
}

/// Signed volume by the divergence theorem (cubic units): positive for a
/// closed mesh with outward normals. For overlapping shells it is the sum of
/// the shells' volumes. O(triangles).
inline double signed_volume(const TriangleMesh& mesh) {
  double v = 0;
  for (Index t = 0; t < mesh.triangles.cols(); ++t)
    v += mesh.corner(t, 0).dot(mesh.corner(t, 1).cross(mesh.corner(t, 2)));
  return v / 6.0;
}

/// Centre of mass of the solid bounded by `mesh` (uniform density), from
/// signed tetrahedra; falls back to the area-weighted surface centroid when
/// the signed volume is (nearly) zero, e.g. for an open surface. Any finite
/// size works: the tetrahedra are computed scaled by a power of two, which
/// is exact. O(triangles).
inline Eigen::Vector3d mass_centroid(const TriangleMesh& mesh) {
  // Tetrahedra against a reference point inside the bounds, for precision
  // with far-away origins (CAD files), with the extent brought into
  // [0.5, 1): a tetrahedron's volume is a cube of lengths, so a mesh under
  // about 1e-100 across underflowed to "no volume" (its surface centroid)
  // and one over 1e100 overflowed. Elsewhere the result is as unscaled, bit
  // for bit.
  const Eigen::AlignedBox3d bounds = mesh_bounds(mesh);
  const Eigen::Vector3d ref = bounds.center();
  const double extent = bounds.sizes().maxCoeff();
  const int e = extent > 0 && std::isfinite(extent) ? detail::unit_exponent(extent) : 0;
  double volume = 0, area = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero(), area_moment = Eigen::Vector3d::Zero();
  for (Index t = 0; t < mesh.triangles.cols(); ++t) {
    const Eigen::Vector3d a = detail::scale_by_power_of_two(mesh.corner(t, 0) - ref, -e),
                          b = detail::scale_by_power_of_two(mesh.corner(t, 1) - ref, -e),
                          c = detail::scale_by_power_of_two(mesh.corner(t, 2) - ref, -e);
    const double v = a.dot(b.cross(c)) / 6.0;
    volume += v;
    moment += v * (a + b + c) / 4.0;
    const double s = 0.5 * (b - a).cross(c - a).norm();
    area += s;
    area_moment += s * (a + b + c) / 3.0;
  }
  const double scale = detail::scale_by_power_of_two(bounds.sizes(), -e).prod();
  if (std::abs(volume) > 1e-9 * scale && scale > 0)
    return ref + detail::scale_by_power_of_two(moment / volume, e);
  if (area > 0) return ref + detail::scale_by_power_of_two(area_moment / area, e);
  return ref;
}

/// Flips every triangle if the signed volume is negative (an inside-out
/// file), so that normals point outward. Returns true if it flipped.
inline bool orient_outward(TriangleMesh& mesh) {
  if (signed_volume(mesh) >= 0) return false;
  mesh.triangles.row(1).swap(mesh.triangles.row(2));
  return true;
}

/// Applies the rigid or affine transform `T` to every vertex (in place).
inline void transform_mesh(TriangleMesh& mesh, const Eigen::Affine3d& T) {
  for (Index v = 0; v < mesh.vertices.cols(); ++v) mesh.vertices.col(v) = T * Eigen::Vector3d(mesh.vertices.col(v));
}

}  // namespace iclap

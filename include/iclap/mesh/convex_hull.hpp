// SPDX-License-Identifier: MIT
#pragma once

// 3-D convex hull (quickhull), used to find the faces an object can rest on.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/error.hpp"
#include "iclap/mesh/triangle_mesh.hpp"

namespace iclap {

/// Convex hull of a point set as a closed triangle mesh with outward normals.
/// `vertices` holds only the hull's vertices.
///
/// Quickhull (Barber, Dobkin, Huhdanpaa 1996) with a distance tolerance of
/// about 1e-12 of the point set's extent: points closer than that to a hull
/// face count as on it, so coplanar input (CAD faces) gives no slivers
/// outside the hull. Expected O(n log n). Works at any scale whose bounds'
/// centre and extent are finite (up to about 1e307). Throws
/// InvalidArgument if the points are not finite, are too large for that, or
/// span no volume (fewer than 4 points, or all on one plane).
inline TriangleMesh convex_hull(const Eigen::Matrix3Xd& points) {
  const Index n = points.cols();
  if (n < 4) throw InvalidArgument("points", "a 3-D convex hull needs at least 4 points, got " + std::to_string(n));
  if (!points.allFinite()) throw InvalidArgument("points", "has a non-finite coordinate");
  // Work relative to the centre of the bounds, for precision with far
  // origins, and scaled by a power of two that brings the extent into
  // [0.5, 1): exact, so every decision is the same as unscaled, but squared
  // lengths and cross products neither overflow (coordinates up to about
  // 1e300) nor underflow.
  const Eigen::Vector3d lo = points.rowwise().minCoeff(), hi = points.rowwise().maxCoeff();
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  double extent = (hi - lo).maxCoeff();
  if (!std::isfinite(extent) || !centre.allFinite())
    throw InvalidArgument("points", "coordinates too large to compute with (the extent overflows)");
  if (!(extent > 0)) throw InvalidArgument("points", "all points coincide");
  const int exponent = detail::unit_exponent(extent);
  const Eigen::Matrix3Xd p = detail::scale_by_power_of_two(points.colwise() - centre, -exponent);
  extent = std::ldexp(extent, -exponent);
  const double eps = 1e-12 * extent * 64;

  struct Face {
    int v[3];
    Eigen::Vector3d normal;
    double offset = 0;  // normal . x = offset on the plane
    std::vector<int> outside;
    bool alive = true;
  };
  std::vector<Face> faces;
  std::unordered_map<std::uint64_t, int> edge_face;  // directed edge (a,b) -> face having it
  auto edge_key = [](int a, int b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
  };
  auto pt = [&](int i) { return Eigen::Vector3d(p.col(i)); };
  auto make_face = [&](int a, int b, int c) {
    Face f;
    f.v[0] = a;
    f.v[1] = b;
    f.v[2] = c;
    const Eigen::Vector3d nn = (pt(b) - pt(a)).cross(pt(c) - pt(a));
    const double len = nn.norm();
    f.normal = len > 0 ? Eigen::Vector3d(nn / len) : Eigen::Vector3d::Zero();
    f.offset = f.normal.dot(pt(a));
    const int id = static_cast<int>(faces.size());
    faces.push_back(std::move(f));
    for (int k = 0; k < 3; ++k) edge_face[edge_key(faces[static_cast<std::size_t>(id)].v[k], faces[static_cast<std::size_t>(id)].v[(k + 1) % 3])] = id;
    return id;
  };
  auto dist = [&](const Face& f, int i) { return f.normal.dot(pt(i)) - f.offset; };

  // Initial tetrahedron from extreme points.
  int e[6];
  for (int k = 0; k < 3; ++k) {
    Index imin = 0, imax = 0;
    p.row(k).minCoeff(&imin);
    p.row(k).maxCoeff(&imax);
    e[2 * k] = static_cast<int>(imin);
    e[2 * k + 1] = static_cast<int>(imax);
  }
  int a = e[0], b = e[1];
  double best = -1;
  for (int i = 0; i < 6; ++i)
    for (int j = i + 1; j < 6; ++j) {
      const double d = (pt(e[i]) - pt(e[j])).squaredNorm();
      if (d > best) {
        best = d;
        a = e[i];
        b = e[j];
      }
    }
  int c = -1;
  best = eps * eps;
  const Eigen::Vector3d ab = (pt(b) - pt(a)).normalized();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d ap = pt(i) - pt(a);
    const double d = (ap - ab * ab.dot(ap)).squaredNorm();
    if (d > best) {
      best = d;
      c = i;
    }
  }
  if (c < 0) throw InvalidArgument("points", "all points lie on a line");
  const Eigen::Vector3d nabc = (pt(b) - pt(a)).cross(pt(c) - pt(a)).normalized();
  int dv = -1;
  best = eps;
  for (int i = 0; i < n; ++i) {
    const double d = std::abs(nabc.dot(pt(i) - pt(a)));
    if (d > best) {
      best = d;
      dv = i;
    }
  }
  if (dv < 0) throw InvalidArgument("points", "all points lie on a plane (no volume)");
  if (nabc.dot(pt(dv) - pt(a)) > 0) std::swap(b, c);  // make abc face away from d
  make_face(a, b, c);
  make_face(a, dv, b);
  make_face(b, dv, c);
  make_face(c, dv, a);

  // Assign every point to a face it is outside of.
  for (int i = 0; i < n; ++i) {
    if (i == a || i == b || i == c || i == dv) continue;
    for (auto& f : faces)
      if (dist(f, i) > eps) {
        f.outside.push_back(i);
        break;
      }
  }

  std::vector<int> visible, stack, horizon_a, horizon_b;
  std::vector<char> is_visible;
  for (std::size_t fi = 0; fi < faces.size(); ++fi) {
    if (!faces[fi].alive || faces[fi].outside.empty()) continue;
    // The farthest outside point of this face is the next hull vertex.
    int eye = -1;
    double far = -1;
    for (int i : faces[fi].outside) {
      const double d = dist(faces[fi], i);
      if (d > far) {
        far = d;
        eye = i;
      }
    }
    // Faces visible from the eye: flood fill across edges.
    visible.clear();
    is_visible.assign(faces.size(), 0);
    stack.assign(1, static_cast<int>(fi));
    is_visible[fi] = 1;
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      visible.push_back(f);
      for (int k = 0; k < 3; ++k) {
        const Face& face = faces[static_cast<std::size_t>(f)];
        const auto it = edge_face.find(edge_key(face.v[(k + 1) % 3], face.v[k]));
        if (it == edge_face.end()) continue;
        const int g = it->second;
        if (is_visible[static_cast<std::size_t>(g)] || !faces[static_cast<std::size_t>(g)].alive) continue;
        if (dist(faces[static_cast<std::size_t>(g)], eye) > eps) {
          is_visible[static_cast<std::size_t>(g)] = 1;
          stack.push_back(g);
        }
      }
    }
    // Horizon: edges of visible faces whose neighbour is not visible.
    horizon_a.clear();
    horizon_b.clear();
    for (int f : visible) {
      const Face& face = faces[static_cast<std::size_t>(f)];
      for (int k = 0; k < 3; ++k) {
        const int u = face.v[k], w = face.v[(k + 1) % 3];
        const auto it = edge_face.find(edge_key(w, u));
        if (it == edge_face.end() || !is_visible[static_cast<std::size_t>(it->second)]) {
          horizon_a.push_back(u);
          horizon_b.push_back(w);
        }
      }
    }
    std::vector<int> orphans;
    for (int f : visible) {
      Face& face = faces[static_cast<std::size_t>(f)];
      face.alive = false;
      for (int k = 0; k < 3; ++k) {
        const auto it = edge_face.find(edge_key(face.v[k], face.v[(k + 1) % 3]));
        if (it != edge_face.end() && it->second == f) edge_face.erase(it);
      }
      for (int i : face.outside)
        if (i != eye) orphans.push_back(i);
      face.outside.clear();
      face.outside.shrink_to_fit();
    }
    const std::size_t first_new = faces.size();
    for (std::size_t h = 0; h < horizon_a.size(); ++h) make_face(horizon_a[h], horizon_b[h], eye);
    for (int i : orphans)
      for (std::size_t g = first_new; g < faces.size(); ++g)
        if (dist(faces[g], i) > eps) {
          faces[g].outside.push_back(i);
          break;
        }
  }

  // Collect live faces, renumber the vertices they use.
  TriangleMesh hull;
  std::vector<int> remap(static_cast<std::size_t>(n), -1);
  std::vector<int> tri;
  std::vector<double> coords;
  for (const auto& f : faces) {
    if (!f.alive) continue;
    for (int k = 0; k < 3; ++k) {
      int& r = remap[static_cast<std::size_t>(f.v[k])];
      if (r < 0) {
        r = static_cast<int>(coords.size() / 3);
        for (int j = 0; j < 3; ++j) coords.push_back(points(j, f.v[k]));
      }
      tri.push_back(r);
    }
  }
  hull.vertices = Eigen::Map<const Eigen::Matrix3Xd>(coords.data(), 3, static_cast<Index>(coords.size() / 3));
  hull.triangles = Eigen::Map<const Eigen::Matrix3Xi>(tri.data(), 3, static_cast<Index>(tri.size() / 3));
  return hull;
}

}  // namespace iclap

// SPDX-License-Identifier: MIT
#pragma once

// 3-D convex hull (quickhull), used to find the faces an object can rest on.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/error.hpp"
#include "iclap/mesh/triangle_mesh.hpp"

namespace iclap {

namespace detail {

/// The largest `normals.row(j) . points.col(i) - offsets[j]` over every point
/// i and face j (how far the point is in front of the face's plane, for unit
/// normals): dense, O(n h) for n points and h faces; -infinity when there are
/// none. The reference for worst_point_in_front (tests, benchmark).
inline double worst_point_in_front_dense(const Eigen::MatrixX3d& normals, const Eigen::VectorXd& offsets,
                                         const Eigen::Matrix3Xd& points) {
  double worst = -std::numeric_limits<double>::infinity();
  if (normals.rows() == 0) return worst;
  for (Index first = 0; first < points.cols(); first += 256) {
    const Index count = std::min<Index>(256, points.cols() - first);
    worst = std::max(worst, ((normals * points.middleCols(first, count)).colwise() - offsets).maxCoeff());
  }
  return worst;
}

/// The same decision as `worst_point_in_front_dense(...) <= tolerance`
/// (tolerance >= 0), without the dense products: the result is <= tolerance
/// exactly when the dense worst is, and when it is not, it is the dense worst
/// (the same Eigen product of the same point and face; a build that lets the
/// compiler fuse multiply-adds, e.g. -march=native, may round the two paths
/// differently in the last bits, which only a point within about 1e-16 of
/// the tolerance could notice). When it is, the result is the largest value
/// it computed, or -infinity.
///
/// The points are put in a ball tree (median splits along the longest axis,
/// leaves of at most 32 points); a face is tested against a node's points
/// only if the node's ball reaches (about) the tolerance in front of its
/// plane, so a face costs about the leaves near its plane rather than all n
/// points. At worst
/// (every ball near every plane) O(n h), typically a small fraction of it,
/// plus O(n log n) for the tree.
inline double worst_point_in_front(const Eigen::MatrixX3d& normals, const Eigen::VectorXd& offsets,
                                   const Eigen::Matrix3Xd& points, double tolerance) {
  const Index n = points.cols(), h = normals.rows();
  double worst = -std::numeric_limits<double>::infinity();
  if (n == 0 || h == 0) return worst;
  constexpr Index kLeaf = 32;
  struct Node {
    Index begin = 0, end = 0;  // its points: sorted.middleCols(begin, end - begin)
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    double radius = 0;  // max |p - centre| over its points
    Index child = -1;   // children child and child + 1; -1 for a leaf
  };
  std::vector<Index> order(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) order[static_cast<std::size_t>(i)] = i;
  std::vector<Node> nodes(1);
  nodes[0].end = n;
  double reach = 0;  // max |p| over all points
  for (Index i = 0; i < n; ++i) reach = std::max(reach, points.col(i).norm());
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const Index begin = nodes[k].begin, end = nodes[k].end;
    Eigen::Vector3d lo = points.col(order[static_cast<std::size_t>(begin)]), hi = lo;
    for (Index i = begin + 1; i < end; ++i) {
      lo = lo.cwiseMin(points.col(order[static_cast<std::size_t>(i)]));
      hi = hi.cwiseMax(points.col(order[static_cast<std::size_t>(i)]));
    }
    const Eigen::Vector3d centre = 0.5 * (lo + hi);
    double radius = 0;
    for (Index i = begin; i < end; ++i)
      radius = std::max(radius, (points.col(order[static_cast<std::size_t>(i)]) - centre).norm());
    nodes[k].centre = centre;
    nodes[k].radius = radius;
    if (end - begin <= kLeaf) continue;
    Index axis = 0;
    (hi - lo).maxCoeff(&axis);
    const Index mid = begin + (end - begin) / 2;
    const auto first = order.begin() + static_cast<std::ptrdiff_t>(begin);
    std::nth_element(first, order.begin() + static_cast<std::ptrdiff_t>(mid), order.begin() + static_cast<std::ptrdiff_t>(end),
                     [&](Index u, Index v) { return points(axis, u) < points(axis, v); });
    nodes[k].child = static_cast<Index>(nodes.size());
    Node left, right;
    left.begin = begin;
    left.end = mid;
    right.begin = mid;
    right.end = end;
    nodes.push_back(left);
    nodes.push_back(right);
  }
  Eigen::Matrix3Xd sorted(3, n);
  for (Index i = 0; i < n; ++i) sorted.col(i) = points.col(order[static_cast<std::size_t>(i)]);

  // A node's point p is in front of face (normal u, offset c) by
  // u.p - c = u.centre - c + u.(p - centre) <= u.centre - c + |u| radius.
  // The face is skipped for the node when that bound, as computed, is at
  // most limit = tolerance - 1e-12 (|u| reach + |c|). Each value computed
  // here (|u|, the radius, the bound, the limit, and a point's u.p - c in
  // the dense product) is within some tens of rounding units (2^-53) of
  // |u| reach + |c| (or of the tolerance) of its exact value, as |p| <=
  // reach, |centre| <= 2 reach, radius <= 3 reach: far below the 1e-12
  // margin. So a skipped point's u.p - c, as the dense product rounds it,
  // is at most the tolerance (a tolerance above |u| reach + |c| cannot be
  // exceeded at all): skipping never hides a point the dense check fails.
  Eigen::VectorXd norms(h), limits(h);
  for (Index j = 0; j < h; ++j) {
    norms[j] = normals.row(j).norm();
    limits[j] = tolerance - 1e-12 * (norms[j] * reach + std::abs(offsets[j]));
  }
  // Faces left to test, per tree depth (a child filters its parent's list).
  std::vector<std::vector<Index>> lists(1);
  lists[0].resize(static_cast<std::size_t>(h));
  for (Index j = 0; j < h; ++j) lists[0][static_cast<std::size_t>(j)] = j;
  Eigen::MatrixX3d near_normals(h, 3);
  Eigen::VectorXd near_offsets(h);
  Eigen::MatrixXd values(h, kLeaf);
  // Depth-first, by an explicit stack of (node, depth of its parent's list).
  std::vector<std::pair<Index, std::size_t>> stack(1, {0, 0});
  while (!stack.empty()) {
    const auto [k, depth] = stack.back();
    stack.pop_back();
    const Node& node = nodes[static_cast<std::size_t>(k)];
    if (lists.size() < depth + 2) lists.resize(depth + 2);
    std::vector<Index>& near = lists[depth + 1];
    near.clear();
    for (Index j : lists[depth])
      if (!(normals.row(j).dot(node.centre) - offsets[j] + norms[j] * node.radius <= limits[j])) near.push_back(j);
    if (near.empty()) continue;
    if (node.child >= 0) {
      // The second child is popped after the first's whole subtree, which
      // writes only deeper lists: lists[depth + 1] is still this node's.
      stack.emplace_back(node.child + 1, depth + 1);
      stack.emplace_back(node.child, depth + 1);
      continue;
    }
    const Index m = static_cast<Index>(near.size()), count = node.end - node.begin;
    for (Index r = 0; r < m; ++r) {
      near_normals.row(r) = normals.row(near[static_cast<std::size_t>(r)]);
      near_offsets[r] = offsets[near[static_cast<std::size_t>(r)]];
    }
    auto block = values.topLeftCorner(m, count);
    block.noalias() = near_normals.topRows(m) * sorted.middleCols(node.begin, count);
    block.colwise() -= near_offsets.head(m);
    worst = std::max(worst, block.maxCoeff());
  }
  return worst;
}

}  // namespace detail

/// Convex hull of a point set as a closed triangle mesh with outward normals.
/// `vertices` holds only the hull's vertices.
///
/// Quickhull (Barber, Dobkin, Huhdanpaa 1996) with a distance tolerance of
/// about 1e-12 of the point set's extent: points closer than that to a hull
/// face count as on it, so coplanar input (CAD faces) gives no slivers
/// outside the hull. A horizon face the new point is nearly coplanar with
/// is replaced too when the new face across the edge would fold over it,
/// so nearly coplanar input (CAD faces flat up to rounding noise) gives a
/// convex hull. The result is checked: every input point within 1e-6 of the
/// extent of every face (in practice within 1e-7), a closed surface;
/// if rounding broke that, the hull is recomputed with a tolerance 10 and
/// 100 times larger, then InvalidArgument naming "points" is thrown (no
/// wrong hull is returned).
/// Expected O(n log n), plus the check (detail::worst_point_in_front): a
/// ball tree over the points tests a hull triangle only against the points
/// near its plane; O(n h) at worst (h hull triangles), on the shared
/// scanned meshes 8 to 12 times less than the dense O(n h) check. Works
/// at any scale whose bounds' centre and extent are finite (up to about
/// 1e307). Throws InvalidArgument if the points are not finite, are too
/// large for that, or span no volume (fewer than 4 points, or all on one
/// plane).
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
  // Distance tolerance of the decisions; larger on a retry (below).
  double eps = 1e-12 * extent * 64;
  // How far in front of a face of the result an input point may be.
  const double tolerance = 1e-6 * extent;

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
  std::vector<int> live;
  for (int attempt = 0;; ++attempt) {
    faces.clear();
    edge_face.clear();
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
    std::vector<char> is_visible, on_hull(static_cast<std::size_t>(n), 0);
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
      // Horizon: edges of visible faces whose neighbour is not visible. A
      // neighbour the eye is nearly coplanar with (within eps, so not
      // visible) can still give a new face that folds over it: the eye within
      // eps of the edge's line (a sliver of any normal), or in the
      // neighbour's plane on its side of the edge (normal flipped). Such a
      // neighbour is made visible too, until every new face is convex to its
      // neighbour across the horizon (a point it drops is within eps of the
      // new faces; the check below makes sure).
      for (bool grown = true; grown;) {
        grown = false;
        horizon_a.clear();
        horizon_b.clear();
        for (std::size_t vi = 0; vi < visible.size(); ++vi) {
          const Face& face = faces[static_cast<std::size_t>(visible[vi])];
          for (int k = 0; k < 3; ++k) {
            const int u = face.v[k], w = face.v[(k + 1) % 3];
            const auto it = edge_face.find(edge_key(w, u));
            if (it != edge_face.end() && is_visible[static_cast<std::size_t>(it->second)]) continue;
            if (it != edge_face.end()) {
              const Face& g = faces[static_cast<std::size_t>(it->second)];
              const int o = g.v[0] != u && g.v[0] != w ? g.v[0] : g.v[1] != u && g.v[1] != w ? g.v[1] : g.v[2];
              const Eigen::Vector3d uw = pt(w) - pt(u), nn = uw.cross(pt(eye) - pt(u));
              const double len = nn.norm();
              bool sound = len > eps * uw.norm();  // eye farther than eps from the line
              if (sound) {
                const Eigen::Vector3d nrm = nn / len;
                const double d = nrm.dot(pt(o) - pt(u));
                sound = d < -eps || (d <= eps && nrm.dot(g.normal) > 0);
              }
              if (!sound) {
                is_visible[static_cast<std::size_t>(it->second)] = 1;
                visible.push_back(it->second);
                grown = true;
                continue;
              }
            }
            horizon_a.push_back(u);
            horizon_b.push_back(w);
          }
        }
      }
      // Corners of the visible faces off the horizon leave the hull: they are
      // orphans too, kept if rounding leaves them outside a new face.
      std::vector<int> orphans;
      for (std::size_t h = 0; h < horizon_a.size(); ++h) on_hull[static_cast<std::size_t>(horizon_a[h])] = 1;
      on_hull[static_cast<std::size_t>(eye)] = 1;
      for (int f : visible)
        for (int k = 0; k < 3; ++k) {
          const int v = faces[static_cast<std::size_t>(f)].v[k];
          if (!on_hull[static_cast<std::size_t>(v)]) {
            on_hull[static_cast<std::size_t>(v)] = 1;
            orphans.push_back(v);
          }
        }
      for (std::size_t h = 0; h < horizon_a.size(); ++h) on_hull[static_cast<std::size_t>(horizon_a[h])] = 0;
      on_hull[static_cast<std::size_t>(eye)] = 0;
      for (int v : orphans) on_hull[static_cast<std::size_t>(v)] = 0;
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

    // Rounding can still fold the hull where many points are nearly coplanar.
    // Check the result rather than return a hull with input points in front
    // of a face (a wrong resting face in place_on_table) or an open surface;
    // retry with coarser decisions, then refuse.
    live.clear();
    for (std::size_t f = 0; f < faces.size(); ++f)
      if (faces[f].alive) live.push_back(static_cast<int>(f));
    std::string failure = live.size() < 4 ? "left no closed hull" : "";
    for (int f : live)
      for (int k = 0; k < 3 && failure.empty(); ++k) {
        // Each directed edge in one live face, its reverse in another.
        const Face& face = faces[static_cast<std::size_t>(f)];
        const auto own = edge_face.find(edge_key(face.v[k], face.v[(k + 1) % 3]));
        const auto it = edge_face.find(edge_key(face.v[(k + 1) % 3], face.v[k]));
        if (own == edge_face.end() || own->second != f || it == edge_face.end() ||
            !faces[static_cast<std::size_t>(it->second)].alive)
          failure = "left the hull open";
      }
    Eigen::MatrixX3d normals(static_cast<Index>(live.size()), 3);
    Eigen::VectorXd offsets(static_cast<Index>(live.size()));
    for (std::size_t j = 0; j < live.size(); ++j) {
      normals.row(static_cast<Index>(j)) = faces[static_cast<std::size_t>(live[j])].normal.transpose();
      offsets[static_cast<Index>(j)] = faces[static_cast<std::size_t>(live[j])].offset;
    }
    if (failure.empty()) {
      const double worst = detail::worst_point_in_front(normals, offsets, p, tolerance);
      if (!(worst <= tolerance))
        failure = "left an input point " + format_value(worst / extent) + " of the extent in front of a hull face";
    }
    if (failure.empty()) break;
    if (attempt == 2)
      throw InvalidArgument("points", "rounding on nearly coplanar points " + failure +
                                          "; no hull is returned (snapping the points to their planes may help)");
    eps *= 10;
  }

  // Collect live faces, renumber the vertices they use.
  TriangleMesh hull;
  std::vector<int> remap(static_cast<std::size_t>(n), -1);
  std::vector<int> tri;
  std::vector<double> coords;
  for (int fi : live) {
    const Face& f = faces[static_cast<std::size_t>(fi)];
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

// SPDX-License-Identifier: MIT
#pragma once

// A bounding volume hierarchy over a triangle mesh for ray and closest-point
// queries: what the simulator needs to press a tactile pad onto a scanned or
// CAD mesh of 16k-50k triangles thousands of times per second.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iclap/core/error.hpp"
#include "iclap/mesh/triangle_mesh.hpp"

namespace iclap {

/// Which triangle sides a ray may hit.
enum class RaySide {
  any,    ///< both sides
  front,  ///< only triangles whose outward normal faces the ray (entering a closed solid)
};

/// A ray-mesh intersection.
struct RayHit {
  double t = 0;             ///< distance along the (unit) direction
  Index triangle = -1;      ///< index into the mesh's triangles
  Eigen::Vector3d normal;   ///< unit outward normal of that triangle
};

/// The point of a mesh closest to a query point.
struct ClosestPoint {
  Eigen::Vector3d point;         ///< on the surface
  Index triangle = -1;           ///< triangle it lies on
  double squared_distance = 0;   ///< from the query point
};

/// Bounding volume hierarchy (binned surface-area heuristic, leaves of at
/// most 4 triangles) over a copy of a TriangleMesh.
///
/// Build O(T log T); a ray or closest-point query visits O(log T) nodes on
/// typical meshes. Immutable after construction: const queries are
/// thread-safe, and copies share the tree (cheap).
class MeshBvh {
 public:
  /// The largest query coordinate magnitude closest_point takes: with mesh
  /// coordinates within kMaxMeshCoordinate (1e75), its dot products of
  /// offsets and edges stay below 1e153 and their products finite.
  static constexpr double kMaxQueryCoordinate = 1e77;

  /// Builds the tree; throws like validate_mesh and check_mesh_range.
  explicit MeshBvh(TriangleMesh mesh) {
    validate_mesh(mesh);
    check_mesh_range(mesh);
    auto data = std::make_shared<Data>();
    data->mesh = std::move(mesh);
    build(*data);
    data_ = std::move(data);
  }

  const TriangleMesh& mesh() const noexcept { return data_->mesh; }
  /// Bounds of the whole mesh.
  Eigen::AlignedBox3d bounds() const { return data_->nodes.front().box; }

  /// First intersection of the ray `origin + t * direction`, 0 <= t <= t_max,
  /// with the triangles (only front faces with RaySide::front). `direction`
  /// must be a unit vector. Ties go to the smaller triangle index.
  /// Throws NonFiniteValue naming "origin" or "direction" for a NaN or
  /// infinite coordinate and "t_max" for a NaN t_max, and InvalidArgument
  /// naming "direction" for a zero direction (each made every box test
  /// fail: "no hit", which the simulator read as "no contact").
  std::optional<RayHit> intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                  double t_max = std::numeric_limits<double>::infinity(),
                                  RaySide side = RaySide::any) const {
    for (Index k = 0; k < 3; ++k) {
      if (!std::isfinite(origin[k])) throw NonFiniteValue("origin", k, 0, origin[k]);
      if (!std::isfinite(direction[k])) throw NonFiniteValue("direction", k, 0, direction[k]);
    }
    if (std::isnan(t_max)) throw NonFiniteValue("t_max", 0, 0, t_max);
    if (direction.x() == 0 && direction.y() == 0 && direction.z() == 0)
      throw InvalidArgument("direction", "is zero; a unit vector is needed");
    const Data& d = *data_;
    const Eigen::Vector3d inv(1.0 / direction.x(), 1.0 / direction.y(), 1.0 / direction.z());
    double best_t = t_max;
    std::int32_t best = -1;
    std::array<std::int32_t, 64> stack;
    std::size_t top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& n = d.nodes[static_cast<std::size_t>(stack[--top])];
      if (!slab(n.box, origin, inv, best_t)) continue;
      if (n.count > 0) {
        for (std::int32_t i = n.first; i < n.first + n.count; ++i) {
          double t = 0;
          if (!hit_triangle(d.tris[static_cast<std::size_t>(i)], origin, direction, side, t)) continue;
          const std::int32_t tri = d.order[static_cast<std::size_t>(i)];
          if (best < 0 ? t <= best_t : (t < best_t || (t == best_t && tri < best))) {
            best_t = t;
            best = tri;
          }
        }
        continue;
      }
      // Visit the nearer child first.
      const std::int32_t a = n.first, b = n.first + 1;
      const double ta = entry(d.nodes[static_cast<std::size_t>(a)].box, origin, inv);
      const double tb = entry(d.nodes[static_cast<std::size_t>(b)].box, origin, inv);
      if (top + 2 > stack.size()) throw Error("MeshBvh: tree too deep");
      if (ta <= tb) {
        stack[top++] = b;
        stack[top++] = a;
      } else {
        stack[top++] = a;
        stack[top++] = b;
      }
    }
    if (best < 0) return std::nullopt;
    RayHit h;
    h.t = best_t;
    h.triangle = best;
    h.normal = d.mesh.area_normal(best).normalized();
    return h;
  }

  /// The surface point closest to `p` (ties: smaller triangle index).
  /// Throws NonFiniteValue naming "p" for a NaN or infinite coordinate and
  /// InvalidArgument naming "p" for one beyond +-kMaxQueryCoordinate, whose
  /// squared distances would overflow (no triangle would be found).
  ClosestPoint closest_point(const Eigen::Vector3d& p) const {
    for (Index k = 0; k < 3; ++k) {
      if (!std::isfinite(p[k])) throw NonFiniteValue("p", k, 0, p[k]);
      if (!(std::abs(p[k]) <= kMaxQueryCoordinate))
        throw InvalidArgument("p", "coordinate " + std::to_string(k) + " is " + format_value(p[k]) +
                                       ", beyond +-" + format_value(kMaxQueryCoordinate) +
                                       ", where squared distances overflow");
    }
    const Data& d = *data_;
    ClosestPoint best;
    best.squared_distance = std::numeric_limits<double>::infinity();
    std::array<std::pair<double, std::int32_t>, 64> stack;
    std::size_t top = 0;
    stack[top++] = {box_squared_distance(d.nodes[0].box, p), 0};
    while (top > 0) {
      const auto [dist, id] = stack[--top];
      if (dist > best.squared_distance) continue;
      const Node& n = d.nodes[static_cast<std::size_t>(id)];
      if (n.count > 0) {
        for (std::int32_t i = n.first; i < n.first + n.count; ++i) {
          const Tri& t = d.tris[static_cast<std::size_t>(i)];
          const Eigen::Vector3d q = closest_on_triangle(p, t.v0, t.v0 + t.e1, t.v0 + t.e2);
          const double s = (q - p).squaredNorm();
          const std::int32_t tri = d.order[static_cast<std::size_t>(i)];
          if (s < best.squared_distance || (s == best.squared_distance && tri < best.triangle)) {
            best.squared_distance = s;
            best.point = q;
            best.triangle = tri;
          }
        }
        continue;
      }
      const std::int32_t a = n.first, b = n.first + 1;
      const double da = box_squared_distance(d.nodes[static_cast<std::size_t>(a)].box, p);
      const double db = box_squared_distance(d.nodes[static_cast<std::size_t>(b)].box, p);
      if (top + 2 > stack.size()) throw Error("MeshBvh: tree too deep");
      if (da <= db) {
        stack[top++] = {db, b};
        stack[top++] = {da, a};
      } else {
        stack[top++] = {da, a};
        stack[top++] = {db, b};
      }
    }
    return best;
  }

  /// The point of triangle abc closest to p (Ericson, Real-Time Collision
  /// Detection, 5.1.5). A triangle without area (two corners equal, or all
  /// three on a line up to rounding: the sine of the angle at a below 6e-8)
  /// gives the closest point of its edges, the first edge of ab, bc, ca on a
  /// tie: Ericson's divisions are 0 / 0 there (corners a and b equal gave
  /// NaN, which lost every comparison, so a query answered another
  /// triangle), and his region tests cancel to noise when nearly so.
  ///
  /// Its products reach the fourth power of the triangle's size, so a
  /// triangle smaller than 2^-100 or larger than 2^100 (in its largest
  /// coordinate difference) is solved scaled by a power of two, which is
  /// exact: a triangle 1e-78 across underflowed to "no triangle found", one
  /// 1e-100 across to a point on an edge, and the scale factor of one of
  /// subnormal size overflowed. Other triangles are solved as they are, bit
  /// for bit as before. The products also reach the square of the query's
  /// distance over the triangle's size, which must stay below about 1e150.
  static Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                             const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const double size = std::max((b - a).cwiseAbs().maxCoeff(), (c - a).cwiseAbs().maxCoeff());
    if (size > 0 && (size < 0x1p-100 || size > 0x1p100)) {
      const int e = detail::unit_exponent(size);
      const Eigen::Vector3d q = closest_on_unit_triangle(detail::scale_by_power_of_two(p - a, -e),
                                                         Eigen::Vector3d::Zero(),
                                                         detail::scale_by_power_of_two(b - a, -e),
                                                         detail::scale_by_power_of_two(c - a, -e));
      return a + detail::scale_by_power_of_two(q, e);
    }
    return closest_on_unit_triangle(p, a, b, c);
  }

 private:
  /// closest_on_triangle for a triangle whose products neither overflow
  /// nor underflow.
  static Eigen::Vector3d closest_on_unit_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                                  const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
    // Nearly collinear corners count as degenerate: with sin(angle at a)
    // near 1e-16, Ericson's region tests (differences of products such as
    // d1 d4 - d3 d2, all proportional to |ab x ac|) cancel to rounding noise
    // and can pick a point as far off as the triangle's size. Below
    // sin^2 = 16 eps (sin < 6e-8) the closest point of the edges is used: it
    // is off by at most the triangle's width, < 6e-8 of its shorter edge
    // (sampled: Ericson is good to ~1e-8 of the size at sin 1e-6).
    if (ab.cross(ac).squaredNorm() <=
        16 * std::numeric_limits<double>::epsilon() * ab.squaredNorm() * ac.squaredNorm()) {
      Eigen::Vector3d best = closest_on_segment(p, a, b);
      for (const Eigen::Vector3d& q : {closest_on_segment(p, b, c), closest_on_segment(p, c, a)})
        if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
      return best;
    }
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const Eigen::Vector3d bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
    const Eigen::Vector3d cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
      return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    const double denom = 1.0 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
  }

  /// The point of segment se closest to p (s for a segment of length 0).
  static Eigen::Vector3d closest_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& s,
                                            const Eigen::Vector3d& e) {
    const Eigen::Vector3d d = e - s;
    const double length2 = d.squaredNorm();
    if (!(length2 > 0.0)) return s;
    return s + std::clamp((p - s).dot(d) / length2, 0.0, 1.0) * d;
  }

  struct Node {
    Eigen::AlignedBox3d box;
    std::int32_t first = 0;  // leaf: first triangle slot; inner: left child (right = first + 1)
    std::int32_t count = 0;  // > 0 for leaves
  };
  struct Tri {
    Eigen::Vector3d v0, e1, e2;
  };
  struct Data {
    TriangleMesh mesh;
    std::vector<Node> nodes;
    std::vector<Tri> tris;             // in leaf order
    std::vector<std::int32_t> order;   // leaf slot -> mesh triangle index
  };

  static bool slab(const Eigen::AlignedBox3d& b, const Eigen::Vector3d& o, const Eigen::Vector3d& inv,
                   double t_max) {
    double t0 = 0, t1 = t_max;
    for (int k = 0; k < 3; ++k) {
      double near = (b.min()[k] - o[k]) * inv[k], far = (b.max()[k] - o[k]) * inv[k];
      if (near > far) std::swap(near, far);
      // NaN (0 * inf on a slab boundary) compares false: keep the interval.
      if (near > t0) t0 = near;
      if (far < t1) t1 = far;
      if (t0 > t1) return false;
    }
    return true;
  }

  static double entry(const Eigen::AlignedBox3d& b, const Eigen::Vector3d& o, const Eigen::Vector3d& inv) {
    double t0 = 0;
    for (int k = 0; k < 3; ++k) {
      const double near = std::min((b.min()[k] - o[k]) * inv[k], (b.max()[k] - o[k]) * inv[k]);
      if (near > t0) t0 = near;
    }
    return t0;
  }

  static double box_squared_distance(const Eigen::AlignedBox3d& b, const Eigen::Vector3d& p) {
    double s = 0;
    for (int k = 0; k < 3; ++k) {
      const double d = std::max({b.min()[k] - p[k], 0.0, p[k] - b.max()[k]});
      s += d * d;
    }
    return s;
  }

  // Moller-Trumbore; front faces have det > 0 (the direction opposes the
  // normal e1 x e2).
  static bool hit_triangle(const Tri& tri, const Eigen::Vector3d& o, const Eigen::Vector3d& dir, RaySide side,
                           double& t) {
    const Eigen::Vector3d pvec = dir.cross(tri.e2);
    const double det = tri.e1.dot(pvec);
    if (side == RaySide::front ? !(det > 0) : det == 0) return false;
    const double inv_det = 1.0 / det;
    const Eigen::Vector3d tvec = o - tri.v0;
    const double u = tvec.dot(pvec) * inv_det;
    if (u < 0 || u > 1) return false;
    const Eigen::Vector3d qvec = tvec.cross(tri.e1);
    const double v = dir.dot(qvec) * inv_det;
    if (v < 0 || u + v > 1) return false;
    t = tri.e2.dot(qvec) * inv_det;
    return t >= 0;
  }

  static void build(Data& d) {
    const TriangleMesh& m = d.mesh;
    const std::size_t n = static_cast<std::size_t>(m.triangle_count());
    std::vector<Eigen::AlignedBox3d> boxes(n);
    std::vector<Eigen::Vector3d> centroids(n);
    for (std::size_t t = 0; t < n; ++t) {
      const Index ti = static_cast<Index>(t);
      boxes[t].setEmpty();
      for (int k = 0; k < 3; ++k) boxes[t].extend(m.corner(ti, k));
      centroids[t] = boxes[t].center();
    }
    std::vector<std::int32_t> idx(n);
    for (std::size_t t = 0; t < n; ++t) idx[t] = static_cast<std::int32_t>(t);
    d.nodes.reserve(2 * n);
    d.nodes.emplace_back();
    struct Task {
      std::size_t node, begin, end;
      int depth;
    };
    std::vector<Task> tasks = {{0, 0, n, 0}};
    constexpr int kBins = 12;
    constexpr std::size_t kLeaf = 4;
    while (!tasks.empty()) {
      const Task task = tasks.back();
      tasks.pop_back();
      Eigen::AlignedBox3d box, cbox;
      box.setEmpty();
      cbox.setEmpty();
      for (std::size_t i = task.begin; i < task.end; ++i) {
        box.extend(boxes[static_cast<std::size_t>(idx[i])]);
        cbox.extend(centroids[static_cast<std::size_t>(idx[i])]);
      }
      d.nodes[task.node].box = box;
      const std::size_t count = task.end - task.begin;
      auto make_leaf = [&] {
        d.nodes[task.node].first = static_cast<std::int32_t>(task.begin);
        d.nodes[task.node].count = static_cast<std::int32_t>(count);
      };
      if (count <= kLeaf || task.depth >= 60) {
        make_leaf();
        continue;
      }
      // Binned SAH over the longest centroid axis.
      int axis = 0;
      const Eigen::Vector3d ext = cbox.sizes();
      if (ext[1] > ext[axis]) axis = 1;
      if (ext[2] > ext[axis]) axis = 2;
      std::size_t mid = task.begin + count / 2;
      if (!(ext[axis] > 0 && std::isfinite(kBins / ext[axis]) && kBins / ext[axis] > 0)) {
        // All centroids coincide, or they span more than a double (the
        // bins' scale would be 0 and inf * 0 a NaN cast to int): split by
        // index.
      } else {
        const double lo = cbox.min()[axis], scale = kBins / ext[axis];
        auto bin_of = [&](std::int32_t t) {
          const int b = static_cast<int>((centroids[static_cast<std::size_t>(t)][axis] - lo) * scale);
          return std::clamp(b, 0, kBins - 1);
        };
        std::array<Eigen::AlignedBox3d, kBins> bin_box;
        std::array<std::size_t, kBins> bin_count{};
        for (auto& b : bin_box) b.setEmpty();
        for (std::size_t i = task.begin; i < task.end; ++i) {
          const int b = bin_of(idx[i]);
          bin_box[static_cast<std::size_t>(b)].extend(boxes[static_cast<std::size_t>(idx[i])]);
          ++bin_count[static_cast<std::size_t>(b)];
        }
        auto area = [](const Eigen::AlignedBox3d& b) {
          if (b.isEmpty()) return 0.0;
          const Eigen::Vector3d s = b.sizes();
          return s.x() * s.y() + s.y() * s.z() + s.z() * s.x();
        };
        std::array<double, kBins - 1> left_cost{};
        Eigen::AlignedBox3d acc;
        acc.setEmpty();
        std::size_t acc_n = 0;
        for (int i = 0; i < kBins - 1; ++i) {
          acc.extend(bin_box[static_cast<std::size_t>(i)]);
          acc_n += bin_count[static_cast<std::size_t>(i)];
          left_cost[static_cast<std::size_t>(i)] = area(acc) * static_cast<double>(acc_n);
        }
        acc.setEmpty();
        acc_n = 0;
        double best_cost = std::numeric_limits<double>::infinity();
        int best_split = -1;
        for (int i = kBins - 1; i > 0; --i) {
          acc.extend(bin_box[static_cast<std::size_t>(i)]);
          acc_n += bin_count[static_cast<std::size_t>(i)];
          const double cost = left_cost[static_cast<std::size_t>(i - 1)] + area(acc) * static_cast<double>(acc_n);
          if (acc_n < count && acc_n > 0 && cost < best_cost) {
            best_cost = cost;
            best_split = i;
          }
        }
        if (best_split > 0) {
          const auto it = std::partition(idx.begin() + static_cast<std::ptrdiff_t>(task.begin),
                                         idx.begin() + static_cast<std::ptrdiff_t>(task.end),
                                         [&](std::int32_t t) { return bin_of(t) < best_split; });
          mid = static_cast<std::size_t>(it - idx.begin());
        }
        if (mid == task.begin || mid == task.end) mid = task.begin + count / 2;
      }
      if (mid == task.begin + count / 2) {
        std::nth_element(idx.begin() + static_cast<std::ptrdiff_t>(task.begin),
                         idx.begin() + static_cast<std::ptrdiff_t>(mid),
                         idx.begin() + static_cast<std::ptrdiff_t>(task.end),
                         [&](std::int32_t a, std::int32_t b) {
                           const double ca = centroids[static_cast<std::size_t>(a)][axis];
                           const double cb = centroids[static_cast<std::size_t>(b)][axis];
                           return ca < cb || (ca == cb && a < b);
                         });
      }
      const std::size_t left = d.nodes.size();
      d.nodes.emplace_back();
      d.nodes.emplace_back();
      d.nodes[task.node].first = static_cast<std::int32_t>(left);
      d.nodes[task.node].count = 0;
      tasks.push_back({left, task.begin, mid, task.depth + 1});
      tasks.push_back({left + 1, mid, task.end, task.depth + 1});
    }
    d.order = idx;
    d.tris.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Index t = idx[i];
      const Eigen::Vector3d a = m.corner(t, 0);
      d.tris[i] = Tri{a, m.corner(t, 1) - a, m.corner(t, 2) - a};
    }
  }

  std::shared_ptr<const Data> data_;
};

}  // namespace iclap

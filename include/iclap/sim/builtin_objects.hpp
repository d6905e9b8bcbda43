// SPDX-License-Identifier: MIT
#pragma once

// The simulator's built-in object set: 20 tool-like objects built from
// primitives, mirroring the kinds of objects of the paper (Section V, Fig. 4):
// pairs that share local appearance but differ in extent (two fixed wrenches
// with the same heads and different lengths, three wooden cuboids, two
// screwdrivers with the same handle) and pairs of similar extent whose local
// appearance differs (two pliers with the same handles and pivot but
// different jaws). Dimensions are those of ordinary hand tools; none was
// tuned to make objects easier or harder to recognise.

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iclap/core/error.hpp"
#include "iclap/mesh/primitives.hpp"
#include "iclap/sim/objects.hpp"

namespace iclap {

namespace detail {

// Builders in millimetres (converted to metres at the end), lying on the
// table with z up.
struct ToolBuilder {
  TriangleMesh mesh;

  void add(const TriangleMesh& m) {
    if (mesh.vertex_count() == 0) mesh = m;
    else append_mesh(mesh, m);
  }
  static Eigen::Affine3d pose(const Eigen::Vector3d& at, double yaw_deg = 0) {
    Eigen::Affine3d T = Eigen::Affine3d::Identity();
    T.translate(at);
    T.rotate(Eigen::AngleAxisd(yaw_deg * kPi / 180.0, Eigen::Vector3d::UnitZ()));
    return T;
  }
  static Eigen::Affine3d along(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
    Eigen::Affine3d T = Eigen::Affine3d::Identity();
    T.translate(0.5 * (from + to));
    T.rotate(Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), (to - from).normalized()));
    return T;
  }
  void box(const Eigen::Vector3d& size, const Eigen::Vector3d& centre, double yaw_deg = 0) {
    add(transformed(make_box(size), pose(centre, yaw_deg)));
  }
  void capsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r, int segments = 16) {
    add(transformed(make_capsule(r, (b - a).norm(), segments, 4), along(a, b)));
  }
  void cylinder(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r, int segments = 24) {
    add(transformed(make_cylinder(r, (b - a).norm(), segments), along(a, b)));
  }
  // Solid of revolution along a -> b: profile (radius, distance from a).
  void lathe(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const std::vector<Eigen::Vector2d>& profile,
             int segments = 24) {
    const double len = (b - a).norm();
    Eigen::Affine3d T = along(a, b);
    T.translate(Eigen::Vector3d(0, 0, -len / 2));
    add(transformed(make_lathe(profile, segments), T));
  }
  void extrusion(const std::vector<Eigen::Vector2d>& outline, double z0, double z1,
                 const Eigen::Vector3d& at = Eigen::Vector3d::Zero(), double yaw_deg = 0) {
    add(transformed(make_extrusion(outline, z0, z1), pose(at, yaw_deg)));
  }
  // A flat ring (finger loop) of capsules around a circle at height z.
  void ring(const Eigen::Vector2d& c, double radius, double tube, double z, int pieces = 16) {
    for (int i = 0; i < pieces; ++i) {
      const double a0 = 2 * kPi * i / pieces, a1 = 2 * kPi * (i + 1) / pieces;
      capsule({c.x() + radius * std::cos(a0), c.y() + radius * std::sin(a0), z},
              {c.x() + radius * std::cos(a1), c.y() + radius * std::sin(a1), z}, tube, 12);
    }
  }
  SimObject finish(const std::string& name) {
    TriangleMesh m = mesh;
    m.vertices *= 1e-3;
    return make_sim_object(name, std::move(m), false);
  }
};

// Open jaw of a spanner: a disc of radius r with a slot of width w and depth
// d opening towards +x, centred on the origin.
inline std::vector<Eigen::Vector2d> open_jaw_outline(double r, double w, double d, int steps = 28) {
  const double a0 = std::asin(w / 2 / r);
  std::vector<Eigen::Vector2d> p = arc_points({0, 0}, r, a0, 2 * kPi - a0, steps);
  const double inner = r * std::cos(a0) - d;
  p.emplace_back(inner, -w / 2);
  p.emplace_back(inner, w / 2);
  return p;
}

inline void pliers_frame(ToolBuilder& b) {
  b.capsule({-15, 5, 6}, {-125, 20, 6}, 6);  // handles
  b.capsule({-15, -5, 6}, {-125, -20, 6}, 6);
  b.cylinder({0, 0, 0}, {0, 0, 13}, 11, 28);  // pivot
}

inline void fixed_wrench(ToolBuilder& b, double handle_length) {
  const double half = handle_length / 2;
  b.box({handle_length + 10, 11, 5}, {0, 0, 3.5});  // flat shank, 1 mm above the table
  const auto jaw = open_jaw_outline(15, 13, 14);
  b.extrusion(jaw, 0, 7, {half + 12, 0, 0}, 15);     // head, opening outwards
  b.extrusion(jaw, 0, 7, {-half - 12, 0, 0}, 195);
}

inline void screwdriver(ToolBuilder& b, double shaft_length, bool phillips) {
  // Handle along x from 0 to 95 mm, axis 14 mm above the table.
  b.lathe({0, 0, 14}, {95, 0, 14},
          {{0, 0}, {10, 0}, {13, 4}, {14, 15}, {13, 60}, {11.5, 85}, {8, 95}, {0, 95}}, 24);
  b.cylinder({95, 0, 14}, {95 + shaft_length, 0, 14}, 3, 16);
  const double tip = 95 + shaft_length;
  if (phillips) {
    b.add(transformed(make_frustum(3, 0.6, 9, 16), ToolBuilder::along({tip, 0, 14}, {tip + 9, 0, 14})
                                                        .translate(Eigen::Vector3d(0, 0, -4.5))));
    b.box({7, 1.2, 4.5}, {tip + 3.5, 0, 14});
    b.box({7, 4.5, 1.2}, {tip + 3.5, 0, 14});
  } else {
    b.box({9, 6, 1}, {tip + 4.5, 0, 14});  // flat blade
  }
}

}  // namespace detail

/// Names of the built-in objects, in the order builtin_objects() returns
/// them. Stable: they are class labels in datasets.
inline std::vector<std::string> builtin_object_names() {
  return {"pliers_1",       "pliers_2",       "fixed_wrench_1",  "fixed_wrench_2",    "scissors",
          "wooden_cuboid_1", "wooden_cuboid_2", "wooden_cuboid_3", "screwdriver_1",     "screwdriver_2",
          "c_clamp",         "spring_clamp",    "hammer",          "adjustable_wrench", "allen_key",
          "tape_measure",    "file",            "socket_wrench",   "utility_knife",     "mallet"};
}

/// The built-in object `name` (see builtin_object_names); InvalidArgument
/// for an unknown name. Deterministic; a few milliseconds.
inline SimObject builtin_object(const std::string& name) {
  using detail::ToolBuilder;
  ToolBuilder b;
  if (name == "pliers_1") {  // combination pliers: broad jaws with cross ridges
    detail::pliers_frame(b);
    b.extrusion({{5, -10}, {35, -9}, {50, -6}, {53, 0}, {50, 6}, {35, 9}, {5, 10}}, 1.5, 11.5);
    for (int i = 0; i < 6; ++i) b.box({1.5, 15, 1.2}, {16 + 5.0 * i, 0, 12});
  } else if (name == "pliers_2") {  // long-nose pliers: same frame, slender jaws
    detail::pliers_frame(b);
    b.extrusion({{5, -9}, {20, -7}, {55, -2.5}, {63, -1}, {63, 1}, {55, 2.5}, {20, 7}, {5, 9}}, 2, 10);
  } else if (name == "fixed_wrench_1") {  // 150 mm double open-end spanner
    detail::fixed_wrench(b, 95);
  } else if (name == "fixed_wrench_2") {  // 220 mm, same heads
    detail::fixed_wrench(b, 165);
  } else if (name == "scissors") {
    b.extrusion({{-8, -3}, {30, -5.5}, {95, -0.6}, {95, 0.6}, {30, 1}, {-8, 3}}, 0, 2.2, {0, 0, 0}, 4);
    b.extrusion({{-8, -3}, {30, -1}, {95, -0.6}, {95, 0.6}, {30, 5.5}, {-8, 3}}, 2.2, 4.4, {0, 0, 0}, -4);
    b.cylinder({0, 0, 0}, {0, 0, 5.5}, 4, 16);  // pivot screw
    b.capsule({-6, 3, 3.5}, {-45, 14, 3.5}, 3.5);
    b.capsule({-6, -3, 3.5}, {-45, -14, 3.5}, 3.5);
    b.ring({-56, 19}, 12, 3.5, 3.5);
    b.ring({-56, -19}, 12, 3.5, 3.5);
  } else if (name == "wooden_cuboid_1") {
    b.box({60, 40, 30}, {0, 0, 15});
  } else if (name == "wooden_cuboid_2") {
    b.box({100, 60, 30}, {0, 0, 15});
  } else if (name == "wooden_cuboid_3") {
    b.box({150, 50, 40}, {0, 0, 20});
  } else if (name == "screwdriver_1") {  // flat blade, 100 mm shaft
    detail::screwdriver(b, 100, false);
  } else if (name == "screwdriver_2") {  // Phillips, 150 mm shaft, same handle
    detail::screwdriver(b, 150, true);
  } else if (name == "c_clamp") {
    b.extrusion({{0, 0}, {70, 0}, {70, 15}, {15, 15}, {15, 85}, {70, 85}, {70, 100}, {0, 100}}, 0, 12);
    b.cylinder({60, 125, 6}, {60, 40, 6}, 5, 16);   // screw
    b.cylinder({35, 125, 6}, {85, 125, 6}, 4, 16);  // T-handle
    b.cylinder({60, 46, 6}, {60, 38, 6}, 9, 20);    // swivel pad
  } else if (name == "spring_clamp") {
    b.capsule({-75, -18, 4.5}, {0, -5, 4.5}, 4.5);
    b.capsule({0, -5, 4.5}, {45, 2, 4.5}, 4.5);
    b.capsule({-75, 18, 4.5}, {0, 5, 4.5}, 4.5);
    b.capsule({0, 5, 4.5}, {45, -2, 4.5}, 4.5);
    b.cylinder({0, 0, 0}, {0, 0, 13}, 9, 24);  // coil spring
    b.box({10, 8, 11}, {49, 5, 5.5});          // jaw pads
    b.box({10, 8, 11}, {49, -5, 5.5});
  } else if (name == "hammer") {
    b.extrusion({{-150, -11}, {110, -9}, {110, 9}, {-150, 11}}, 4, 22);                     // handle
    b.box({28, 60, 26}, {125, 15, 13});                                                       // face side
    b.extrusion({{111, -15}, {139, -15}, {133, -50}, {125, -62}, {117, -50}}, 1, 25);        // claw
    b.cylinder({125, 45, 13}, {125, 52, 13}, 12, 24);                                         // striking face
  } else if (name == "adjustable_wrench") {
    b.extrusion(arc_points({-150, 0}, 11, detail::kPi / 2, 3 * detail::kPi / 2, 12), 1, 9);
    b.extrusion({{-150, -11}, {-10, -14}, {-10, 14}, {-150, 11}}, 1, 9);
    b.extrusion(detail::open_jaw_outline(25, 20, 23, 36), 0, 12, {8, 0, 0}, 20);
    b.cylinder({-2, -16, 6}, {-2, 2, 6}, 6.5, 20);  // worm screw
  } else if (name == "allen_key") {
    b.cylinder({0, 0, 3}, {90, 0, 3}, 3, 6);
    b.cylinder({0, 0, 3}, {0, 30, 3}, 3, 6);
    b.add(transformed(make_sphere(3, 6, 4), ToolBuilder::pose({0, 0, 3})));
  } else if (name == "tape_measure") {
    std::vector<Eigen::Vector2d> rounded;
    for (int q = 0; q < 4; ++q) {
      const Eigen::Vector2d c((q == 0 || q == 3) ? 20.5 : -20.5, q < 2 ? 20.5 : -20.5);
      const auto arc = arc_points(c, 12, q * detail::kPi / 2, (q + 1) * detail::kPi / 2, 6);
      rounded.insert(rounded.end(), arc.begin(), arc.end());
    }
    b.extrusion(rounded, 0, 35);
    b.box({8, 20, 2}, {36, 0, 3});      // tape end
    b.box({2, 20, 7}, {40, 0, 4.5});    // hook
    b.box({16, 10, 4}, {10, 0, 37});    // lock button
    b.box({2, 30, 20}, {-33.5, 0, 17.5});  // belt clip
  } else if (name == "file") {
    b.extrusion({{0, -10}, {170, -7}, {195, -4}, {195, 4}, {170, 7}, {0, 10}}, 0, 5);
    for (int i = 0; i < 36; ++i) b.box({0.8, 18, 0.7}, {6 + 5.0 * i, 0, 5.3}, 30);
    b.box({45, 8, 4}, {-22, 0, 2.5});  // tang
  } else if (name == "socket_wrench") {
    b.capsule({-125, 0, 8}, {-15, 0, 8}, 8);
    b.box({30, 16, 12}, {0, 0, 7});
    b.cylinder({22, 0, 0}, {22, 0, 16}, 20, 32);   // ratchet head
    b.box({10, 10, 10}, {22, 0, 21});              // square drive
    b.box({10, 6, 3}, {5, 0, 14.5}, 20);           // selector lever
  } else if (name == "utility_knife") {
    b.extrusion({{0, -12}, {130, -10}, {150, -4}, {150, 6}, {0, 12}}, 0, 16);
    b.extrusion({{148, -4}, {172, -1}, {148, 4}}, 7.7, 8.3);
    b.box({15, 8, 4}, {60, 0, 18});
    for (int i = 0; i < 8; ++i) b.box({2, 20, 1}, {8 + 5.0 * i, 0, 16.5});
  } else if (name == "mallet") {
    b.cylinder({120, -50, 30}, {120, 50, 30}, 30, 32);
    b.cylinder({-160, 0, 30}, {95, 0, 30}, 12, 20);
  } else {
    throw InvalidArgument("name", quote_text(name, 60) + " is not a built-in object");
  }
  return b.finish(name);
}

/// The 20 built-in objects (see builtin_object_names), in metres, lying on
/// the table.
inline std::vector<SimObject> builtin_objects() {
  std::vector<SimObject> out;
  for (const auto& n : builtin_object_names()) out.push_back(builtin_object(n));
  return out;
}

}  // namespace iclap

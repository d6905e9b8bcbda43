// SPDX-License-Identifier: MIT
#pragma once

/// Nearest-neighbour search policies. All model the same interface:
///   explicit Search(Cloud points, const Settings& = {});
///   Index size() const; Index dim() const; const Cloud& points() const;
///   Neighbor<Scalar> nearest(const Scalar* query) const;   // thread-safe
/// with identical distances and the tie rule "smaller index wins", so either
/// can stand in for the other (and brute force is the kd-tree's oracle).
/// Optionally a policy also offers
///   Neighbor<Scalar> nearest(const Scalar* query, Index hint) const;
/// a warm-started query that returns exactly what nearest(query) returns;
/// `Icp` passes each test point's previous match as the hint when the policy
/// has it (`KdTreeSearch` does; brute force gains nothing from a hint).
/// `AdaptiveSearch` is brute force on small clouds and a kd-tree on the
/// others (the default of `ReferenceCloud` and of the recognition
/// classifiers). `KdTreeSearch` and `BruteForceSearch` keep their points in
/// one immutable block that copies share. `TruncatedDistanceField` is not a
/// search policy: it answers "how far, up to a cut-off" (not "which point")
/// in constant time, for the occupancy classifier.
#include "iclap/search/adaptive.hpp"
#include "iclap/search/brute_force.hpp"
#include "iclap/search/distance_field.hpp"
#include "iclap/search/kdtree.hpp"
#include "iclap/search/neighbor.hpp"

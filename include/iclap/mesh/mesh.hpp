// SPDX-License-Identifier: MIT
#pragma once

/// \file
/// Umbrella header of the mesh area: the triangle mesh type, OBJ/STL/PLY
/// loaders, convex hull, table placement, the BVH for ray and
/// closest-point queries, and surface sampling.

#include "iclap/mesh/bvh.hpp"
#include "iclap/mesh/convex_hull.hpp"
#include "iclap/mesh/load.hpp"
#include "iclap/mesh/obj.hpp"
#include "iclap/mesh/placement.hpp"
#include "iclap/mesh/ply.hpp"
#include "iclap/mesh/primitives.hpp"
#include "iclap/mesh/sampling.hpp"
#include "iclap/mesh/stl.hpp"
#include "iclap/mesh/triangle_mesh.hpp"

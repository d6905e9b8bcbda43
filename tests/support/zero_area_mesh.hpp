// SPDX-License-Identifier: MIT
#pragma once

// A mesh whose four vertices span a volume but whose four triangles each
// repeat a vertex, so none has any area: what validate_mesh must refuse.

#include "iclap/mesh/triangle_mesh.hpp"

namespace iclap::test {

inline TriangleMesh zero_area_mesh() {
  TriangleMesh m;
  m.vertices.resize(3, 4);
  m.vertices << 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
  m.triangles.resize(3, 4);
  m.triangles << 0, 1, 2, 3, 0, 1, 2, 3, 1, 2, 3, 0;
  return m;
}

}  // namespace iclap::test

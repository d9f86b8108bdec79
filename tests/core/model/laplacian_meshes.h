// Small meshes with known Laplacian weights, for the cotangent and intrinsic Delaunay tests.
#pragma once

#include <cmath>
#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/mesh_topology.h"

namespace deform::test_support {

// A flat (cells + 1)^2 grid of spacing h in the xy-plane, each square split along the diagonal
// from its lower left to its upper right corner: every triangle is right isosceles, so an axis
// edge is opposite two 45 degree angles (weight 1, or 1/2 on the boundary) and a diagonal two
// right angles (weight 0). Vertex (x, y) is y * (cells + 1) + x.
inline TriangleMesh GridMesh(int cells, double h = 0.5) {
  TriangleMesh mesh;
  const int side = cells + 1;
  mesh.vertices.resize(side * side, 3);
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) mesh.vertices.row(y * side + x) << x * h, y * h, 0;
  }
  mesh.triangles.resize(2 * cells * cells, 3);
  int t = 0;
  for (int y = 0; y < cells; ++y) {
    for (int x = 0; x < cells; ++x) {
      const int a = y * side + x, b = a + 1, c = a + side + 1, d = a + side;
      mesh.triangles.row(t++) << a, b, c;
      mesh.triangles.row(t++) << a, c, d;
    }
  }
  return mesh;
}

// Two flat triangles (a, b, c) and (b, a, d) on the long edge a-b = (0,0,0)-(2,0,0), with c and d
// at height +-0.3 above its middle: both angles opposite a-b are obtuse (146.6 degrees), so its
// cotangent weight is negative; flipped, the diagonal c-d (length 0.6) is Delaunay. With
// `consistent` false the second triangle is given as (a, b, d), against the first's orientation.
inline TriangleMesh ObtuseQuad(bool consistent = true) {
  TriangleMesh mesh;
  mesh.vertices.resize(4, 3);
  mesh.vertices << 0, 0, 0, 2, 0, 0, 1, 0.3, 0, 1, -0.3, 0;
  mesh.triangles.resize(2, 3);
  mesh.triangles << 0, 1, 2, 1, 0, 3;
  if (!consistent) mesh.triangles.row(1) << 0, 1, 3;
  return mesh;
}

// The weight vertex i's row gives vertex j (0 where j is not in the row).
template <typename Weighted>
double WeightOf(const Weighted& weights, int i, int j) {
  for (int p = weights.offsets[i]; p < weights.offsets[i + 1]; ++p) {
    if (weights.neighbors[p] == j) return weights.weights[p];
  }
  return 0;
}

}  // namespace deform::test_support

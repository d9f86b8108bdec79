// Closed triangle meshes made of unit cubes, for fixtures of any shape: the boundary faces of a
// set of filled grid cells, each split into two triangles, outward-facing. The surface is a closed
// 2-manifold when filled cells touch only face to face (never along an edge or at a corner alone).
#pragma once

#include <Eigen/Core>
#include <array>
#include <map>
#include <set>
#include <vector>

#include "core/geometry/mesh.h"

namespace deform::test_support {

using Cell = std::array<int, 3>;

// Cells [lo, hi) in each axis.
inline void AddBox(std::set<Cell>* cells, Cell lo, Cell hi) {
  for (int x = lo[0]; x < hi[0]; ++x)
    for (int y = lo[1]; y < hi[1]; ++y)
      for (int z = lo[2]; z < hi[2]; ++z) cells->insert({x, y, z});
}

// The boundary of `cells`, each cell `size` wide, the grid's origin at `origin`.
inline TriangleMesh VoxelMesh(const std::set<Cell>& cells, double size = 1.0,
                              const Eigen::Vector3d& origin = Eigen::Vector3d::Zero()) {
  std::map<Cell, int> index_of_corner;
  std::vector<Cell> corners;
  std::vector<std::array<int, 3>> triangles;
  const auto corner = [&](Cell c) {
    const auto [it, inserted] = index_of_corner.emplace(c, static_cast<int>(corners.size()));
    if (inserted) corners.push_back(c);
    return it->second;
  };
  for (const Cell& cell : cells) {
    for (int axis = 0; axis < 3; ++axis) {
      for (int sign : {-1, 1}) {
        Cell neighbour = cell;
        neighbour[axis] += sign;
        if (cells.count(neighbour)) continue;
        // The face's corners p0..p3, counter-clockwise seen from outside: with b, c the next axes
        // (e_b x e_c = e_axis), p0 -> p0 + e_b -> p0 + e_b + e_c -> p0 + e_c faces +axis.
        const int b = (axis + 1) % 3, c = (axis + 2) % 3;
        Cell p0 = cell;
        if (sign > 0) p0[axis] += 1;
        Cell p1 = p0, p2 = p0, p3 = p0;
        p1[b] += 1;
        p2[b] += 1;
        p2[c] += 1;
        p3[c] += 1;
        if (sign < 0) std::swap(p1, p3);
        const int i0 = corner(p0), i1 = corner(p1), i2 = corner(p2), i3 = corner(p3);
        triangles.push_back({i0, i1, i2});
        triangles.push_back({i0, i2, i3});
      }
    }
  }
  TriangleMesh mesh;
  mesh.vertices.resize(static_cast<int>(corners.size()), 3);
  for (int v = 0; v < static_cast<int>(corners.size()); ++v) {
    for (int a = 0; a < 3; ++a) mesh.vertices(v, a) = origin[a] + size * corners[v][a];
  }
  mesh.triangles.resize(static_cast<int>(triangles.size()), 3);
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    for (int a = 0; a < 3; ++a) mesh.triangles(t, a) = triangles[t][a];
  }
  return mesh;
}

}  // namespace deform::test_support

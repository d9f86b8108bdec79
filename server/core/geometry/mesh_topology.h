// Vertex adjacency and connected components of a triangle mesh.
#pragma once

#include <vector>

#include "core/geometry/mesh.h"

namespace deform {

// One-ring neighbours of every vertex, compressed: the neighbours of vertex i are
// neighbors[offsets[i] .. offsets[i + 1]), sorted ascending, without duplicates.
struct VertexAdjacency {
  std::vector<int> offsets;    // n + 1
  std::vector<int> neighbors;  // 2 * #edges

  int degree(int i) const { return offsets[i + 1] - offsets[i]; }
};

VertexAdjacency BuildVertexAdjacency(const Triangles& triangles, int num_vertices);

// Component label (0-based, in order of the lowest vertex) of every vertex; returns the count.
int ConnectedComponents(const VertexAdjacency& adjacency, std::vector<int>* component);

// Whether every edge is shared by two triangles (no boundary): the mesh encloses a volume.
bool IsClosed(const Triangles& triangles);

}  // namespace deform

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

// Shortest distances along the mesh's edges (Euclidean edge lengths) from the `sources` to every
// vertex: infinity where no source is connected. With `nearest_source`, also the source each vertex
// is nearest to (-1 where none). Multi-source Dijkstra, O((V + E) log V).
std::vector<double> SurfaceDistances(const Positions& vertices, const VertexAdjacency& adjacency,
                                     const std::vector<int>& sources,
                                     std::vector<int>* nearest_source = nullptr);

// Whether every edge is shared by two triangles (no boundary): the mesh encloses a volume.
bool IsClosed(const Triangles& triangles);

}  // namespace deform

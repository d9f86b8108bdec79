// Intrinsic triangulations of a triangle mesh and the flip algorithm that makes one Delaunay
// (Bobenko and Springborn, "A discrete Laplace-Beltrami operator for simplicial surfaces", 2007;
// Sharp, Soliman and Crane, "Navigating intrinsic triangulations", 2019): the surface's metric
// stays the mesh's, only the edges change. Each edge is known by its length alone; a flipped edge
// is a geodesic across the two triangles beside it, and it may join two vertices that were not
// neighbours, run parallel to another edge between the same two vertices, or start and end at one
// vertex. The triangulation is therefore a Delta-complex, addressed by corners rather than by
// vertex pairs.
#pragma once

#include <vector>

#include "core/geometry/mesh.h"

namespace deform {

// Cotangents are clamped to [-kMaxCotangent, kMaxCotangent]: an angle below about 0.06 degrees
// (or within it of 180) reads as that angle, so a sliver cannot make a weight arbitrarily large.
inline constexpr double kMaxCotangent = 1e3;

// The cotangent of a triangle's corner from the length of the opposite side and of the two sides
// at the corner, clamped as above (Kahan's area formula, exact for any valid triangle; a triangle
// that violates the triangle inequality reads as flat). Sets *clamped when the bound applied.
double CornerCotangent(double opposite, double side_b, double side_c, bool* clamped);

// Corner k of triangle t is corner 3t + k. Corner h starts the side from its vertex to the next
// corner's: edge corner_edge[h] joins corner_vertex[h] and corner_vertex[Next(h)], and is opposite
// corner Next(Next(h)). Triangles are oriented consistently across each edge where the mesh allows
// (every orientable component); an edge whose two sides run the same way (where a non-orientable
// component's orientation had to break) is never flipped.
struct IntrinsicTriangulation {
  int num_vertices = 0;
  std::vector<int> corner_vertex;  // 3 per triangle
  std::vector<int> corner_edge;    // 3 per triangle
  std::vector<double> edge_length;
  // The two corners whose sides are edge e: edge_corners[2e], edge_corners[2e + 1], the second -1
  // on the boundary.
  std::vector<int> edge_corners;
  std::vector<char> edge_flippable;  // interior and its sides run opposite ways

  static int Next(int corner) { return corner % 3 == 2 ? corner - 2 : corner + 1; }
  int num_edges() const { return static_cast<int>(edge_length.size()); }
  int num_triangles() const { return static_cast<int>(corner_vertex.size()) / 3; }
  // The cotangent of the corner opposite the side that corner h starts, clamped (CornerCotangent).
  double OppositeCotangent(int h, bool* clamped) const;
  // The cotangent weight of edge e: (cot a + cot b) / 2 over the corners opposite it (one on the
  // boundary). Adds to *clamped the number of cotangents clamped, when given.
  double CotangentWeight(int e, int* clamped = nullptr) const;
};

// The mesh's own triangulation: its edges with their Euclidean lengths. The mesh must pass
// ValidateMesh (no edge in more than two triangles).
IntrinsicTriangulation TriangulationOfMesh(const TriangleMesh& mesh);

// Flips edges until every flippable edge is locally Delaunay (the two angles opposite it sum to at
// most 180 degrees, i.e. its cotangent weight is non-negative to within kDelaunayTolerance): a
// queue of the edges that may be non-Delaunay, the two triangles of a flipped edge re-queueing
// their other edges. Bobenko and Springborn prove that this ends; `max_flips` (default: 100 per
// edge) guards against rounding keeping it going. Returns the number of flips made.
inline constexpr double kDelaunayTolerance = 1e-10;
int FlipToDelaunay(IntrinsicTriangulation* triangulation, int max_flips = -1);

}  // namespace deform

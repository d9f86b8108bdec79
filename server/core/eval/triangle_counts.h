// Per-frame counts of broken triangles in a deformed skin: inverted ones and intersecting pairs
// (the quality report's inverted_triangles and self_intersections).
#pragma once

#include "core/geometry/mesh.h"

namespace deform {

// The triangles of `triangles` that a deformation turned over or crushed: those whose posed normal
// (the cross product of two edges) has a negative dot product with the same triangle's normal in
// `reference` (linear blend skinning of the same pose: the skin's orientation that follows the
// bones), or whose posed area is below 1e-12 of its area in `rest`. LBS itself (posed ==
// reference) counts only the crushed ones. All three position sets index the same vertices.
int CountInvertedTriangles(const Triangles& triangles, const Positions& rest,
                           const Positions& posed, const Positions& reference);

// The unordered pairs of triangles that share no corner and intersect in `posed`, found with a
// bounding-volume tree of the posed triangles (TriangleBvh::CountIntersectingTrianglePairs: a
// segment-triangle test on each of the six edges; contacts without crossing and coplanar overlaps
// are not counted). A closed surface that does not pass through itself counts 0.
int CountSelfIntersections(const Triangles& triangles, const Positions& posed);

}  // namespace deform

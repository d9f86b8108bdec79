// Binding through the body: which bone each vertex follows when the rig gives no weights.
//
// A vertex is bound to the nearest bone it can reach through the body: the segment from the
// vertex to the bone's closest point must not cross the surface (the mesh's own triangles at the
// vertex excepted). Vertices that see no bone that way (thin flaps such as ears, whose every
// segment leaves and re-enters the skin) take the bone of the nearest bound vertex along the
// surface (shortest path over mesh edges). Only a connected piece of the mesh in which no vertex
// sees any bone falls back to the straight-line nearest bone. A vertex whose closest point on the
// bone it sees is that bone's head (it lies behind the joint, on the parent's side) follows the
// parent bone instead where it sees the parent through the body, at most twice as far (a flank
// above a hip whose thigh hangs from a pelvis segment some way off belongs to the pelvis).
// Straight-line nearest alone would bind an ear lying beside a hand to the hand bones, a finger to
// its neighbour's bone.
#pragma once

#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/mesh_topology.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/skeleton_geometry.h"
#include "core/geometry/triangle_bvh.h"

namespace deform {

struct BodyBinding {
  // Per vertex: the bone it follows, the parameter of its closest point on that bone and the
  // distance to it (the same fields as NearestBone, so joint regions can use either).
  std::vector<NearestBone> bones;
  int seen_through_body = 0;      // vertices bound by an unobstructed segment
  int reached_along_surface = 0;  // vertices bound through the nearest bound vertex
  int straight_line = 0;          // vertices of pieces in which no vertex saw a bone
  int candidates_tested = 0;      // segment queries made, for the report
};

// `bvh` must be built over `mesh`. Tests each vertex's `max_candidates` nearest bones, nearest
// first. Deterministic; O(V (K + c log F)) for K bones and c candidates tested per vertex.
BodyBinding BindThroughBody(const TriangleMesh& mesh, const Skeleton& skeleton,
                            const VertexAdjacency& adjacency, const TriangleBvh& bvh,
                            int max_candidates = 8, double distance_ratio = 1.0);

}  // namespace deform

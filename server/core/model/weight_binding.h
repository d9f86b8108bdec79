// The binding a rig's own skinning weights give (used instead of binding through the body when a
// client supplies weights): the weights are the rotation field; a vertex that follows one bone
// alone (weight 1) is in that bone's rigid zone; a vertex that blends bones joins the region of a
// joint between them.
#pragma once

#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/mesh_topology.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/skin_weights.h"
#include "core/model/joint_regions.h"

namespace deform {

struct WeightBinding {
  std::vector<int> rigid_bone;      // per vertex: the bone it follows alone, or -1 (it blends)
  std::vector<int> region_joint;    // per blending vertex: the inner joint whose region it joins,
                                    // or -1 when no inner joint lies between its bones
  std::vector<int> main_bone;       // per vertex: its largest weight's bone
  std::vector<double> main_weight;  // per vertex: its largest weight
};

// `weights` must be normalized for this mesh and skeleton (NormalizeSkinWeights). A vertex is
// rigid when one bone carries at least 1 - rigid_tolerance of its weight. A blending
// vertex's region: of the inner joints on the skeleton path between its two largest weights' bones
// (the joint they share when they meet), the one nearest to the vertex.
WeightBinding BindFromWeights(const TriangleMesh& mesh, const Skeleton& skeleton,
                              const SkinWeights& weights, double rigid_tolerance);

// Anchors the connected pieces of the mesh that hold no rigid vertex (a strap, a buckle, an eye
// weighted to several bones everywhere): in such a piece, the tolerance applies relative to its
// best vertex, the one with the largest main_weight: the vertices on that vertex's bone whose
// weight on it is within rigid_tolerance of the best's become rigid on it. Pieces with a rigid
// vertex are unchanged. Returns the number of pieces so anchored.
int AnchorPiecesWithoutRigidVertex(const VertexAdjacency& adjacency, double rigid_tolerance,
                                   WeightBinding* binding);

// The joint regions of a weight binding: region c holds the vertices whose region_joint is c's
// joint (one region per inner joint, in Skeleton::InnerJoints() order, possibly empty). Its radius
// is the largest distance of those vertices from the joint centre, its limb radius the median; the
// per-vertex relative distances and nearest regions are measured with those radii.
JointRegions RegionsFromWeightBinding(const TriangleMesh& mesh, const Skeleton& skeleton,
                                      const VertexAdjacency& adjacency,
                                      const WeightBinding& binding);

}  // namespace deform

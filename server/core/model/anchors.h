// Anchors: rigid-zone vertices whose rows pin them to their bone's rigid motion (METHOD.md), so
// that every rigid zone follows its bone and the joint regions between them deform.
#pragma once

#include <vector>

#include "core/geometry/mesh_topology.h"
#include "core/model/joint_regions.h"

namespace deform {

// The connected piece of bone rigid_bone[start]'s rigid zone that holds `start` (vertices reached
// through neighbours with the same rigid bone), marking them in `seen` (sized to the mesh).
std::vector<int> RigidPiece(const VertexAdjacency& adjacency, const std::vector<int>& rigid_bone,
                            int start, std::vector<char>* seen);

// In every connected piece of every bone's rigid zone (`rigid_bone[i]` = the bone vertex i follows
// alone, -1 for blending vertices): the vertices at least `distance_factor` region radii from every
// joint centre (JointRegions::relative_distance); where fewer than `min_fraction` of the piece's
// vertices qualify, the piece's min_fraction farthest from the joints instead (at least one), so
// that each zone gets anchors in proportion to its size however close its joints are. Sorted.
std::vector<int> ChooseAnchors(const VertexAdjacency& adjacency, const std::vector<int>& rigid_bone,
                               const JointRegions& regions, double distance_factor,
                               double min_fraction);

}  // namespace deform

// What a model's binding turned out to be, and what looks wrong with it: per bone, how many
// vertices follow it and into how many connected pieces its rigid zone falls; warnings for the
// signatures of a bad rig (a rigid zone in pieces far apart, a joint outside the mesh or far from
// it, vertices bound farther from their bone than the limb is thick). Clearly impossible input is
// refused by CheckSkeletonAgainstMesh before anything is built.
#pragma once

#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/geometry/mesh_topology.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/skeleton_geometry.h"
#include "core/geometry/triangle_bvh.h"

namespace deform {

struct BoneBinding {
  int bone = -1;
  std::string name;           // "head->tail", the joints' names
  int vertices = 0;           // vertices bound to the bone (rigid zone and joint regions)
  int rigid_vertices = 0;     // vertices that follow it alone
  std::vector<int> pieces;    // sizes of its rigid zone's connected pieces, largest first
  double farthest_piece = 0;  // distance from the largest piece to the farthest other piece
  int anchors = 0;
  double thickness = 0;      // twice the median distance of its vertices from the bone
  int beyond_thickness = 0;  // vertices bound farther from the bone than 2 * thickness
};

struct BindingReport {
  std::string source;  // "through the body" or "given weights"
  int seen_through_body = 0;
  int reached_along_surface = 0;
  int straight_line = 0;
  std::vector<BoneBinding> bones;
  std::vector<std::string> joints_outside;  // names of joints outside a closed mesh
  std::vector<std::string> warnings;        // human-readable, one line each
};

// INVALID_ARGUMENT for a skeleton that cannot belong to the mesh: a joint farther from the mesh's
// surface than its bounding-box diagonal (names the joint and the distance), or no joint within
// the mesh's bounding box (grown by 1% of its diagonal).
Status CheckSkeletonAgainstMesh(const TriangleMesh& mesh, const Skeleton& skeleton,
                                const TriangleBvh& bvh);

// Builds the report. `bound_bone[i]` is the bone vertex i follows (its rigid bone, or its largest
// weight), `rigid_bone[i]` that bone when it follows it alone and -1 otherwise; `anchors` are the
// anchor vertices. `closed` tells whether the mesh has no boundary edge (inside tests mean
// something only then).
BindingReport ReportBinding(const TriangleMesh& mesh, const Skeleton& skeleton,
                            const VertexAdjacency& adjacency, const TriangleBvh& bvh,
                            const std::vector<int>& bound_bone, const std::vector<int>& rigid_bone,
                            const std::vector<int>& anchors, bool closed);

}  // namespace deform

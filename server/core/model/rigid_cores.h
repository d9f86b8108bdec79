// Every bone keeps a rigid core, and blends stay near their joints.
//
// Joint regions are measured from the limb's radius; where bones are short against the body's
// thickness (a spine, a neck, a pelvis) neighbouring regions cover a bone's whole length, the bone
// has no rigid zone, nothing anchors it, and the harmonic weights of distant bones flow across it
// (bending a hip moved the shared body's upper back: docs/method.md, "Joint regions"). These two
// rules keep each bone's part of the mesh its own.
#pragma once

#include <vector>

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/geometry/mesh_topology.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/skeleton_geometry.h"
#include "core/model/joint_regions.h"

namespace deform {

// `regions` with, for every bone whose vertices (by `nearest`) lie less than `min_fraction` outside
// every region, its vertices farthest from the region centres (by relative distance) taken out of
// all regions until that fraction is rigid. Bones with no vertex are left alone. Regions of
// limbs, whose rigid zones are already larger, are unchanged.
JointRegions KeepRigidCores(const TriangleMesh& mesh, const VertexAdjacency& adjacency,
                            const std::vector<NearestBone>& nearest, JointRegions regions,
                            double min_fraction);

// Per vertex, the bones its blend may use: for a vertex in joint regions, the bones that touch
// those regions' joints (its own bone, by `nearest`, first); for a rigid vertex, its own bone.
std::vector<std::vector<int>> RegionBonesPerVertex(const JointRegions& regions,
                                                   const Skeleton& skeleton,
                                                   const std::vector<NearestBone>& nearest);

// Takes `vertices` (ModelOptions::unanchored_vertices) out of the rigid zones `rigid_bones` (per
// vertex its bone, or -1), keeping at least `min_fraction` of each bone's zone: where more of a
// zone is listed, its listed vertices farthest from the joints (largest `relative_distance`) stay.
// Returns how many vertices left a zone; INVALID_ARGUMENT naming an index outside the mesh.
StatusOr<int> ReleaseFromRigidZones(const std::vector<int>& vertices,
                                    const std::vector<double>& relative_distance,
                                    double min_fraction, std::vector<int>* rigid_bones);

}  // namespace deform

// Joint regions: the vertices around each inner joint (knee, ankle...) that get joined to that
// joint's centre node and the soft material of the joint.
#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/geometry/mesh_topology.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/skeleton_geometry.h"

namespace deform {

struct JointRegionOptions {
  // Region radius r_c = radius_factor * limb radius at the joint. Default: 1.5.
  double radius_factor = 1.5;
  // Explicit radii (model units) for some joints, by joint index; they override the factor.
  std::vector<std::pair<int, double>> explicit_radius;
};

struct JointRegion {
  int joint = -1;
  Eigen::Vector3d centre;     // the joint's rest position o_c
  double limb_radius = 0;     // median centre-to-skin distance of the limb's cross-section there
  double radius = 0;          // r_c
  std::vector<int> vertices;  // P_c: within r_c of the centre and nearest to a bone of c
  std::vector<int> seam_vertices;  // the vertices of P_c with a one-ring neighbour outside P_c
};

struct JointRegions {
  std::vector<JointRegion> regions;  // one per inner joint, in Skeleton::InnerJoints() order
  // Per vertex: min over regions of |v - o_c| / r_c (infinity when there is no region) and the
  // region attaining it (-1 when there is none).
  std::vector<double> relative_distance;
  std::vector<int> nearest_region;
  // Per vertex: the regions whose P_c contains it (compressed like VertexAdjacency).
  std::vector<int> membership_offsets;
  std::vector<int> membership;
};

// The index into regions.regions of `joint`'s region, or -1 when it has none (only inner joints
// have one; any int is accepted).
int FindJointRegion(const JointRegions& regions, int joint);
// The same as a status: INVALID_ARGUMENT "joint 'hip' has no joint region (only inner joints have
// one)" when there is none, naming the joint from `skeleton` (the regions' own) where it exists.
StatusOr<int> RegionOfJoint(const JointRegions& regions, const Skeleton& skeleton, int joint);

// The limb radius at a joint is measured on the vertices whose closest skeleton point lies within
// a band around the joint (10% of the shortest adjacent bone, widened until it holds 8 vertices).
// INVALID_ARGUMENT for a non-positive or non-finite explicit radius or an unknown joint.
StatusOr<JointRegions> ComputeJointRegions(const TriangleMesh& mesh, const Skeleton& skeleton,
                                           const VertexAdjacency& adjacency,
                                           const std::vector<NearestBone>& nearest,
                                           const JointRegionOptions& options);

// The per-vertex parts of JointRegions for regions whose joint, centre, radii and vertices are
// set: relative distances and nearest regions (by each region's radius), seam vertices (a
// neighbour outside the region) and memberships. Regions are numbered in the order given.
JointRegions AssembleJointRegions(const TriangleMesh& mesh, const VertexAdjacency& adjacency,
                                  std::vector<JointRegion> regions);

}  // namespace deform

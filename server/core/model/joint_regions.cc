#include "core/model/joint_regions.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/base/median.h"

namespace deform {
namespace {

// The bone ends at the joint, starts there, or carries it (an explicit parent whose tail lies
// elsewhere: Skeleton::IncomingBone).
bool BoneTouchesJoint(const Skeleton& skeleton, int bone, int joint) {
  return skeleton.bone(bone).head_joint == joint || skeleton.bone(bone).tail_joint == joint ||
         skeleton.IncomingBone(joint) == bone;
}

double ShortestAdjacentBone(const Skeleton& skeleton, int joint) {
  double shortest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < skeleton.num_bones(); ++k) {
    if (!BoneTouchesJoint(skeleton, k, joint)) continue;
    const Bone& b = skeleton.bone(k);
    shortest = std::min(shortest, (skeleton.joint(b.tail_joint).rest_position -
                                   skeleton.joint(b.head_joint).rest_position)
                                      .norm());
  }
  return shortest;
}

// Median distance from the joint centre to the vertices whose closest skeleton point is within a
// band around the joint; the band widens until enough vertices fall in it.
double LimbRadius(const TriangleMesh& mesh, const Skeleton& skeleton,
                  const std::vector<NearestBone>& nearest, int joint) {
  const Eigen::Vector3d centre = skeleton.joint(joint).rest_position;
  const double shortest = ShortestAdjacentBone(skeleton, joint);
  constexpr int kMinimumSamples = 8;
  std::vector<double> distances;
  for (double band = 0.1 * shortest; band <= 2 * shortest; band *= 2) {
    distances.clear();
    for (int i = 0; i < mesh.num_vertices(); ++i) {
      const NearestBone& nb = nearest[i];
      if (!BoneTouchesJoint(skeleton, nb.bone, joint)) continue;
      const Bone& b = skeleton.bone(nb.bone);
      const Eigen::Vector3d a = skeleton.joint(b.head_joint).rest_position;
      const Eigen::Vector3d closest =
          a + nb.parameter * (skeleton.joint(b.tail_joint).rest_position - a);
      if ((closest - centre).norm() <= band) {
        distances.push_back((mesh.vertices.row(i).transpose() - centre).norm());
      }
    }
    if (static_cast<int>(distances.size()) >= kMinimumSamples) break;
  }
  return Median(distances);
}

// The checks of `options`: explicit radii for inner joints only, positive and finite, and a
// positive, finite radius factor.
Status CheckRegionOptions(const Skeleton& skeleton, const std::vector<int>& inner,
                          const JointRegionOptions& options) {
  for (const auto& [joint, radius] : options.explicit_radius) {
    if (joint < 0 || joint >= skeleton.num_joints()) {
      return Status::InvalidArgument("joint region radius given for unknown joint " +
                                     std::to_string(joint));
    }
    if (std::find(inner.begin(), inner.end(), joint) == inner.end()) {
      return Status::InvalidArgument("joint '" + skeleton.joint(joint).name +
                                     "' is not an inner joint, so it has no region");
    }
    if (!std::isfinite(radius) || radius <= 0) {
      return Status::InvalidArgument("joint region radius of '" + skeleton.joint(joint).name +
                                     "' must be positive and finite");
    }
  }
  if (!std::isfinite(options.radius_factor) || options.radius_factor <= 0) {
    return Status::InvalidArgument("joint region radius factor must be positive and finite");
  }
  return Status::Ok();
}

// Joint `joint`'s region without its vertices: centre, limb radius and radius (an explicit one, or
// the factor times the limb radius).
JointRegion MeasureRegion(const TriangleMesh& mesh, const Skeleton& skeleton,
                          const std::vector<NearestBone>& nearest, int joint,
                          const JointRegionOptions& options) {
  JointRegion region;
  region.joint = joint;
  region.centre = skeleton.joint(joint).rest_position;
  region.limb_radius = LimbRadius(mesh, skeleton, nearest, joint);
  region.radius = options.radius_factor * region.limb_radius;
  for (const auto& [j, radius] : options.explicit_radius) {
    if (j == joint) region.radius = radius;
  }
  return region;
}

// Joint region `region`'s vertices: within its radius and bound to one of its joint's bones.
std::vector<int> RegionVertices(const TriangleMesh& mesh, const Skeleton& skeleton,
                                const std::vector<NearestBone>& nearest,
                                const JointRegion& region) {
  std::vector<int> vertices;
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    const double d = (mesh.vertices.row(i).transpose() - region.centre).norm();
    if (d <= region.radius && BoneTouchesJoint(skeleton, nearest[i].bone, region.joint)) {
      vertices.push_back(i);
    }
  }
  return vertices;
}

// The vertices of region `index` with a one-ring neighbour outside it.
std::vector<int> SeamVertices(const VertexAdjacency& adjacency, const std::vector<int>& vertices,
                              const std::vector<std::vector<int>>& memberships, int index) {
  std::vector<int> seam;
  for (int i : vertices) {
    for (int p = adjacency.offsets[i]; p < adjacency.offsets[i + 1]; ++p) {
      const auto& m = memberships[adjacency.neighbors[p]];
      if (std::find(m.begin(), m.end(), index) == m.end()) {
        seam.push_back(i);
        break;
      }
    }
  }
  return seam;
}

}  // namespace

int FindJointRegion(const JointRegions& regions, int joint) {
  for (int r = 0; r < static_cast<int>(regions.regions.size()); ++r) {
    if (regions.regions[r].joint == joint) return r;
  }
  return -1;
}

StatusOr<int> RegionOfJoint(const JointRegions& regions, const Skeleton& skeleton, int joint) {
  const int region = FindJointRegion(regions, joint);
  if (region >= 0) return region;
  const std::string name = joint >= 0 && joint < skeleton.num_joints()
                               ? "'" + skeleton.joint(joint).name + "'"
                               : std::to_string(joint);
  return Status::InvalidArgument("joint " + name +
                                 " has no joint region (only inner joints have one)");
}

StatusOr<JointRegions> ComputeJointRegions(const TriangleMesh& mesh, const Skeleton& skeleton,
                                           const VertexAdjacency& adjacency,
                                           const std::vector<NearestBone>& nearest,
                                           const JointRegionOptions& options) {
  const std::vector<int> inner = skeleton.InnerJoints();
  DEFORM_RETURN_IF_ERROR(CheckRegionOptions(skeleton, inner, options));
  std::vector<JointRegion> regions;
  for (int joint : inner) {
    JointRegion region = MeasureRegion(mesh, skeleton, nearest, joint, options);
    region.vertices = RegionVertices(mesh, skeleton, nearest, region);
    regions.push_back(std::move(region));
  }
  return AssembleJointRegions(mesh, adjacency, std::move(regions));
}

JointRegions AssembleJointRegions(const TriangleMesh& mesh, const VertexAdjacency& adjacency,
                                  std::vector<JointRegion> regions) {
  const int n = mesh.num_vertices();
  JointRegions result;
  result.relative_distance.assign(n, std::numeric_limits<double>::infinity());
  result.nearest_region.assign(n, -1);
  std::vector<std::vector<int>> memberships(n);
  for (int index = 0; index < static_cast<int>(regions.size()); ++index) {
    const JointRegion& region = regions[index];
    for (int i = 0; i < n; ++i) {
      const double d = (mesh.vertices.row(i).transpose() - region.centre).norm();
      if (region.radius > 0 && d / region.radius < result.relative_distance[i]) {
        result.relative_distance[i] = d / region.radius;
        result.nearest_region[i] = index;
      }
    }
    for (int i : region.vertices) memberships[i].push_back(index);
  }
  for (int index = 0; index < static_cast<int>(regions.size()); ++index) {
    regions[index].seam_vertices =
        SeamVertices(adjacency, regions[index].vertices, memberships, index);
  }
  result.regions = std::move(regions);
  result.membership_offsets.assign(n + 1, 0);
  for (int i = 0; i < n; ++i) {
    result.membership_offsets[i + 1] =
        result.membership_offsets[i] + static_cast<int>(memberships[i].size());
    result.membership.insert(result.membership.end(), memberships[i].begin(), memberships[i].end());
  }
  return result;
}

}  // namespace deform

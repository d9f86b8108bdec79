#include "core/model/rigid_cores.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace deform {

JointRegions KeepRigidCores(const TriangleMesh& mesh, const VertexAdjacency& adjacency,
                            const std::vector<NearestBone>& nearest, JointRegions regions,
                            double min_fraction) {
  const int n = mesh.num_vertices();
  int num_bones = 0;
  for (const NearestBone& b : nearest) num_bones = std::max(num_bones, b.bone + 1);
  // Per bone, its vertices inside some region, farthest (relative to the radii) first.
  std::vector<int> bound(num_bones, 0), rigid(num_bones, 0);
  std::vector<std::vector<std::pair<double, int>>> in_regions(num_bones);
  for (int i = 0; i < n; ++i) {
    const int bone = nearest[i].bone;
    ++bound[bone];
    if (regions.membership_offsets[i] == regions.membership_offsets[i + 1]) {
      ++rigid[bone];
    } else {
      in_regions[bone].emplace_back(regions.relative_distance[i], i);
    }
  }
  std::vector<char> release(n, 0);
  bool any = false;
  for (int bone = 0; bone < num_bones; ++bone) {
    const int wanted = static_cast<int>(std::ceil(min_fraction * bound[bone]));
    if (rigid[bone] >= wanted) continue;
    auto& candidates = in_regions[bone];
    std::sort(candidates.begin(), candidates.end(), std::greater<>());
    const int count = std::min<int>(wanted - rigid[bone], static_cast<int>(candidates.size()));
    for (int c = 0; c < count; ++c) release[candidates[c].second] = 1;
    any = any || count > 0;
  }
  if (!any) return regions;
  for (JointRegion& region : regions.regions) {
    region.vertices.erase(std::remove_if(region.vertices.begin(), region.vertices.end(),
                                         [&](int i) { return release[i] != 0; }),
                          region.vertices.end());
  }
  return AssembleJointRegions(mesh, adjacency, std::move(regions.regions));
}

std::vector<std::vector<int>> RegionBonesPerVertex(const JointRegions& regions,
                                                   const Skeleton& skeleton,
                                                   const std::vector<NearestBone>& nearest) {
  const int n = static_cast<int>(nearest.size());
  std::vector<std::vector<int>> bones_of_joint(skeleton.num_joints());
  for (int k = 0; k < skeleton.num_bones(); ++k) {
    bones_of_joint[skeleton.bone(k).head_joint].push_back(k);
    bones_of_joint[skeleton.bone(k).tail_joint].push_back(k);
  }
  for (int j = 0; j < skeleton.num_joints(); ++j) {  // an explicit parent carrying the joint
    const int carrier = skeleton.IncomingBone(j);
    if (carrier >= 0 && skeleton.bone(carrier).tail_joint != j)
      bones_of_joint[j].push_back(carrier);
  }
  std::vector<std::vector<int>> allowed(n);
  for (int i = 0; i < n; ++i) {
    std::vector<int>& bones = allowed[i];
    bones.push_back(nearest[i].bone);
    for (int p = regions.membership_offsets[i]; p < regions.membership_offsets[i + 1]; ++p) {
      for (int k : bones_of_joint[regions.regions[regions.membership[p]].joint]) {
        if (std::find(bones.begin(), bones.end(), k) == bones.end()) bones.push_back(k);
      }
    }
  }
  return allowed;
}

}  // namespace deform

#include "core/model/rigid_cores.h"

#include <algorithm>
#include <cmath>
#include <string>
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

StatusOr<int> ReleaseFromRigidZones(const std::vector<int>& vertices,
                                    const std::vector<double>& relative_distance,
                                    double min_fraction, std::vector<int>* rigid_bones) {
  const int n = static_cast<int>(rigid_bones->size());
  int bones = 0;
  for (int i = 0; i < n; ++i) bones = std::max(bones, (*rigid_bones)[i] + 1);
  std::vector<int> zone_size(bones, 0);
  for (int i = 0; i < n; ++i) {
    if ((*rigid_bones)[i] >= 0) ++zone_size[(*rigid_bones)[i]];
  }
  std::vector<std::vector<int>> listed(bones);
  std::vector<char> seen(n, 0);
  for (const int i : vertices) {
    if (i < 0 || i >= n) {
      return Status::InvalidArgument("unanchored_vertices: vertex " + std::to_string(i) +
                                     " is not a vertex of the " + std::to_string(n) +
                                     "-vertex mesh");
    }
    if (seen[i] != 0 || (*rigid_bones)[i] < 0) continue;
    seen[i] = 1;
    listed[(*rigid_bones)[i]].push_back(i);
  }
  int released = 0;
  for (int k = 0; k < bones; ++k) {
    std::vector<int>& zone = listed[k];
    const auto keep = static_cast<std::size_t>(std::ceil(min_fraction * zone_size[k]));
    const std::size_t may_go =
        static_cast<std::size_t>(zone_size[k]) - std::min<std::size_t>(keep, zone_size[k]);
    if (zone.size() > may_go) {  // the nearest to the joints go
      std::sort(zone.begin(), zone.end(), [&](int a, int b) {
        return relative_distance[a] < relative_distance[b] ||
               (relative_distance[a] == relative_distance[b] && a < b);
      });
      zone.resize(may_go);
    }
    for (const int i : zone) (*rigid_bones)[i] = -1;
    released += static_cast<int>(zone.size());
  }
  return released;
}

}  // namespace deform

#include "core/model/weight_binding.h"

#include <algorithm>
#include <limits>

namespace deform {
namespace {

// Bone `bone` and its ancestors, nearest first.
std::vector<int> BoneChain(const Skeleton& skeleton, int bone) {
  std::vector<int> chain;
  for (int k = bone; k >= 0; k = skeleton.bone(k).parent_bone) chain.push_back(k);
  return chain;
}

// The joints a path from bone a to bone b passes: the heads of the bones on each side below their
// lowest common ancestor (for bones in different trees, every head on both chains).
std::vector<int> JointsBetween(const Skeleton& skeleton, int a, int b) {
  const std::vector<int> chain_a = BoneChain(skeleton, a);
  const std::vector<int> chain_b = BoneChain(skeleton, b);
  std::vector<int> joints;
  for (const auto* chain : {&chain_a, &chain_b}) {
    const std::vector<int>& other = chain == &chain_a ? chain_b : chain_a;
    for (int k : *chain) {
      if (std::find(other.begin(), other.end(), k) != other.end()) break;  // common ancestor
      joints.push_back(skeleton.bone(k).head_joint);
    }
  }
  return joints;
}

int NearestInnerJoint(const Skeleton& skeleton, const std::vector<char>& inner,
                      const std::vector<int>& joints, const Eigen::Vector3d& p) {
  int best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (int j : joints) {
    if (!inner[j]) continue;
    const double d = (skeleton.joint(j).rest_position - p).norm();
    if (d < best_distance) {
      best_distance = d;
      best = j;
    }
  }
  return best;
}

}  // namespace

WeightBinding BindFromWeights(const TriangleMesh& mesh, const Skeleton& skeleton,
                              const SkinWeights& weights, double rigid_tolerance) {
  const int n = mesh.num_vertices();
  std::vector<char> inner(skeleton.num_joints(), 0);
  for (int j : skeleton.InnerJoints()) inner[j] = 1;
  WeightBinding result;
  result.rigid_bone.assign(n, -1);
  result.region_joint.assign(n, -1);
  result.main_bone.assign(n, -1);
  result.main_weight.assign(n, 0);
  for (int i = 0; i < n; ++i) {
    int first = -1, second = -1;
    double first_weight = -1, second_weight = -1;
    for (int e = weights.offsets[i]; e < weights.offsets[i + 1]; ++e) {
      const double w = weights.weights[e];
      if (w > first_weight) {
        second = first;
        second_weight = first_weight;
        first = weights.bones[e];
        first_weight = w;
      } else if (w > second_weight) {
        second = weights.bones[e];
        second_weight = w;
      }
    }
    result.main_bone[i] = first;
    result.main_weight[i] = first_weight;
    if (first_weight >= 1 - rigid_tolerance || second < 0) {
      result.rigid_bone[i] = first;
      continue;
    }
    result.region_joint[i] = NearestInnerJoint(
        skeleton, inner, JointsBetween(skeleton, first, second), mesh.vertices.row(i).transpose());
  }
  return result;
}

int AnchorPiecesWithoutRigidVertex(const VertexAdjacency& adjacency, double rigid_tolerance,
                                   WeightBinding* binding) {
  std::vector<int> component;
  const int count = ConnectedComponents(adjacency, &component);
  std::vector<char> has_rigid(count, 0);
  std::vector<int> best(count, -1);
  for (std::size_t i = 0; i < component.size(); ++i) {
    const int c = component[i];
    if (binding->rigid_bone[i] >= 0) has_rigid[c] = 1;
    if (best[c] < 0 || binding->main_weight[i] > binding->main_weight[best[c]]) {
      best[c] = static_cast<int>(i);
    }
  }
  int anchored = 0;
  for (int c = 0; c < count; ++c) anchored += has_rigid[c] ? 0 : 1;
  for (std::size_t i = 0; i < component.size(); ++i) {
    const int c = component[i];
    if (has_rigid[c]) continue;
    const int b = best[c];
    if (binding->main_bone[i] == binding->main_bone[b] &&
        binding->main_weight[i] >= binding->main_weight[b] - rigid_tolerance) {
      binding->rigid_bone[i] = binding->main_bone[i];
      binding->region_joint[i] = -1;
    }
  }
  return anchored;
}

JointRegions RegionsFromWeightBinding(const TriangleMesh& mesh, const Skeleton& skeleton,
                                      const VertexAdjacency& adjacency,
                                      const WeightBinding& binding) {
  const int n = mesh.num_vertices();
  const std::vector<int> inner = skeleton.InnerJoints();
  std::vector<std::vector<int>> region_vertices(inner.size());
  for (int i = 0; i < n; ++i) {
    const auto it = std::find(inner.begin(), inner.end(), binding.region_joint[i]);
    if (it != inner.end()) region_vertices[it - inner.begin()].push_back(i);
  }
  std::vector<JointRegion> regions;
  for (std::size_t r = 0; r < inner.size(); ++r) {
    JointRegion region;
    region.joint = inner[r];
    region.centre = skeleton.joint(inner[r]).rest_position;
    std::vector<double> distances;
    for (int i : region_vertices[r]) {
      distances.push_back((mesh.vertices.row(i).transpose() - region.centre).norm());
    }
    if (!distances.empty()) {
      region.radius = *std::max_element(distances.begin(), distances.end());
      std::nth_element(distances.begin(), distances.begin() + distances.size() / 2,
                       distances.end());
      region.limb_radius = distances[distances.size() / 2];
    }
    region.vertices = std::move(region_vertices[r]);
    regions.push_back(std::move(region));
  }
  return AssembleJointRegions(mesh, adjacency, std::move(regions));
}

}  // namespace deform

#include "core/model/stiffness.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace deform {
Status CheckMaterialWeight(double weight, const std::string& what) {
  if (!std::isfinite(weight) || weight <= 0 || weight > kMaxMaterialWeight) {
    return Status::InvalidArgument(what + " must be finite and in (0, " +
                                   std::to_string(kMaxMaterialWeight) + "], got " +
                                   std::to_string(weight));
  }
  return Status::Ok();
}

Status CheckJointMaterial(const JointMaterial& material, const std::string& what) {
  DEFORM_RETURN_IF_ERROR(CheckMaterialWeight(material.rigid, what + " rigid weight"));
  DEFORM_RETURN_IF_ERROR(CheckMaterialWeight(material.soft, what + " soft weight"));
  DEFORM_RETURN_IF_ERROR(CheckMaterialWeight(material.seam, what + " seam weight"));
  return Status::Ok();
}

namespace {

// The per-joint profiles: `default_material` for every region, replaced by the stiffness's.
StatusOr<std::vector<JointMaterial>> RegionMaterials(const JointRegions& regions,
                                                     const Skeleton& skeleton,
                                                     const JointMaterial& default_material,
                                                     const Stiffness& stiffness) {
  DEFORM_RETURN_IF_ERROR(CheckJointMaterial(default_material, "default material"));
  std::vector<JointMaterial> materials(regions.regions.size(), default_material);
  for (const auto& [joint, material] : stiffness.joint_materials) {
    DEFORM_ASSIGN_OR_RETURN(const int r, RegionOfJoint(regions, skeleton, joint));
    DEFORM_RETURN_IF_ERROR(CheckJointMaterial(material, "joint " + std::to_string(joint)));
    materials[r] = material;
  }
  return materials;
}

// The weights of the profiles alone: the largest soft or seam weight of the regions a vertex is
// in, else the rigid weight of its nearest region (`default_rigid` when there is none).
Eigen::VectorXd ProfileWeights(const JointRegions& regions,
                               const std::vector<JointMaterial>& materials, double default_rigid,
                               int num_vertices) {
  Eigen::VectorXd w(num_vertices);
  for (int i = 0; i < num_vertices; ++i) {
    const int nearest = regions.nearest_region[i];
    w[i] = nearest >= 0 ? materials[nearest].rigid : default_rigid;
  }
  std::vector<double> inside(num_vertices, 0.0);
  for (int r = 0; r < static_cast<int>(regions.regions.size()); ++r) {
    for (int i : regions.regions[r].vertices) inside[i] = std::max(inside[i], materials[r].soft);
    for (int i : regions.regions[r].seam_vertices) {
      inside[i] = std::max(inside[i], materials[r].seam);
    }
  }
  for (int i = 0; i < num_vertices; ++i) {
    if (inside[i] > 0) w[i] = inside[i];
  }
  return w;
}

}  // namespace

StatusOr<Eigen::VectorXd> MaterialRowWeights(const JointRegions& regions, const Skeleton& skeleton,
                                             int num_vertices,
                                             const JointMaterial& default_material,
                                             const Stiffness& stiffness) {
  DEFORM_ASSIGN_OR_RETURN(const std::vector<JointMaterial> materials,
                          RegionMaterials(regions, skeleton, default_material, stiffness));
  Eigen::VectorXd w = ProfileWeights(regions, materials, default_material.rigid, num_vertices);
  for (const auto& [joint, weight] : stiffness.region_weights) {
    DEFORM_ASSIGN_OR_RETURN(const int r, RegionOfJoint(regions, skeleton, joint));
    DEFORM_RETURN_IF_ERROR(
        CheckMaterialWeight(weight, "region weight of joint " + std::to_string(joint)));
    for (int i : regions.regions[r].vertices) w[i] = weight;
  }
  for (const auto& [vertex, weight] : stiffness.vertex_weights) {
    if (vertex < 0 || vertex >= num_vertices) {
      return Status::InvalidArgument("stiffness for vertex " + std::to_string(vertex) +
                                     " but the mesh has " + std::to_string(num_vertices) +
                                     " vertices");
    }
    DEFORM_RETURN_IF_ERROR(
        CheckMaterialWeight(weight, "weight of vertex " + std::to_string(vertex)));
    w[vertex] = weight;
  }
  return w;
}

}  // namespace deform

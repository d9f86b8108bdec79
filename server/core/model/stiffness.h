// Material weights: the per-vertex stiffness W of METHOD.md and how clients describe it.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/skeleton.h"
#include "core/model/joint_regions.h"

namespace deform {

// The material profile around one joint. Weights are relative; a heavier row changes less.
struct JointMaterial {
  double rigid = 2.0;  // vertices outside every joint region (nearest joint's profile). Default: 2
  double soft = 1.0;   // vertices inside this joint's region. Default: 1
  double seam = 4.0;   // vertices of the region on its border. Default: 4
};

// A client's stiffness description, applied in this order on top of the model's default profile:
// per-joint profiles, then whole-region weights, then individual vertex weights.
struct Stiffness {
  std::vector<std::pair<int, JointMaterial>> joint_materials;  // joint index -> profile
  std::vector<std::pair<int, double>> region_weights;          // joint index -> weight on all P_c
  std::vector<std::pair<int, double>> vertex_weights;          // vertex index -> weight
};

// Largest weight accepted; keeps the normal equations well conditioned.
constexpr double kMaxMaterialWeight = 1e4;

// The rule for every material weight: finite and in (0, kMaxMaterialWeight]. INVALID_ARGUMENT
// "<what> must be finite and in (0, 10000.000000], got <weight>" otherwise. MaterialRowWeights
// checks every weight with it; the service calls it to refuse a request before factorizing.
Status CheckMaterialWeight(double weight, const std::string& what);
// CheckMaterialWeight on the three weights, described as "<what> rigid weight" and so on.
Status CheckJointMaterial(const JointMaterial& material, const std::string& what);

// Per-vertex row weights w_i. A vertex in one or more joint regions takes the largest soft (or, on
// a region's border, seam) weight among them; a vertex outside every region takes the rigid weight
// of its nearest region's joint (`default_material.rigid` if the skeleton has no inner joint).
// INVALID_ARGUMENT for weights that are not finite and in (0, kMaxMaterialWeight], joints without a
// region (RegionOfJoint; `skeleton` names them), or vertices out of range.
StatusOr<Eigen::VectorXd> MaterialRowWeights(const JointRegions& regions, const Skeleton& skeleton,
                                             int num_vertices,
                                             const JointMaterial& default_material,
                                             const Stiffness& stiffness);

}  // namespace deform

// Skinning baselines with the model's harmonic bone weights (METHOD.md, "Baselines").
#pragma once

#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/pose.h"
#include "core/model/bone_weights.h"

namespace deform {

// Linear blend skinning: x_i = sum_k h_ik (R_k v_i + t_k). `posed` is resized to rest's shape.
void LinearBlendSkinning(const Positions& rest, const BoneWeights& weights,
                         const std::vector<RigidTransform>& bone_transforms, Positions* posed);

// Dual quaternion skinning (Kavan et al. 2008) with the same weights: the normalized blend of the
// bones' unit dual quaternions, signs aligned to each vertex's heaviest bone.
void DualQuaternionSkinning(const Positions& rest, const BoneWeights& weights,
                            const std::vector<RigidTransform>& bone_transforms, Positions* posed);

}  // namespace deform

// Skinning with optimized centres of rotation (Le & Hodgins, "Real-time Skeletal Skinning with
// Optimized Centers of Rotation", SIGGRAPH 2016): a baseline of the method comparison
// (`deformctl deform --method cor`).
//
// Precomputed per vertex i, with the model's bone weights w: its centre of rotation
//   p_i* = sum_t s(w_i, w_t) a_t c_t / sum_t s(w_i, w_t) a_t
// over every triangle t of the rest mesh (the exact sum; the paper's clustering of triangles is
// not used), with a_t its area, c_t its centroid, w_t the mean of its corners' weights and the
// paper's similarity
//   s(w_p, w_v) = sum_{j<k} w_pj w_pk w_vj w_vk exp(-(w_pj w_vk - w_pk w_vj)^2 / sigma^2),
// sigma = 0.1 (the paper's value). A vertex whose similarity sum is 0 (it has one bone, or no
// triangle shares two of its bones) has no centre and follows linear blend skinning.
// Per frame: R_i = the rotation of the normalized quaternion blend (QLERP) of its bones'
// rotations, signs aligned to its heaviest bone; t_i = LBS(p_i*) - R_i p_i*;
// x_i = R_i v_i + t_i.
#pragma once

#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/pose.h"
#include "core/model/bone_weights.h"

namespace deform {

struct RotationCenters {
  static constexpr double kSigma = 0.1;  // the similarity's width (the paper's)

  Positions centers;             // #V by 3, p_i* (0 where has_center[i] is 0)
  std::vector<char> has_center;  // #V: 1 where the similarity sum is positive
  int num_without_center = 0;    // vertices that follow LBS
};

// The centres of rotation of every vertex of `mesh` with `weights` (one row per vertex).
// O(sum over vertices of the triangles sharing two of its bones); no triangle clustering.
RotationCenters ComputeRotationCenters(const TriangleMesh& mesh, const BoneWeights& weights,
                                       double sigma = RotationCenters::kSigma);

// Skinning with the optimized centres: `posed` is resized to rest's shape; allocation-free when it
// already has it.
void OptimizedCentersSkinning(const Positions& rest, const BoneWeights& weights,
                              const RotationCenters& centers,
                              const std::vector<RigidTransform>& bone_transforms, Positions* posed);

}  // namespace deform

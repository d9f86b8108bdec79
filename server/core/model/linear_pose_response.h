// METHOD.md's fast path: a frame without a solve, for the linear rotation blend.
//
// With T_i = sum_k h_ik R_k, the right-hand side of the normal equations is linear in the entries
// of the bone transforms (R_k, t_k), and so is the solution:
//
//   x_i = sum_k ( R_k (U_k0[i], U_k1[i], U_k2[i])^T + t_k V_k[i] )
//
// U_kb = A^-1 (the right-hand side with R_k = the unit matrix's column b, every other transform
// zero), V_k = A^-1 (the right-hand side of t_k = 1). Four vectors of length n per bone, computed
// once per factorization with 2 K three-column solves; a frame then costs 12 K multiply-adds per
// vertex and reads 32 K bytes per vertex. It is exact for the linear blend (a test compares it
// with the solve) and differs from the quaternion blend in the blend regions (measured in
// METHOD-comparison tests and the quality table).
//
// The blend's knots (linear_blend_plan.h: quaternion blends of a few bones at fixed shares,
// computed per frame) enter like more rotations, three response vectors each (the translations
// only reach the right-hand side through the bones themselves).
//
// BuildLinearPoseResponse (at the end) computes it from the model's least-squares system.
// Immutable after construction; Evaluate() is const, allocation-free and may run on any number of
// threads at once.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <vector>

#include "core/geometry/pose.h"
#include "core/geometry/skeleton.h"
#include "core/model/laplacian_system.h"
#include "core/model/linear_blend_plan.h"
#include "core/solver/cholesky_factor.h"

namespace deform {

class LinearPoseResponse {
 public:
  // `bones`: the bones with a non-zero response, ascending. `columns`: for each of them, in that
  // order, the four response vectors U_k0, U_k1, U_k2, V_k of `num_vertices` doubles each; then
  // for each of `plan`'s knots its three vectors U_0, U_1, U_2.
  // Precondition: columns.size() == (4 * bones.size() + 3 * plan->num_knots()) * num_vertices.
  LinearPoseResponse(int num_vertices, std::vector<int> bones,
                     std::shared_ptr<const LinearBlendPlan> plan, std::vector<double> columns);

  // positions (n by 3, row-major) = the solution for these bone transforms (one per skeleton bone,
  // as ForwardKinematics gives them). No allocation.
  void Evaluate(const std::vector<RigidTransform>& bone_transforms, double* positions) const;

  int num_vertices() const { return num_vertices_; }
  const std::vector<int>& bones() const { return bones_; }
  int num_knots() const { return plan_->num_knots(); }
  // Bytes of the stored response vectors: what each frame reads.
  std::size_t bytes() const { return columns_.size() * sizeof(double); }

 private:
  int num_vertices_ = 0;
  std::vector<int> bones_;
  std::shared_ptr<const LinearBlendPlan> plan_;
  std::vector<double> columns_;
};

// METHOD.md's precomputed response of `system` for the linear blend `plan` (of the model's bone
// weights), with the vertex rows' squared weights `row_weights_squared` (n) and `factor`, the
// Cholesky factor of that NormalMatrix. Costs 2 K + 3 (knots) three-column solves. Null when a
// frame would read more from it than a solve reads from the factor (its doubles against twice the
// factor's non-zeros), or when a joint node moves with the root transform (its joint has no
// incoming bone; inner joints always have one).
std::unique_ptr<const LinearPoseResponse> BuildLinearPoseResponse(
    const LaplacianSystem& system, const Skeleton& skeleton,
    const std::shared_ptr<const LinearBlendPlan>& plan, const Eigen::VectorXd& row_weights_squared,
    const CholeskyFactor& factor);

}  // namespace deform

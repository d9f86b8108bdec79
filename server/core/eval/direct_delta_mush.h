// Direct Delta Mush (Le & Lewis, "Direct Delta Mush Skinning and Variants", SIGGRAPH 2019), the
// variant with full 4x4 matrices (the paper's v0, its rotation and translation smoothed by
// separate amounts): a baseline of the method comparison (`deformctl deform --method ddm`).
//
// Precomputed per vertex i and bone j, with the model's bone weights w, u_k = (v_k - c, 1) (the
// rest positions about the bounding box's centre c, so that the covariances below do not cancel
// against the distance from the origin) and B = (I - lambda (I - D^-1 A))^p (p steps of explicit
// Laplacian smoothing with the uniform Laplacian, A the adjacency and D the degrees):
//   Omega_ij = sum_k B_ik w_kj u_k u_k^T               (4x4, p = rotation_iterations)
//   omega_ij = sum_k B'_ik w_kj u_k                     (4,   p = translation_iterations)
// Per frame, with M_j the bone's rigid transform as a 3x4 matrix on centred coordinates:
//   [Q q] = sum_j M_j Omega_ij / s, [p^T 1] = sum_j (row 3 of Omega_ij) / s  (s normalizes)
//   R_i = U V^T from the SVD of Q - q p^T (Eigen's JacobiSVD; the smallest singular vector
//         flipped when det < 0), the paper's closest rotation;
//   t_i = q' - R_i p' with q', p' the same means from omega (translation smoothing), and
//   x_i = R_i (v_i - c) + t_i.
// With equal iteration counts this is the paper's v0 exactly. The rest pose gives the rest mesh
// (every Omega_ij is symmetric positive semi-definite, so R_i = I) and a rigid motion of the whole
// skeleton moves the mesh rigidly (R_i is that motion's rotation).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/pose.h"
#include "core/model/bone_weights.h"

namespace deform {

struct DirectDeltaMushOptions {
  // Smoothing of the rotation part (the 4x4 Omega). Default: 20 iterations.
  int rotation_iterations = 20;
  // Smoothing of the translation part, less than the rotation's as the paper recommends so that
  // the skin slides less. Default: 10 iterations.
  int translation_iterations = 10;
  // The step of each explicit smoothing iteration, in (0, 1] (B keeps non-negative entries and
  // rows summing to 1). Default: 0.5.
  double step = 0.5;
};

class DirectDeltaMush {
 public:
  using BoneMatrices = std::vector<Eigen::Matrix<double, 3, 4>>;

  // Precomputes Omega and omega for `mesh` with `weights`. Memory: the result (14 doubles per
  // vertex and bone with a non-zero smoothed weight) and working buffers of 2 x 14 doubles per
  // vertex, reused bone after bone: nothing of size #V^2 or #V x #bones x 16 dense.
  static DirectDeltaMush Precompute(const TriangleMesh& mesh, const BoneWeights& weights,
                                    const DirectDeltaMushOptions& options = {});

  // One frame: `posed` is resized to #V by 3 and `bone_matrices` to #bones; allocation-free when
  // both already have their sizes.
  void Deform(const std::vector<RigidTransform>& bone_transforms, Positions* posed,
              BoneMatrices* bone_matrices) const;

  int num_entries() const { return static_cast<int>(bones_.size()); }
  const DirectDeltaMushOptions& options() const { return options_; }

 private:
  struct Entry {
    double rotation[10];    // Omega_ij's upper triangle, row by row
    double translation[4];  // omega_ij
  };

  DirectDeltaMushOptions options_;
  Eigen::Vector3d center_ = Eigen::Vector3d::Zero();
  Positions centred_rest_;  // v_i - c
  int num_bones_ = 0;
  std::vector<int> offsets_;  // vertex i's entries are [offsets_[i], offsets_[i + 1])
  std::vector<int> bones_;    // the entries' bones, ascending per vertex
  std::vector<Entry> entries_;
};

}  // namespace deform
